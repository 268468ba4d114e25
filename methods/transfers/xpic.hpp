// XPIC(m): Hammerquist & Nairn 2017, "A new method for material point method
// particle updates that reduces noise and enhances stability", CMAME 318.
// With S the G2P interpolation (v_p = sum_i w_ip v_i), S+ the mass-weighted P2G
// (v_i = sum_p w_ip m_p v_p / m_i) and P = S S+, FLIP is
//   v_p^{n+1} = v_p^n + S (v^{n+1} - v^n)
// and PIC is FLIP - (I - P) v_p^n. XPIC(m) removes (I - P)^m v_p^n instead,
// which expands (binomial theorem) into
//   v_p^{n+1} = S (v^{n+1} - v^n + v*),
//   v* = sum_{k=1..m} (-1)^{k+1} C(m,k) S+ P^{k-1} v_p^n
//      = sum_{k=1..m} (-1)^{k+1} C(m,k) Q^{k-1} v^n,   Q = S+ S on the grid,
// since S+ v_p^n = v^n (equation numbers of the paper not checked). XPIC(1) is PIC; as m grows the
// scheme approaches FLIP with only the null-space noise of P removed. The base solver computes the
// grid series (the m - 1 round trips Q) because this policy declares old_velocity_series(): it
// replaces v_old_i by
//   v^n - v* = sum_{j=0..m-1} d_j Q^j v^n,  d_0 = 1 - m, d_j = (-1)^{j+1} C(m, j+1),
// so that G2P reads v_p = S (v^{n+1} - v_old) like a FLIP increment.
// P2G, force, F update and the position (x_p += dt S v^{n+1}) are PIC's.
// Parameter: [xpic] m, an integer in [1, 20] (default 5; C(m, k) grows fast and
// the alternating series loses digits beyond that).
#pragma once

#include <cmath>
#include <string_view>
#include <vector>

#include "transfers/pic.hpp"

namespace mpmtb {

template <int Dim, class Kernel>
class XpicPolicy : public PicPolicy<Dim, Kernel> {
  using Base = PicPolicy<Dim, Kernel>;
  using typename Base::M;
  using typename Base::V;

 public:
  static constexpr int kMaxOrder = 20;
  XpicPolicy(Parameters& params, Real dx)
      : Base(params, dx),
        m_(static_cast<int>(params.optional(
            "m", 5,
            Range{[](Real v) { return v >= 1 && v <= kMaxOrder && v == std::floor(v); },
                  "an integer in [1, 20]"}))) {}

  int order() const { return m_; }

  // The coefficients d_j of v_old <- sum_j d_j Q^j v_old (see the header).
  std::vector<Real> old_velocity_series() const {
    std::vector<Real> d(m_);
    Real binomial = m_;  // C(m, j + 1), exact in Real for m <= 20
    d[0] = 1 - binomial;
    for (int j = 1; j < m_; ++j) {
      binomial = binomial * (m_ - j) / (j + 1);
      d[j] = (j % 2 ? 1 : -1) * binomial;
    }
    return d;
  }

  struct Gather {
    V v = V::Zero();
    V v_old = V::Zero();  // S (v^n - v*)
    M grad_v = M::Zero();
  };
  using TensorPath = XpicPolicy;
  static constexpr TensorTerms gather_terms{.gradient = true, .old = true};
  Gather gather_from(const GatherSums<Dim>& sums) const { return {sums.v, sums.v_old, sums.G}; }
  void gather(Gather& g, Real w, const V& grad, const V&, const V& v_i, const V& v_old_i) const {
    g.v += w * v_i;
    g.v_old += w * v_old_i;
    g.grad_v += v_i * grad.transpose();
  }
  void finish(const Gather& g, Particles<Dim>& P, int p, Real dt) const {
    P.v[p] = g.v - g.v_old;  // S (v^{n+1} - v^n + v*)
    deformation_update<Dim>(P.F[p], g.grad_v, dt);
    P.x[p] += dt * g.v;
  }

 private:
  int m_;
};

struct XpicTransfer {
  static constexpr std::string_view name = "xpic";
  static constexpr std::string_view description =
      "XPIC(m): PIC with the first m terms of FLIP's grid projection series "
      "(Hammerquist & Nairn 2017); xpic.m (default 5), m = 1 is PIC";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@article{hammerquist2017,
  author = {Hammerquist, Chad C. and Nairn, John A.},
  title = {A new method for material point method particle updates that reduces noise and enhances stability},
  journal = {Computer Methods in Applied Mechanics and Engineering},
  volume = {318},
  pages = {724--738},
  year = {2017},
  doi = {10.1016/j.cma.2017.01.035}
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
  using Policy = XpicPolicy<Dim, Kernel>;
};

}  // namespace mpmtb
