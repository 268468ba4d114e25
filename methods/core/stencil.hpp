// The kernel stencil of one particle: tensor-product weights w_ip, gradients
// grad w_ip and offsets x_i - x_p for the Kernel::support^Dim nodes around x_p.
// Computed once per particle and shared by P2G and G2P.
#pragma once

#include <cmath>

#include "grid.hpp"
#include "types.hpp"

namespace mpmtb {

namespace detail {
// Multi-indices of a support^Dim block, last axis fastest (the grid's memory order).
template <int Dim, int S>
constexpr auto stencil_multi_indices() {
  std::array<std::array<int, Dim>, ipow(S, Dim)> table{};
  for (int n = 0; n < ipow(S, Dim); ++n) {
    int rest = n;
    for (int a = Dim - 1; a >= 0; --a) {
      table[n][a] = rest % S;
      rest /= S;
    }
  }
  return table;
}
}  // namespace detail

template <int Dim, class Kernel>
struct Stencil {
  static constexpr int S = Kernel::support;
  static constexpr int count = ipow(S, Dim);
  static constexpr auto offsets = detail::stencil_multi_indices<Dim, S>();

  long base_node = 0;  // linear index of the stencil's first node
  Real w[Dim][S];      // 1D weights N((x_p - x_i) / dx) per axis
  Real dw[Dim][S];     // 1D derivatives dN/dx per axis (physical units)
  Real d[Dim][S];      // 1D offsets x_i - x_p per axis

  Stencil(const Vec<Dim>& xp, const GridGeometry<Dim>& g) {
    const Real inv_dx = 1 / g.dx;
    for (int a = 0; a < Dim; ++a) {
      const Real xi = (xp[a] - g.lo[a]) * inv_dx;  // position in cell units
      // First node of the support: floor(xi) for support 2, floor(xi - 1/2) for 3, floor(xi) - 1
      // for 4.
      const int first = static_cast<int>(std::floor(xi - Real(0.5) * (S - 2)));
      for (int k = 0; k < S; ++k) {
        const Real r = xi - (first + k);
        w[a][k] = Kernel::N(r);
        dw[a][k] = Kernel::dN(r) * inv_dx;
        d[a][k] = -r * g.dx;
      }
      base_node += static_cast<long>(first + GridGeometry<Dim>::pad) * g.strides()[a];
    }
  }

  // Calls f(node, w_ip, grad w_ip, x_i - x_p) for every node of the stencil.
  template <class Fn>
  void for_each_node(const GridGeometry<Dim>& g, Fn&& f) const {
    const auto& stride = g.strides();
    for (int n = 0; n < count; ++n) {
      const auto& k = offsets[n];
      long node = base_node;
      Real weight = 1;
      Vec<Dim> grad, dpos;
      for (int a = 0; a < Dim; ++a) {
        node += k[a] * stride[a];
        weight *= w[a][k[a]];
        dpos[a] = d[a][k[a]];
        Real g_a = dw[a][k[a]];
        for (int b = 0; b < Dim; ++b) {
          if (b != a) g_a *= w[b][k[b]];
        }
        grad[a] = g_a;
      }
      f(node, weight, grad, dpos);
    }
  }

  // D_p = sum_i w_ip (x_i - x_p)(x_i - x_p)^T. Diagonal for tensor-product kernels
  // (the off-diagonal sums factor into zero first moments).
  Vec<Dim> inertia_diagonal() const {
    Vec<Dim> D;
    for (int a = 0; a < Dim; ++a) {
      Real s = 0;
      for (int k = 0; k < S; ++k) s += w[a][k] * d[a][k] * d[a][k];
      D[a] = s;
    }
    return D;
  }
};

}  // namespace mpmtb
