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

// Kernels whose weights depend on the particle half-width GridGeometry::l (uGIMP)
// declare weights(r0, w, dw, l); the others keep their own code.
template <class Kernel>
constexpr bool kernel_uses_half_width = requires(Real* out) {
  Kernel::weights(Real(1), out, out, Real(1));
};

// Kernels whose D_p = sum w (x_i - x_p)(x_i - x_p)^T is neither constant (B-splines)
// nor singular (the hat): the affine transfers take the particle's own D_p.
template <class Kernel>
constexpr bool kernel_particle_inertia = [] {
  if constexpr (requires { Kernel::particle_inertia; }) {
    return Kernel::particle_inertia;
  } else {
    return false;
  }
}();

template <int Dim, class Kernel>
struct Stencil {
  static constexpr int S = Kernel::support;
  static constexpr int count = ipow(S, Dim);
  static constexpr auto offsets = detail::stencil_multi_indices<Dim, S>();

  long base_node = 0;  // linear index of the stencil's first node
  Real w[Dim][S];      // 1D weights N((x_p - x_i) / dx) per axis
  Real dw[Dim][S];     // 1D derivatives dN/dx per axis (physical units)
  Real d[Dim][S];      // 1D offsets x_i - x_p per axis

  // Index (unpadded) of the first node of the support along one axis, for a
  // position xi in cell units.
  static int first_index(Real xi) { return static_cast<int>(std::floor(xi - Real(0.5) * (S - 2))); }

  Stencil(const Vec<Dim>& xp, const GridGeometry<Dim>& g) {
    const Real inv_dx = 1 / g.dx;
    for (int a = 0; a < Dim; ++a) {
      const Real xi = (xp[a] - g.lo[a]) * inv_dx;  // position in cell units
      // First node of the support: floor(xi) for support 2, floor(xi - 1/2) for 3, floor(xi) - 1
      // for 4.
      const int first = first_index(xi);
      if constexpr (kernel_uses_half_width<Kernel>) {
        // The same with the particle half-width (uGIMP).
        const Real r0 = xi - first;
        Kernel::weights(r0, w[a], dw[a], g.l);
        for (int k = 0; k < S; ++k) {
          dw[a][k] *= inv_dx;
          d[a][k] = -(r0 - k) * g.dx;
        }
      } else if constexpr (requires(Real * out) { Kernel::weights(Real(1), out, out); }) {
        // The kernel's own branch-free form for the whole support (same values).
        const Real r0 = xi - first;
        Kernel::weights(r0, w[a], dw[a]);
        for (int k = 0; k < S; ++k) {
          dw[a][k] *= inv_dx;
          d[a][k] = -(r0 - k) * g.dx;
        }
      } else {
        for (int k = 0; k < S; ++k) {
          const Real r = xi - (first + k);
          w[a][k] = Kernel::N(r);
          dw[a][k] = Kernel::dN(r) * inv_dx;
          d[a][k] = -r * g.dx;
        }
      }
      base_node += static_cast<long>(first + GridGeometry<Dim>::pad) * g.strides()[a];
    }
  }

  // Calls f(node, w_ip, grad w_ip, x_i - x_p) for every node of the stencil, last
  // axis fastest. The products of the 1D factors are built axis by axis, so a node
  // costs one multiplication for w_ip and Dim for grad w_ip (dropped by the
  // compiler when the callback does not read the gradient).
  template <class Fn>
  void for_each_node(const GridGeometry<Dim>& g, Fn&& f) const {
    Real grad_part[Dim] = {};  // (read only for the axes already done)
    Vec<Dim> dpos;
    loop_axis<0>(g.strides(), base_node, Real(1), grad_part, dpos, f);
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

 private:
  // Axis A of the tensor-product loop. On entry `weight` is prod_{b<A} w_b and
  // grad_part[a] = dw_a prod_{b<A, b!=a} w_b for a < A.
  template <int A, class Fn>
  void loop_axis(const std::array<long, Dim>& stride, long node, Real weight, const Real* grad_part,
                 Vec<Dim>& dpos, Fn& f) const {
    if constexpr (A == Dim) {
      Vec<Dim> grad;
      for (int a = 0; a < Dim; ++a) grad[a] = grad_part[a];
      f(node, weight, static_cast<const Vec<Dim>&>(grad), static_cast<const Vec<Dim>&>(dpos));
    } else {
      for (int k = 0; k < S; ++k) {
        Real part[Dim];
        for (int a = 0; a < A; ++a) part[a] = grad_part[a] * w[A][k];
        part[A] = weight * dw[A][k];
        dpos[A] = d[A][k];
        loop_axis<A + 1>(stride, node + k * stride[A], weight * w[A][k], part, dpos, f);
      }
    }
  }
};

}  // namespace mpmtb
