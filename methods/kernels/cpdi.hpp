// CPDI1, convected particle domain interpolation: Sadeghirad, Brannon &
// Burghardt 2011, "A convected particle domain interpolation technique to extend
// applicability of the material point method for problems involving massive
// deformations", IJNME 86(12).
//
// The particle domain is the parallelogram (parallelepiped) spanned by the
// half-edge vectors r_a = F_p r0_a, r0_a = l0 dx e_a (l0 = 1/(2 ppc),
// GridGeometry::l): x = x_p + J xi, J = [r_1 .. r_Dim], xi in [-1, 1]^Dim, with
// corners x_c = x_p + J s_c, s_c in {-1, 1}^Dim. The hat N_i is replaced on the
// domain by its multilinear interpolant from the corners, and the GIMP averages
// (1/V_p) int N_i, (1/V_p) int grad N_i of that interpolant are
//   w_ip      = 2^-Dim sum_c N_i(x_c)
//   grad w_ip = sum_c N_i(x_c) g_c,   g_c = 2^-Dim J^-T s_c
// (the integral of grad Q_c over the domain is det J J^-T s_c, V_p = 2^Dim det J).
// Both are exact for linear fields: sum_i w = 1, sum_i grad w = 0,
// sum_i w x_i = x_p, sum_i x_i grad w^T = I. The gradient is the domain average
// of the interpolant's gradient, not d w_ip / d x_p: the two agree where N_i is
// linear over the whole domain (no grid line inside it), and the boundary
// integral (1/V_p) oint N_i^h n ds everywhere (tests/unit/particle_domain_test.cpp).
//
// Not a tensor product: the stencil (Stencil<Dim, CpdiKernel> below) holds the
// weights of a box of 4 nodes per axis, which covers the corners' hats while the
// domain's extent along each axis stays below 2 cells (|J / dx| row sums below 1);
// a larger domain is scaled down to that bound (kMaxHalfExtent). The transfers'
// sums over it (TensorTransfer<Dim, CpdiKernel> below) are node by node.
//
// D_p = sum_i w (x_i - x_p)(x_i - x_p)^T = J J^T + the corners' hat variances: a
// full matrix under shear, so the transfers that take a diagonal D_p (APIC,
// MLS-MPM, AFLIP/ASFLIP, PolyPIC; transfers/affine.hpp) refuse this kernel.
// CPDI2 (corners tracked as particles of their own) is not implemented.
#pragma once

#include <cmath>
#include <string_view>

#include "core/grid.hpp"
#include "core/stencil.hpp"
#include "core/tensor_transfer.hpp"
#include "core/types.hpp"

namespace mpmtb {

struct CpdiKernel {
  static constexpr std::string_view name = "cpdi";
  static constexpr std::string_view description =
      "CPDI1 (Sadeghirad, Brannon & Burghardt 2011): domain spanned by F r0, weights and "
      "gradients from its 2^Dim corners' hats; 4 nodes per axis, not a tensor product (full D_p)";
  static constexpr std::string_view bibtex = R"bib(@article{sadeghirad2011,
  author = {Sadeghirad, Alireza and Brannon, Rebecca M. and Burghardt, Jeff},
  title = {A convected particle domain interpolation technique to extend applicability of the material point method for problems involving massive deformations},
  journal = {International Journal for Numerical Methods in Engineering},
  volume = {86},
  number = {12},
  pages = {1435--1456},
  year = {2011},
  doi = {10.1002/nme.3110}
})bib";
  static constexpr int support = 4;
  static constexpr bool constant_inertia = false;
  static constexpr Real inertia = 0;
  // The stencil takes F_p (Stencil(x_p, F_p, geo)).
  static constexpr bool deformed_domain = true;
  // D_p is a full matrix: refused by the transfers that take it diagonal.
  static constexpr bool full_inertia = true;
  static constexpr Real default_half_width = Real(0.25);
  // Largest half-extent of the domain along an axis, in cells (the 4-node box).
  static constexpr Real kMaxHalfExtent = Real(0.999);

  // Whether the domain l0 F exceeds the box and is scaled into it (reported by
  // the runs: summary `domains_clamped_max`, core/registry.hpp).
  template <int Dim>
  static bool domain_clamped(Real l0, const Mat<Dim>& F) {
    for (int a = 0; a < Dim; ++a)
      if (!(l0 * F.row(a).cwiseAbs().sum() <= kMaxHalfExtent)) return true;
    return false;
  }

  // The 1D form at F = I (reference for the tests): the hat at the two corners
  // r -+ l, averaged, and its CPDI gradient (hat(r + l) - hat(r - l)) / (2l).
  static Real hat(Real r) {
    const Real a = std::abs(r);
    return a < 1 ? 1 - a : 0;
  }
  static Real N(Real r, Real l = default_half_width) {
    return Real(0.5) * (hat(r - l) + hat(r + l));
  }
  static Real dN(Real r, Real l = default_half_width) {
    return (hat(r + l) - hat(r - l)) / (2 * l);
  }
};

// The CPDI1 stencil: weights, gradients and offsets of the 4^Dim nodes of a box
// that holds every corner's hat support, node by node (last axis fastest).
template <int Dim>
struct Stencil<Dim, CpdiKernel> {
  static constexpr int S = CpdiKernel::support;
  static constexpr int count = ipow(S, Dim);
  static constexpr int corners = 1 << Dim;
  // Nodes the box may reach from first_index: it starts there or one node later.
  static constexpr int kSpan = S + 1;

  long base_node = 0;  // linear index of the box's first node
  Real w_[count];
  Vec<Dim> grad_[count], d_[count];

  // The first node of the 4-node support of a particle at xi (cell units), as
  // for the cubic B-spline: ParticleBlocks colours by it. The box starts there
  // or one node later (the domain's half-extent is below one cell).
  static int first_index(Real xi) { return static_cast<int>(std::floor(xi - Real(1))); }
  // The same for every axis at once, axis a in lane a (the binning's).
  static AxisInts first_indices(AxisPack xi) { return axis_floor(xi - Real(1)); }

  // The undeformed domain (F = I).
  Stencil(const Vec<Dim>& xp, const GridGeometry<Dim>& g) : Stencil(xp, Mat<Dim>::Identity(), g) {}

  Stencil(const Vec<Dim>& xp, const Mat<Dim>& F, const GridGeometry<Dim>& g) {
    // Half-edge vectors in cell units, J / dx = l0 F, scaled down if the box
    // would not hold the domain.
    Mat<Dim> J = g.l * F;
    Real extent = 0;
    for (int a = 0; a < Dim; ++a) extent = std::max(extent, J.row(a).cwiseAbs().sum());
    if (extent > CpdiKernel::kMaxHalfExtent) J *= CpdiKernel::kMaxHalfExtent / extent;
    Vec<Dim> xi;
    for (int a = 0; a < Dim; ++a) xi[a] = (xp[a] - g.lo[a]) * g.inv_dx;
    // Corners and the box's first node per axis (the lowest corner's cell).
    Vec<Dim> xc[corners];
    int first[Dim];
    for (int a = 0; a < Dim; ++a) first[a] = std::numeric_limits<int>::max();
    for (int c = 0; c < corners; ++c) {
      xc[c] = xi + J * sign(c);
      for (int a = 0; a < Dim; ++a)
        first[a] = std::min(first[a], static_cast<int>(std::floor(xc[c][a])));
    }
    // g_c = 2^-Dim J^-T s_c in physical units (Sadeghirad et al. 2011).
    const Mat<Dim> JinvT = J.inverse().transpose() * (g.inv_dx / corners);
    for (int n = 0; n < count; ++n) {
      w_[n] = 0;
      grad_[n].setZero();
    }
    for (int c = 0; c < corners; ++c) {
      const Vec<Dim> gc = JinvT * sign(c);
      // The corner's hat: 2 nodes per axis, from cell j_a of the box, fraction t_a.
      int j[Dim];
      Real t[Dim];
      for (int a = 0; a < Dim; ++a) {
        const Real cell = std::floor(xc[c][a]);
        j[a] = static_cast<int>(cell) - first[a];
        t[a] = xc[c][a] - cell;
      }
      for (int q = 0; q < corners; ++q) {
        Real N = 1;
        int n = 0;
        for (int a = 0; a < Dim; ++a) {
          const int bit = (q >> (Dim - 1 - a)) & 1;
          N *= bit ? t[a] : 1 - t[a];
          n = n * S + j[a] + bit;
        }
        w_[n] += N;
        grad_[n] += N * gc;
      }
    }
    for (int n = 0; n < count; ++n) {
      w_[n] *= Real(1) / corners;  // the corners' average
      int rest = n;
      for (int a = Dim - 1; a >= 0; --a) {
        d_[n][a] = (first[a] + rest % S - xi[a]) * g.dx;
        rest /= S;
      }
    }
    for (int a = 0; a < Dim; ++a) {
      base_node += static_cast<long>(first[a] + GridGeometry<Dim>::pad) * g.strides()[a];
    }
  }

  // Calls f(node, w_ip, grad w_ip, x_i - x_p) for every node of the box, last axis fastest.
  template <class Fn>
  void for_each_node(const GridGeometry<Dim>& g, Fn&& f) const {
    for (int n = 0; n < count; ++n) {
      long node = base_node;
      int rest = n;
      for (int a = Dim - 1; a >= 0; --a) {
        node += (rest % S) * g.strides()[a];
        rest /= S;
      }
      f(node, w_[n], static_cast<const Vec<Dim>&>(grad_[n]), static_cast<const Vec<Dim>&>(d_[n]));
    }
  }

  // records[W i + c] += w_ip value[c] and sum_i w_ip field[i] over the box, node
  // by node (Stencil::add_to_records, Stencil::interpolate).
  template <int W>
  void add_to_records(const GridGeometry<Dim>& g, const Real (&value)[W], Real* records) const {
    for_each_node(g, [&](long node, Real w, const Vec<Dim>&, const Vec<Dim>&) {
      for (int c = 0; c < W; ++c) records[node * W + c] += w * value[c];
    });
  }
  Real interpolate(const GridGeometry<Dim>& g, const Real* field) const {
    Real sum = 0;
    for_each_node(
        g, [&](long node, Real w, const Vec<Dim>&, const Vec<Dim>&) { sum += w * field[node]; });
    return sum;
  }

  // D_p = sum_i w_ip (x_i - x_p)(x_i - x_p)^T, full.
  Mat<Dim> inertia() const {
    Mat<Dim> D = Mat<Dim>::Zero();
    for (int n = 0; n < count; ++n) D += w_[n] * d_[n] * d_[n].transpose();
    return D;
  }
  Vec<Dim> inertia_diagonal() const { return inertia().diagonal(); }

 private:
  // s_c: the signs of corner c, axis a from bit Dim - 1 - a.
  static Vec<Dim> sign(int c) {
    Vec<Dim> s;
    for (int a = 0; a < Dim; ++a) s[a] = ((c >> (Dim - 1 - a)) & 1) ? Real(1) : Real(-1);
    return s;
  }
};

// The transfers' stencil sums (core/tensor_transfer.hpp) for CPDI, node by node:
// the same values as the tensor-product path's, for a kernel that is not one.
template <int Dim>
class TensorTransfer<Dim, CpdiKernel> {
  using St = Stencil<Dim, CpdiKernel>;
  using Form = ScatterForm<Dim>;

 public:
  template <TensorTerms T>
  static void scatter(const St& st, const GridGeometry<Dim>& g, const Form& form, Real* sums) {
    constexpr int N = Form::N;
    Real alpha[N], gamma[Dim][N], beta[Dim][N];
    for (int l = 0; l < N; ++l) {
      alpha[l] = form.alpha[l];
      for (int a = 0; a < Dim; ++a) gamma[a][l] = form.gamma[a][l], beta[a][l] = form.beta[a][l];
    }
    add<T, N>(st, g, alpha, gamma, beta, sums);
  }
  // Into folded sums: each column becomes (m, p + dt f) first.
  template <TensorTerms T>
  static void scatter_folded(const St& st, const GridGeometry<Dim>& g, const Form& form, Real dt,
                             Real* sums) {
    constexpr int W = kFoldedWidth<Dim>;
    Real alpha[W], gamma[Dim][W], beta[Dim][W];
    fold(form.alpha, dt, alpha);
    for (int a = 0; a < Dim; ++a)
      fold(form.gamma[a], dt, gamma[a]), fold(form.beta[a], dt, beta[a]);
    add<T, W>(st, g, alpha, gamma, beta, sums);
  }

  template <TensorTerms T>
  static GatherSums<Dim> gather(const St& st, const GridGeometry<Dim>& g, const Real* rows,
                                Real* nodal = nullptr) {
    static_assert(!T.nodal, "CPDI: no transfer with nodal rows (PolyPIC refuses it)");
    (void)nodal;
    using VR = VelocityRows<Dim, T.old>;
    GatherSums<Dim> out;
    st.for_each_node(g, [&](long node, Real w, const Vec<Dim>& grad, const Vec<Dim>& d) {
      const Real* r = rows + node * VR::N;
      Vec<Dim> v, v_old;
      for (int a = 0; a < Dim; ++a) {
        v[a] = r[a];
        if constexpr (T.old) v_old[a] = r[VR::old + a];
      }
      out.v += w * v;
      if constexpr (T.old) out.v_old += w * v_old;
      if constexpr (T.moment) out.B += (w * v) * d.transpose();
      if constexpr (T.gradient) out.G += v * grad.transpose();
    });
    return out;
  }

 private:
  // (m, p + dt f) of a form column, zero beyond.
  static void fold(const typename Form::Col& c, Real dt, Real* out) {
    for (int l = 0; l < kFoldedWidth<Dim>; ++l) out[l] = 0;
    out[Form::m] = c[Form::m];
    for (int a = 0; a < Dim; ++a) out[Form::p + a] = c[Form::p + a] + dt * c[Form::f + a];
  }
  // Node value alpha w + sum_a gamma_a w d_a + sum_a beta_a grad_a w, W values per node.
  template <TensorTerms T, int W>
  static void add(const St& st, const GridGeometry<Dim>& g, const Real (&alpha)[W],
                  const Real (&gamma)[Dim][W], const Real (&beta)[Dim][W], Real* sums) {
    static_assert(!T.nodal, "CPDI: no transfer with nodal rows (PolyPIC refuses it)");
    st.for_each_node(g, [&](long node, Real w, const Vec<Dim>& grad, const Vec<Dim>& d) {
      Real* out = sums + node * W;
      for (int l = 0; l < W; ++l) {
        Real value = w * alpha[l];
        for (int a = 0; a < Dim; ++a) {
          if constexpr (T.moment) value += w * d[a] * gamma[a][l];
          if constexpr (T.gradient) value += grad[a] * beta[a][l];
        }
        out[l] += value;
      }
    });
  }
};

}  // namespace mpmtb
