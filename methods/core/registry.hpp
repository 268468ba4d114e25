// Names to compiled combinations. The lists live in transfers/all.hpp,
// kernels/all.hpp and models/registry.cpp; this resolves a name once, at set-up.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/parameters.hpp"
#include "core/stepper.hpp"

namespace mpmtb {

struct VariantInfo {
  std::string name;
  std::string description;
  std::string bibtex = {};  // the papers behind it (BibTeX entries), from its header
  bool affine = false;      // transfers: P2G carries C_p, so L includes the affine part
  bool conserves_angular_momentum = false;  // transfers: claimed, and tested to round-off
  // Transfers: sum m_p x_p advances by dt sum m_i v_i, so the centre of mass
  // moves with the momentum (false for ASFLIP's per-particle position correction).
  bool positions_follow_momentum = true;
};

std::vector<VariantInfo> transfer_list();
std::vector<VariantInfo> kernel_list();

// Empty when the combination runs; otherwise the reason it is refused.
// Unknown names throw InputError listing the valid ones.
std::string unsupported_reason(std::string_view transfer, std::string_view kernel);

// True when the solvers of the combination are compiled in this build: every
// supported one by default, a subset with MPMTB_COMBINATIONS=reduced (the
// sanitizer tree; core/combinations.hpp). Unknown names throw InputError.
bool compiled_combination(std::string_view transfer, std::string_view kernel);

// The compiled solver for (Dim, kernel, transfer). Throws InputError for
// unknown names (listing the valid ones), refused combinations and, in a
// reduced build, combinations not compiled (naming the kernels that are).
template <int Dim>
std::unique_ptr<Stepper<Dim>> make_stepper(std::string_view transfer, std::string_view kernel,
                                           Parameters& transfer_params);

// Kernels whose particle domain follows F (cpGIMP, CPDI) clamp it to their
// support: the number of particles of F whose domain (initial half-width l0 in
// cells, GridGeometry::l) is clamped now; -1 for kernels with a fixed domain.
template <int Dim>
long clamped_domains(std::string_view kernel, const std::vector<Mat<Dim>>& F, Real l0);

}  // namespace mpmtb
