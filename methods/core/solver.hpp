// Factory of compiled step combinations. Each transfer's .cpp instantiates its
// solvers for every dimension and kernel (SolverInstances); the registry sees
// only these declarations, so no other translation unit compiles the loops.
#pragma once

#include <memory>

#include "core/parameters.hpp"
#include "core/stepper.hpp"

namespace mpmtb {

// `transfer_params` holds the transfer's own parameters (e.g. FLIP's alpha).
template <int Dim, class Kernel, class Transfer>
std::unique_ptr<Stepper<Dim>> make_solver(Parameters& transfer_params);

template <class Transfer>
struct SolverInstances {
  static void instantiate();
};

}  // namespace mpmtb
