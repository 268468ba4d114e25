// The kernel stencil of one particle: tensor-product weights w_ip, gradients
// grad w_ip and offsets x_i - x_p for the Kernel::support^Dim nodes around x_p.
// Computed once per particle and shared by P2G and G2P.
#pragma once

#include <cmath>
#include <type_traits>
#if defined(__AVX__)
#include <immintrin.h>
#endif

#include "grid.hpp"
#include "pack.hpp"
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

// Kernels whose particle domain follows the particle's deformation gradient F
// declare deformed_domain = true: their stencil is built by Stencil(x_p, F_p, geo),
// and Stencil(x_p, geo) is the undeformed domain (F = I). cpGIMP
// (kernels/cpgimp.hpp) declares half_width(l0, F_aa) for the constructor below;
// CPDI (kernels/cpdi.hpp) specialises Stencil and TensorTransfer itself.
template <class Kernel>
constexpr bool kernel_deformed_domain = [] {
  if constexpr (requires { Kernel::deformed_domain; }) {
    return Kernel::deformed_domain;
  } else {
    return false;
  }
}();

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

// One SIMD value with a lane per axis (up to 3 axes and a padding lane).
typedef Real AxisPack __attribute__((vector_size(4 * sizeof(Real))));

// The lanes' square roots, in place: one vector instruction where the target has
// it (correctly rounded, as std::sqrt; the lanes are never negative where used).
// (A template, so that only the branch of the build's Real is compiled; also for
// registers twice as wide as an AxisPack, PolyModes::keep_group in 3D, which are
// never passed by value: GCC warns of their ABI on targets without AVX-512.)
template <class Pack = AxisPack>
inline void axis_sqrt_in_place(Pack& x) {
  constexpr bool is_double = std::is_same_v<std::remove_cvref_t<decltype(x[0])>, double>;
#if defined(__AVX512F__)
  if constexpr (sizeof(Pack) == 64 && is_double) {
    x = reinterpret_cast<Pack>(_mm512_sqrt_pd(reinterpret_cast<__m512d>(x)));
    return;
  }
#elif defined(__AVX__)
  if constexpr (sizeof(Pack) == 64 && is_double) {  // two AVX registers
    auto lo = __builtin_shufflevector(x, x, 0, 1, 2, 3);
    auto hi = __builtin_shufflevector(x, x, 4, 5, 6, 7);
    axis_sqrt_in_place(lo), axis_sqrt_in_place(hi);
    x = __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7);
    return;
  }
#endif
#if defined(__AVX__)
  if constexpr (sizeof(Pack) == 32 && is_double) {
    x = reinterpret_cast<Pack>(_mm256_sqrt_pd(reinterpret_cast<__m256d>(x)));
    return;
  } else if constexpr (sizeof(Pack) == 32) {
    x = reinterpret_cast<Pack>(_mm256_sqrt_ps(reinterpret_cast<__m256>(x)));
    return;
  } else if constexpr (sizeof(Pack) == 16 && !is_double) {
    x = reinterpret_cast<Pack>(_mm_sqrt_ps(reinterpret_cast<__m128>(x)));
    return;
  }
#endif
  constexpr int lanes = sizeof(Pack) / sizeof(x[0]);
  for (int a = 0; a < lanes; ++a) x[a] = std::sqrt(x[a]);
}

// Four int lanes, one per axis (AxisPack's lanes as integers).
typedef int AxisInts __attribute__((vector_size(16)));

// The lanes rounded down, as ints (std::floor and the conversion, lane by lane;
// the lanes are within int range where used).
template <class Pack = AxisPack>
inline AxisInts axis_floor(Pack x) {
#if defined(__AVX__)
  if constexpr (sizeof(Pack) == 32) {
    const __m256d down = _mm256_round_pd(reinterpret_cast<__m256d>(x), _MM_FROUND_FLOOR);
    return reinterpret_cast<AxisInts>(_mm256_cvttpd_epi32(down));
  } else {
    const __m128 down = _mm_round_ps(reinterpret_cast<__m128>(x), _MM_FROUND_FLOOR);
    return reinterpret_cast<AxisInts>(_mm_cvttps_epi32(down));
  }
#else
  AxisInts out;
  for (int a = 0; a < 4; ++a) out[a] = static_cast<int>(std::floor(x[a]));
  return out;
#endif
}

// Kernels whose branch-free weights() takes any value type: the stencil then
// evaluates every axis at once, one axis per lane of an AxisPack.
template <class Kernel>
constexpr bool kernel_weights_by_axes = requires(AxisPack* out) {
  Kernel::weights(AxisPack{}, out, out);
};

template <int Dim, class Kernel>
struct Stencil {
  static constexpr int S = Kernel::support;
  static constexpr int count = ipow(S, Dim);
  static constexpr auto offsets = detail::stencil_multi_indices<Dim, S>();

  long base_node = 0;  // linear index of the stencil's first node
  // The 1D factors of node k of the support, axis a in lane a: weights
  // N((x_p - x_i) / dx), derivatives dN/dx (physical units) and offsets x_i - x_p.
  // Node-major with the axes side by side, so that all axes are computed and
  // stored at once (by_axes); read them through w(a, k), dw(a, k), d(a, k).
  AxisPack wk[S], dwk[S], dk[S];
  Real w(int a, int k) const { return wk[k][a]; }
  Real dw(int a, int k) const { return dwk[k][a]; }
  Real d(int a, int k) const { return dk[k][a]; }

  // Index (unpadded) of the first node of the support along one axis, for a
  // position xi in cell units.
  static int first_index(Real xi) { return static_cast<int>(std::floor(xi - Real(0.5) * (S - 2))); }
  // The same for every axis at once, axis a in lane a (the binning's).
  static AxisInts first_indices(AxisPack xi) { return axis_floor(xi - Real(0.5) * (S - 2)); }

  MPMTB_INLINE Stencil(const Vec<Dim>& xp, const GridGeometry<Dim>& g) {
    if constexpr (!kernel_uses_half_width<Kernel> && kernel_weights_by_axes<Kernel>) {
      by_axes(xp, g);
      return;
    }
    const Real inv_dx = g.inv_dx;
    for (int k = 0; k < S; ++k) wk[k] = dwk[k] = dk[k] = AxisPack{};  // (the padding lanes)
    for (int a = 0; a < Dim; ++a) {
      const Real xi = (xp[a] - g.lo[a]) * inv_dx;  // position in cell units
      // First node of the support: floor(xi) for support 2, floor(xi - 1/2) for 3, floor(xi) - 1
      // for 4.
      const int first = first_index(xi);
      Real w_a[S], dw_a[S];
      if constexpr (kernel_uses_half_width<Kernel>) {
        // The same with the particle half-width (uGIMP).
        const Real r0 = xi - first;
        Kernel::weights(r0, w_a, dw_a, g.l);
        for (int k = 0; k < S; ++k) set(a, k, w_a[k], dw_a[k] * inv_dx, -(r0 - k) * g.dx);
      } else if constexpr (requires(Real * out) { Kernel::weights(Real(1), out, out); }) {
        // The kernel's own branch-free form for the whole support (same values).
        const Real r0 = xi - first;
        Kernel::weights(r0, w_a, dw_a);
        for (int k = 0; k < S; ++k) set(a, k, w_a[k], dw_a[k] * inv_dx, -(r0 - k) * g.dx);
      } else {
        for (int k = 0; k < S; ++k) {
          const Real r = xi - (first + k);
          set(a, k, Kernel::N(r), Kernel::dN(r) * inv_dx, -r * g.dx);
        }
      }
      base_node += static_cast<long>(first + GridGeometry<Dim>::pad) * g.strides()[a];
    }
  }

  // The stencil of a particle of deformation gradient F: for kernels with a
  // deformed domain (cpGIMP) the half-width along axis a is Kernel::half_width(l0,
  // F_aa), l0 = GridGeometry::l; every other kernel ignores F (the constructor above).
  MPMTB_INLINE Stencil(const Vec<Dim>& xp, const Mat<Dim>&,
                       const GridGeometry<Dim>& g) requires(!kernel_deformed_domain<Kernel>)
      : Stencil(xp, g) {}
  MPMTB_INLINE Stencil(const Vec<Dim>& xp, const Mat<Dim>& F,
                       const GridGeometry<Dim>& g) requires(kernel_deformed_domain<Kernel>) {
    const Real inv_dx = g.inv_dx;
    for (int k = 0; k < S; ++k) wk[k] = dwk[k] = dk[k] = AxisPack{};  // (the padding lanes)
    for (int a = 0; a < Dim; ++a) {
      const Real xi = (xp[a] - g.lo[a]) * inv_dx;
      const int first = first_index(xi);
      const Real r0 = xi - first;
      Real w_a[S], dw_a[S];
      Kernel::weights(r0, w_a, dw_a, Kernel::half_width(g.l, F(a, a)));
      for (int k = 0; k < S; ++k) set(a, k, w_a[k], dw_a[k] * inv_dx, -(r0 - k) * g.dx);
      base_node += static_cast<long>(first + GridGeometry<Dim>::pad) * g.strides()[a];
    }
  }

  // The constructor's kernel branch for all axes at once, axis a in lane a: the
  // same operations on the same values, so the same bits as axis by axis, in a
  // third of the instructions (the profile showed the two stencils of a step,
  // P2G's and G2P's, at about 280 instructions per particle axis by axis).
  MPMTB_INLINE void by_axes(const Vec<Dim>& xp, const GridGeometry<Dim>& g) {
    const Real inv_dx = g.inv_dx;
    AxisPack xi{}, first_real{};
    int first[Dim];
    for (int a = 0; a < Dim; ++a) {
      xi[a] = (xp[a] - g.lo[a]) * inv_dx;
      first[a] = first_index(xi[a]);
      first_real[a] = Real(first[a]);
    }
    const AxisPack r0 = xi - first_real;
    Kernel::weights(r0, wk, dwk);
    for (int k = 0; k < S; ++k) {
      dwk[k] *= inv_dx;
      dk[k] = -(r0 - Real(k)) * g.dx;
    }
    for (int a = 0; a < Dim; ++a) {
      base_node += static_cast<long>(first[a] + GridGeometry<Dim>::pad) * g.strides()[a];
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

  // records[W i + c] += w_ip value[c] for every node i of the stencil, a record
  // of W values per node (the nonlocal transfer's mass, mass-weighted field and
  // structural tensor). w_ip is formed as for_each_node forms it (the leading
  // axes' product, then the last axis's factor) and multiplies each value once,
  // so every record gets the bits of node-by-node code; the S nodes along the
  // last axis (stride 1) are one Strip of S W values: a row of the stencil costs
  // a few loads, adds and stores instead of W per node (perf: the nonlocal
  // transfer's scalar loop over nodes cost more than P2G's whole scatter).
  template <int W>
  MPMTB_INLINE void add_to_records(const GridGeometry<Dim>& g, const Real (&value)[W],
                                   Real* __restrict records) const {
    using L = Strip<S * W>;
    const L w_last = L::from([&](int l) MPMTB_INLINE_LAMBDA { return w(Dim - 1, l / W); });
    const L v = L::from([&](int l) MPMTB_INLINE_LAMBDA { return value[l % W]; });
    for_each_row<0>(
        g.strides(), base_node, Real(1), [&](long first, Real weight) MPMTB_INLINE_LAMBDA {
          const L w_ip = L::from([&](int) MPMTB_INLINE_LAMBDA { return weight; }) * w_last;
          Real* out = records + first * W;
          (L::load(out) + w_ip * v).store(out);
        });
  }

  // sum_i w_ip field[i], factored axis by axis,
  //   sum_k w_0k sum_l w_1l ... sum_m w_(Dim-1)m field[k, l, ..., m]:
  // short sums of S terms instead of one chain of S^Dim additions (the chain's
  // latency bounded the nonlocal pass's interpolation back).
  Real interpolate(const GridGeometry<Dim>& g, const Real* field) const {
    return interpolate_axis<0>(g.strides(), base_node, field);
  }

  // D_p = sum_i w_ip (x_i - x_p)(x_i - x_p)^T. Diagonal for tensor-product kernels
  // (the off-diagonal sums factor into zero first moments).
  Vec<Dim> inertia_diagonal() const {
    Vec<Dim> D;
    for (int a = 0; a < Dim; ++a) {
      Real s = 0;
      for (int k = 0; k < S; ++k) s += w(a, k) * d(a, k) * d(a, k);
      D[a] = s;
    }
    return D;
  }

 private:
  // The factors of node k along axis a (the per-axis branches of the constructor).
  void set(int a, int k, Real w_ak, Real dw_ak, Real d_ak) {
    wk[k][a] = w_ak;
    dwk[k][a] = dw_ak;
    dk[k][a] = d_ak;
  }
  // Calls f(first node, prod_{b<Dim-1} w_b) for every row of the stencil along
  // the last axis; `weight` = prod_{b<A} w_b on entry.
  template <int A, class Fn>
  MPMTB_INLINE void for_each_row(const std::array<long, Dim>& stride, long node, Real weight,
                                 Fn&& f) const {
    if constexpr (A == Dim - 1) {
      f(node, weight);
    } else {
      for (int k = 0; k < S; ++k)
        for_each_row<A + 1>(stride, node + k * stride[A], weight * w(A, k), f);
    }
  }
  // The sum over axes A.. of interpolate().
  template <int A>
  MPMTB_INLINE Real interpolate_axis(const std::array<long, Dim>& stride, long node,
                                     const Real* field) const {
    const auto term = [&](int k) MPMTB_INLINE_LAMBDA {
      if constexpr (A == Dim - 1) {
        return w(A, k) * field[node + k];
      } else {
        return w(A, k) * interpolate_axis<A + 1>(stride, node + k * stride[A], field);
      }
    };
    Real sum = term(0);
#pragma GCC unroll 4
    for (int k = 1; k < S; ++k) sum += term(k);
    return sum;
  }
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
        for (int a = 0; a < A; ++a) part[a] = grad_part[a] * w(A, k);
        part[A] = weight * dw(A, k);
        dpos[A] = d(A, k);
        // The last axis has stride 1 (GridGeometry): constant node offsets.
        const long n = node + k * (A == Dim - 1 ? 1 : stride[A]);
        loop_axis<A + 1>(stride, n, weight * w(A, k), part, dpos, f);
      }
    }
  }
};

}  // namespace mpmtb
