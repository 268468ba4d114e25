// uGIMP (kernels/gimp.hpp; Bardenhagen & Kober 2004, eq. 40): the shape function and
// its half-width dependence, the particle's own D_p in the affine transfers, and the
// published reason for GIMP: less cell-crossing noise than the linear hat
// (Bardenhagen & Kober 2004; Steffen, Kirby & Berzins 2008).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/grid.hpp"
#include "core/stencil.hpp"
#include "core/tensor_transfer.hpp"
#include "kernels/gimp.hpp"
#include "kernels/quadratic.hpp"
#include "run.hpp"
#include "setup.hpp"
#include "support/compiled.hpp"
#include "support/convergence.hpp"
#include "transfers/apic.hpp"
#include "transfers/mls.hpp"

namespace mpmtb {
namespace gimp_test {

using K = GimpKernel;
const std::vector<Real> kHalfWidths = {Real(1) / 32, Real(1) / 8, Real(1) / 6, Real(0.25),
                                       Real(0.5)};

Real Hat(Real r) {
  return std::max(Real(0), 1 - std::abs(r));
}

// Values and slopes agree on both sides of the breakpoints |r| = l, 1 - l, 1 + l (C1),
// while the second derivative jumps there (so the check has something to see: with a
// wrong branch formula the value or slope jumps by O(1)).
TEST(GimpKernel, ContinuousWithContinuousSlopeAtBreakpoints) {
  const Real d = 1e-9;
  for (const Real l : kHalfWidths) {
    for (const Real b : {l, 1 - l, 1 + l}) {
      for (const Real s : {Real(-1), Real(1)}) {
        const Real r = s * b;
        EXPECT_NEAR(K::N(r - d, l), K::N(r + d, l), 4 * d) << "N jumps at " << r << ", l=" << l;
        EXPECT_NEAR(K::dN(r - d, l), K::dN(r + d, l), 4 * d / l)
            << "dN jumps at " << r << ", l=" << l;
      }
    }
    EXPECT_EQ(K::N(1 + l, l), 0);
    EXPECT_NEAR(K::N(0, l), 1 - l / 2, 1e-15);  // the hat's peak averaged over [-l, l]
  }
}

TEST(GimpKernel, DerivativeMatchesFiniteDifference) {
  const Real h = 1e-6;
  for (const Real l : kHalfWidths) {
    for (Real r = -1.6; r <= 1.6; r += 0.00731) {
      bool near = false;
      for (const Real b : {Real(0), l, 1 - l, 1 + l}) near |= std::abs(std::abs(r) - b) < 1e-4;
      if (near) continue;
      EXPECT_NEAR(K::dN(r, l), (K::N(r + h, l) - K::N(r - h, l)) / (2 * h), 1e-7)
          << "r=" << r << " l=" << l;
    }
  }
}

// The branch-free weights() against the piecewise definition over the support.
TEST(GimpKernel, BranchFreeWeightsMatchPiecewiseForm) {
  for (const Real l : kHalfWidths) {
    for (Real r0 = 0.5; r0 < 1.5; r0 += 0.000917) {
      Real w[3], dw[3];
      K::weights(r0, w, dw, l);
      Real sum = 0, first = 0;
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(w[k], K::N(r0 - k, l), 1e-14) << "r0=" << r0 << " k=" << k << " l=" << l;
        EXPECT_NEAR(dw[k], K::dN(r0 - k, l), 1e-14) << "r0=" << r0 << " k=" << k << " l=" << l;
        sum += w[k];
        first += w[k] * (r0 - k);
      }
      EXPECT_NEAR(sum, 1, 1e-14) << "partition of unity";
      EXPECT_NEAR(first, 0, 1e-14) << "linear reproduction";
      // The fourth node (r0 + 1 or r0 - 3) lies outside the support: 3 nodes suffice.
      EXPECT_EQ(K::N(r0 + 1, l), 0);
      EXPECT_EQ(K::N(r0 - 3, l), 0);
    }
  }
}

// l -> 0: the particle domain shrinks to a point and S tends to the hat; the largest
// gap, l/2, is at the peak (the hat averaged over [-l, l]).
TEST(GimpKernel, SmallHalfWidthTendsToTheHat) {
  for (const Real l : {Real(0.1), Real(0.01), Real(1e-3)}) {
    Real gap = 0;
    for (Real r = -1.3; r <= 1.3; r += 1e-4) gap = std::max(gap, std::abs(K::N(r, l) - Hat(r)));
    EXPECT_LE(gap, l / 2 + 1e-12) << "l=" << l;
    EXPECT_GE(gap, l / 2 - 1e-3 * l) << "l=" << l;  // attained near r = 0
  }
}

// With one particle per cell (l = 1/2) the particle domains are whole cells, and the
// hat averaged over a cell is the quadratic B-spline (B-splines: B_{n+1} = B_n
// convolved with the unit box), so the two kernels coincide: values and slopes.
TEST(GimpKernel, OneParticlePerCellIsTheQuadraticBSpline) {
  for (Real r = -1.6; r <= 1.6; r += 1.37e-3) {
    EXPECT_NEAR(K::N(r, Real(0.5)), QuadraticKernel::N(r), 1e-14) << "r=" << r;
    EXPECT_NEAR(K::dN(r, Real(0.5)), QuadraticKernel::dN(r), 1e-13) << "r=" << r;
  }
}

// uGIMP's D_p per axis in cell units from its definition as the hat averaged over the
// particle domain [xi - l, xi + l]: the average of the hat's f (1 - f) plus l^2 / 3
// (the domain's own second moment). H integrates f (1 - f) from 0 (1/6 per cell).
Real GimpInertia(Real xi, Real l) {
  auto H = [](Real x) {
    const Real n = std::floor(x), t = x - n;
    return n / 6 + t * t / 2 - t * t * t / 3;
  };
  return (H(xi + l) - H(xi - l)) / (2 * l) + l * l / 3;
}

// The stencil uses the grid's l: D_p equals the closed form above at that l. And D_p
// per axis lies between l^2/3 dx^2 (the domain's own moment: never singular, unlike
// the hat) and (1/4 + l^2/3) dx^2.
TEST(GimpKernel, InertiaIsBoundedAwayFromZeroAndFollowsTheGridHalfWidth) {
  for (const Real l : kHalfWidths) {
    GridGeometry<2> g(Vec<2>(-0.3, 0.2), 0.37, {8, 8});
    g.l = l;
    std::mt19937 gen(7);
    std::uniform_real_distribution<Real> u(0, 8 * g.dx);
    for (int s = 0; s < 200; ++s) {
      const Vec<2> xp = g.lo + Vec<2>(u(gen), u(gen));
      const Stencil<2, K> st(xp, g);
      const Vec<2> D = st.inertia_diagonal() / (g.dx * g.dx);
      Real wsum = 0;
      st.for_each_node(g, [&](long, Real w, const Vec<2>&, const Vec<2>&) { wsum += w; });
      EXPECT_NEAR(wsum, 1, 1e-13);
      for (int a = 0; a < 2; ++a) {
        EXPECT_NEAR(D[a], GimpInertia((xp[a] - g.lo[a]) / g.dx, l), 1e-12) << "l=" << l;
        EXPECT_GE(D[a], l * l / 3 - 1e-13) << "l=" << l;
        EXPECT_LE(D[a], Real(0.25) + l * l / 3 + 1e-13) << "l=" << l;
      }
    }
  }
}

// The scene's ppc sets the half-width: l = 1/(2 ppc).
TEST(GimpKernel, SceneGridCarriesHalfWidthFromPpc) {
  for (const int ppc : {1, 2, 3, 4}) {
    Overrides o;
    o.ppc = ppc;
    o.kernel = "gimp";
    const Scene scene = load_scene("translating_block", o);
    EXPECT_NEAR(scene_grid<2>(scene).l, Real(1) / (2 * ppc), 1e-15);
  }
}

// APIC / MLS-MPM with the particle's own D_p: C_p = B_p D_p^-1 recovers the gradient
// of an affine grid velocity exactly at any position and half-width, on both the
// per-node and the tensor-product path. (A constant D_p, e.g. the quadratic
// B-spline's dx^2/4, or a D_p off by any factor is off by O(1) here; the hat's
// gradient form would also pass this test, and the angular momentum conformance
// test, transfer_test.cpp, is what tells it apart.)
template <class Policy>
void CheckAffineRecovery(Real l) {
  GridGeometry<2> g(Vec<2>(-0.3, 0.2), 0.37, {8, 8});
  g.l = l;
  Mat<2> A;
  A << 0.3, -1.7, 2.1, 0.4;
  const Vec<2> b(0.5, -0.25);
  std::vector<Vec<2>> v(g.node_count());
  for (long n = 0; n < g.node_count(); ++n) v[n] = b + A * g.position(n);
  Parameters params;
  const Policy policy(params, g.dx);
  std::mt19937 gen(11);
  std::uniform_real_distribution<Real> u(0, 8 * g.dx);
  for (int s = 0; s < 50; ++s) {
    const Vec<2> xp = g.lo + Vec<2>(u(gen), u(gen));
    const Stencil<2, K> st(xp, g);
    auto slow = policy.begin_gather(st);
    st.for_each_node(g, [&](long n, Real w, const Vec<2>& grad, const Vec<2>& d) {
      policy.gather(slow, w, grad, d, v[n], v[n]);
    });
    VelocityRows<2, Policy::gather_terms.old> rows;
    rows.resize(v.size());
    rows.pack(0, static_cast<long>(v.size()), v.data(), v.data());
    const auto fast = policy.gather_from(
        TensorTransfer<2, K>::template gather<Policy::gather_terms>(st, g, rows.data()));
    EXPECT_LT((slow.C - A).norm(), 1e-11) << "l=" << l << " x_p=" << xp.transpose();
    EXPECT_LT((fast.C - A).norm(), 1e-11) << "l=" << l << " x_p=" << xp.transpose();
    EXPECT_LT((slow.v - (b + A * xp)).norm(), 1e-12);
  }
}

TEST(GimpKernel, AffineTransfersRecoverAffineFieldWithParticleInertia) {
  for (const Real l : kHalfWidths) {
    CheckAffineRecovery<ApicPolicy<2, K>>(l);
    CheckAffineRecovery<MlsPolicy<2, K>>(l);
  }
}

// ---------------------------------------------------------------- runs --

std::map<std::string, std::vector<Real>> ReadSeries(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line, cell;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::stringstream ss(line); std::getline(ss, cell, ',');) names.push_back(cell);
  std::map<std::string, std::vector<Real>> cols;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    for (std::size_t i = 0; i < names.size() && std::getline(ss, cell, ','); ++i) {
      cols[names[i]].push_back(std::strtod(cell.c_str(), nullptr));
    }
  }
  return cols;
}

// The suite's translate_spin case (cases/suite/cases.cpp): peak strain energy over the
// initial energy of a block translating while spinning. The exact motion's strain is
// the small centripetal one the B-splines agree on; the hat adds cell-crossing noise.
Real SpinStrainPeak(const std::string& kernel) {
  Overrides o;
  o.kernel = kernel;
  o.transfer = "mls";
  o.set = {"bodies.0.angular_velocity=[0,0,2]"};
  const Scene scene = load_scene("translating_block", o);
  const auto dir = std::filesystem::temp_directory_path() / ("mpmtb_gimp_spin_" + kernel);
  RunOptions options;
  options.threads = 1;
  const RunOutcome r = run_scene(scene, dir, options);
  EXPECT_EQ(r.status, "ok") << kernel << ": " << r.reason;
  auto s = ReadSeries(dir / "series.csv");
  const Real e0 = s["kinetic"].at(0) + s["strain"].at(0);
  return *std::max_element(s["strain"].begin(), s["strain"].end()) / e0;
}

// GIMP's C1 weights remove the hat's force jumps at cell crossings (Bardenhagen &
// Kober 2004, sec. 4): its spurious strain stays at the B-spline's level, well below
// the hat's. Band: below a quarter of the hat's peak and within a factor 3 of the
// quadratic B-spline's (both smooth kernels see the same centripetal strain).
TEST(GimpRuns, TranslatingSpinningBlockHasLessCellCrossingNoiseThanTheHat) {
  const Real linear = SpinStrainPeak("linear"), gimp = SpinStrainPeak("gimp");
  const Real quadratic = SpinStrainPeak("quadratic");
  EXPECT_LT(gimp, 0.25 * linear) << "gimp " << gimp << ", linear " << linear;
  EXPECT_LT(gimp, 3 * quadratic) << "gimp " << gimp << ", quadratic " << quadratic;
}

// The large-amplitude manufactured bar (G = 0.05, REFERENCE.md): with the hat the
// error grows under refinement once particles cross cells (the published failure,
// Wallstedt & Guilkey 2008; Steffen et al. 2008). Levels 16..64:
// * APIC (true kernel gradients): uGIMP's error does not grow (it falls, then levels
//   off near 64 cells), while the hat's grows;
// * both APIC and MLS-MPM: uGIMP stays far below the hat (band: a fifth) at 32 and 64.
// Not asserted: beyond 32 cells uGIMP's error rises again with MLS-MPM (its force
// direction D_p^-1 (x_i - x_p) w_ip is not grad S_ip), though much more slowly than
// the hat's: undeformed particle domains are uGIMP's own limit under large strain.
TEST(GimpRuns, LargeAmplitudeManufacturedBarStaysFarBelowTheHat) {
  MPMTB_SKIP_UNLESS_COMPILED("apic", "linear");
  MPMTB_SKIP_UNLESS_COMPILED("apic", "gimp");
  const std::vector<int> levels = {16, 32, 64};
  for (const std::string transfer : {"apic", "mls"}) {
    Overrides o;
    o.transfer = transfer;
    o.set = testing::kLarge;
    o.kernel = "linear";
    const auto hat = testing::errors_over("mms_bar", levels, o);
    o.kernel = "gimp";
    const auto gimp = testing::errors_over("mms_bar", levels, o);
    const std::string table = transfer + "\nlinear:\n" + testing::error_table(levels, hat) +
                              "gimp:\n" + testing::error_table(levels, gimp);
    EXPECT_GT(hat[2], hat[0]) << "the hat's failure is not reproduced\n" << table;
    EXPECT_LT(gimp[1], hat[1] / 5) << table;
    EXPECT_LT(gimp[2], hat[2] / 5) << table;
    if (transfer == "apic") {
      EXPECT_LE(gimp[2], gimp[0]) << table;
    }
  }
}

}  // namespace gimp_test
}  // namespace mpmtb
