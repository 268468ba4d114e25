// The solver's fast path (core/tensor_transfer.hpp: transfers as sums over the
// tensor-product stencil) against each policy's per-node math, its reference
// definition: for every transfer x kernel x dimension that declares the fast
// path, P2G node values and the particle state after G2P agree to round-off.
// Also: the kernels' branch-free weights equal N and dN at every support node.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <string>

#include "core/policy_hooks.hpp"
#include "core/stencil.hpp"
#include "core/tensor_transfer.hpp"
#include "kernels/all.hpp"
#include "support/gaps.hpp"
#include "transfers/all.hpp"

namespace mpmtb {
namespace tensor_transfer_test {

template <int Dim>
Mat<Dim> random_matrix(std::mt19937& rng) {
  std::uniform_real_distribution<Real> u(-1, 1);
  return Mat<Dim>::NullaryExpr([&] { return u(rng); });
}
template <int Dim>
Vec<Dim> random_vector(std::mt19937& rng) {
  std::uniform_real_distribution<Real> u(-1, 1);
  return Vec<Dim>::NullaryExpr([&] { return u(rng); });
}

using testing::relative_gap;

template <int Dim, class Kernel, class Transfer>
void check_fast_path_matches_per_node(const std::string& what, int* checked, int* folded_forms) {
  using Policy = typename Transfer::template Policy<Dim, Kernel>;
  if constexpr (!Transfer::template supports<Kernel> || !has_tensor_path<Policy>()) {
    return;
  } else {
    ++*checked;
    std::mt19937 rng(7 + Dim);
    std::array<int, Dim> cells;
    cells.fill(6);
    Vec<Dim> lo;
    for (int a = 0; a < Dim; ++a) lo[a] = -0.4 + 0.3 * a;
    const Real dx = 0.37;
    const GridGeometry<Dim> geo(lo, dx, cells);
    Parameters params;
    const Policy policy(params, dx);
    std::uniform_real_distribution<Real> inside(1.5, 4.5);
    for (int trial = 0; trial < 5; ++trial) {
      Particles<Dim> P;
      Vec<Dim> x;
      for (int a = 0; a < Dim; ++a) x[a] = lo[a] + inside(rng) * dx;
      P.add(x, random_vector<Dim>(rng), 0.7, 0.2, 0);
      P.C[0] = random_matrix<Dim>(rng);
      P.F[0] = Mat<Dim>::Identity() + 0.1 * random_matrix<Dim>(rng);
      if constexpr (requires { Policy::transfer_state_size; }) {
        // Per-particle transfer state (PolyPIC's higher modes), random as C_p.
        P.use_transfer_state(Policy::transfer_state_size);
        for (Real& q : P.transfer_state) q = std::uniform_real_distribution<Real>(-1, 1)(rng);
      }
      const Mat<Dim> tauV = random_matrix<Dim>(rng);
      const Stencil<Dim, Kernel> st(P.x[0], geo);
      const auto src = prepare_source(policy, P, 0, tauV, st);  // as the solver calls it

      // P2G: per node against the sums.
      Grid<Dim> ref(geo), fast(geo);
      st.for_each_node(geo, [&](long n, Real w, const Vec<Dim>& grad, const Vec<Dim>& d) {
        policy.scatter(src, w, grad, d, ref.m[n], ref.p[n], ref.f[n]);
      });
      ScatterForm<Dim> form;
      policy.scatter_form(src, form);
      NodeSums<Dim> sums;
      sums.resize(fast.size());
      TensorTransfer<Dim, Kernel>::template scatter<Policy::scatter_terms>(st, geo, form,
                                                                           sums.data());
      sums.template unpack<true, true>(0, static_cast<long>(fast.size()), fast.m.data(),
                                       fast.p.data(), fast.f.data());
      EXPECT_LT(relative_gap(ref.m, fast.m), 1e-14) << what << " m_i";
      EXPECT_LT(relative_gap(ref.p, fast.p), 1e-14) << what << " p_i";
      EXPECT_LT(relative_gap(ref.f, fast.f), 1e-14) << what << " f_i";
      // The same with the force folded into the momentum: (m_i, p_i + dt f_i).
      const Real dt = 0.3;
      NodeSums<Dim, true> folded;
      folded.resize(fast.size());
      TensorTransfer<Dim, Kernel>::template scatter_folded<Policy::scatter_terms>(st, geo, form, dt,
                                                                                  folded.data());
      Grid<Dim> fold(geo);
      folded.template unpack<true, true>(0, static_cast<long>(fold.size()), fold.m.data(),
                                         fold.p.data(), fold.f.data());
      std::vector<Vec<Dim>> p_dt_f(ref.size());
      for (std::size_t n = 0; n < ref.size(); ++n) p_dt_f[n] = ref.p[n] + dt * ref.f[n];
      EXPECT_LT(relative_gap(ref.m, fold.m), 1e-14) << what << " folded m_i";
      EXPECT_LT(relative_gap(p_dt_f, fold.p), 1e-14) << what << " folded p_i + dt f_i";
      // A policy's own FoldedForm (whole-register columns) folds to the same
      // sums, bit for bit, as its ScatterForm.
      if constexpr (takes_folded_form<Dim, Kernel, Policy>) {
        FoldedForm<Dim> direct;
        policy.folded_form(src, direct);
        NodeSums<Dim, true> from_columns, from_direct;
        from_columns.resize(fast.size());
        from_direct.resize(fast.size());
        TensorTransfer<Dim, Kernel>::template scatter_folded<Policy::scatter_terms>(
            st, geo, form, dt, from_columns.data());
        TensorTransfer<Dim, Kernel>::template scatter_folded_form<Policy::scatter_terms>(
            st, geo, direct, dt, from_direct.data());
        EXPECT_GT(std::count_if(from_columns.values.begin(), from_columns.values.end(),
                                [](Real x) { return x != 0; }),
                  0)
            << what;
        EXPECT_EQ(0, std::memcmp(from_direct.values.data(), from_columns.values.data(),
                                 from_columns.values.size() * sizeof(Real)))
            << what << " FoldedForm";
        ++*folded_forms;
      }

      // G2P from a random velocity field: v_p, C_p, F_p, x_p.
      for (std::size_t n = 0; n < ref.size(); ++n) {
        ref.v[n] = random_vector<Dim>(rng);
        ref.v_old[n] = random_vector<Dim>(rng);
      }
      auto g_ref = begin_gather(policy, st);
      st.for_each_node(geo, [&](long n, Real w, const Vec<Dim>& grad, const Vec<Dim>& d) {
        policy.gather(g_ref, w, grad, d, ref.v[n], ref.v_old[n]);
      });
      VelocityRows<Dim, Policy::gather_terms.old> rows;
      rows.resize(ref.size());
      rows.pack(0, static_cast<long>(ref.size()), ref.v.data(), ref.v_old.data());
      auto g_fast = tensor_gather(policy, st, geo, rows.data());
      Particles<Dim> Pr = P, Pf = P;
      policy.finish(g_ref, Pr, 0, 1e-2);
      policy.finish(g_fast, Pf, 0, 1e-2);
      EXPECT_LT(relative_gap(Pr.v, Pf.v), 1e-14) << what << " v_p";
      EXPECT_LT(relative_gap(Pr.C, Pf.C), 1e-13) << what << " C_p";
      EXPECT_LT(relative_gap(Pr.F, Pf.F), 1e-14) << what << " F_p";
      EXPECT_LT(relative_gap(Pr.x, Pf.x), 1e-14) << what << " x_p";
    }
  }
}

TEST(TensorTransfer, FastPathMatchesPerNodeMathForEveryTransferKernelAndDimension) {
  int checked = 0, folded_forms = 0;
  AllTransfers::for_each([&]<class T>() {
    AllKernels::for_each([&]<class K>() {
      const std::string what = std::string(T::name) + "/" + std::string(K::name);
      check_fast_path_matches_per_node<1, K, T>(what + "/1d", &checked, &folded_forms);
      check_fast_path_matches_per_node<2, K, T>(what + "/2d", &checked, &folded_forms);
      check_fast_path_matches_per_node<3, K, T>(what + "/3d", &checked, &folded_forms);
    });
  });
  EXPECT_GT(checked, 0) << "no transfer declares the fast path";
  EXPECT_GT(folded_forms, 0) << "no transfer writes a FoldedForm";
}

// The branch-free weights a kernel may provide equal N(r) and dN(r) at the
// support's nodes r_k = r0 - k, over the whole range of the first offset r0.
TEST(TensorTransfer, KernelWeightsMatchNAndDN) {
  AllKernels::for_each([&]<class K>() {
    // (uGIMP's weights take the half-width l: here its default, as N and dN.)
    if constexpr (requires(Real * out) { K::weights(Real(1), out, out); }) {
      const Real r_lo = Real(0.5) * (K::support - 2);  // r0 in [r_lo, r_lo + 1)
      for (int i = 0; i <= 1000; ++i) {
        const Real r0 = r_lo + std::min(i / Real(1000), Real(1) - 1e-12);
        Real w[K::support], dw[K::support];
        K::weights(r0, w, dw);
        for (int k = 0; k < K::support; ++k) {
          EXPECT_NEAR(w[k], K::N(r0 - k), 1e-15) << K::name << " r0=" << r0 << " k=" << k;
          EXPECT_NEAR(dw[k], K::dN(r0 - k), 1e-15) << K::name << " r0=" << r0 << " k=" << k;
        }
      }
    }
  });
}

}  // namespace tensor_transfer_test
}  // namespace mpmtb
