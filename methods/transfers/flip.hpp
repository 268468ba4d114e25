// FLIP(alpha): Brackbill & Ruppel 1986, "FLIP: A method for adaptively zoned,
// particle-in-cell calculations of fluid flows in two dimensions", JCP 65; the
// PIC/FLIP blend of Zhu & Bridson 2005 and Stomakhin et al. 2013 (sec. 7):
//   v_p <- alpha (v_p + sum w (v_i - v_i_old)) + (1 - alpha) sum w v_i
// P2G, force and F update as PIC; the position moves with the grid velocity.
// alpha = 1 is pure FLIP (noisy, little dissipation), alpha = 0 is PIC.
// Parameter: [flip] alpha in [0, 1], default 1.
#pragma once

#include <string_view>

#include "transfers/pic.hpp"

namespace mpmtb {

template <int Dim, class Kernel>
class FlipPolicy : public PicPolicy<Dim, Kernel> {
  using Base = PicPolicy<Dim, Kernel>;
  using typename Base::M;
  using typename Base::V;

 public:
  FlipPolicy(Parameters& params, Real dx)
      : Base(params, dx), alpha_(params.optional("alpha", 1, Range::closed(0, 1))) {}

  struct Gather {
    V v = V::Zero();
    V dv = V::Zero();  // sum w (v_i - v_i_old): the grid's velocity increment
    M grad_v = M::Zero();
  };
  using TensorPath = FlipPolicy;
  static constexpr TensorTerms gather_terms{.gradient = true, .old = true};
  Gather gather_from(const GatherSums<Dim>& sums) const {
    return {sums.v, sums.v - sums.v_old, sums.G};
  }
  void gather(Gather& g, Real w, const V& grad, const V&, const V& v_i, const V& v_old_i) const {
    g.v += w * v_i;
    g.dv += w * (v_i - v_old_i);
    g.grad_v += v_i * grad.transpose();
  }
  void finish(const Gather& g, Particles<Dim>& P, int p, Real dt) const {
    P.v[p] = alpha_ * (P.v[p] + g.dv) + (1 - alpha_) * g.v;
    deformation_update<Dim>(P.F[p], g.grad_v, dt);
    P.x[p] += dt * g.v;
  }

 private:
  Real alpha_;
};

struct FlipTransfer {
  static constexpr std::string_view name = "flip";
  static constexpr std::string_view description =
      "FLIP(alpha): grid velocity increments, blended with PIC by flip.alpha (default 1)";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@article{brackbill1986,
  author = {Brackbill, Jeremiah U. and Ruppel, Hans M.},
  title = {{FLIP}: A method for adaptively zoned, particle-in-cell calculations of fluid flows in two dimensions},
  journal = {Journal of Computational Physics},
  volume = {65},
  number = {2},
  pages = {314--343},
  year = {1986},
  doi = {10.1016/0021-9991(86)90211-1}
})bib";
  static constexpr bool affine_momentum = false;
  // Whether the paper claims angular momentum conservation, affine part included, in both
  // transfers (if so, the conformance tests hold it to round-off).
  static constexpr bool conserves_angular_momentum = false;
  static constexpr bool needs_old_velocity = true;
  template <class Kernel>
  static constexpr bool supports = true;
  static constexpr std::string_view unsupported_reason = "";
  template <int Dim, class Kernel>
  using Policy = FlipPolicy<Dim, Kernel>;
};

}  // namespace mpmtb
