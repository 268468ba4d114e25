// The energy error of the stress-update orders (Bardenhagen 2002, "Energy
// conservation error in the material point method for solid mechanics", JCP
// 180), derived for the single material point and measured on it and on the
// vibrating bar.
//
// One-step maps. Scene single_point: one cell of length L, nodes 0 (fixed, by
// a mirror-image particle: see the scene file) and 1, one particle of mass m and volume V at xi =
// x_p / L, linear hat, 1D linear elasticity, FLIP with alpha = 1. Node 1 gets m_1 = xi m and p_1 =
// xi m v (so p_1 / m_1 = v, the particle velocity) and the force f_1 = -V sigma / L. FLIP adds the
// nodal increment back: v <- v + xi dv_1 = v - dt V sigma / (m L); the F update uses v_1 / L. With
// u = L (F - 1), sigma = E u / L and omega^2 = E V / (m L^2) (= 4 pi^2 here), to first order in the
// strain:
//   USL: v' = v - h w^2 u,        u' = u + h (v - h w^2 u / xi)
//        (F from the updated nodal velocity v_1' = v - h w^2 u / xi, whose
//        increment is 1/xi times the particle's)
//   USF: u' = u + h v,            v' = v - h w^2 u'
//   MUSL: v' = v - h w^2 u,       u' = u + h v'  (the remapped p_1/m_1 is v')
// with h = dt, w = omega. Determinants (the factor on phase-space area):
//   USL: 1 - h^2 w^2 (1/xi - 1) < 1 for 0 < xi < 1: strictly dissipative;
//   USF, MUSL: 1, the two symplectic Euler maps: not dissipative.
// A 2 x 2 map N = [[a, b], [c, d]] scales the quadratic form
// c u^2 + (d - a) u v - b v^2 by det N each step (it is invariant for det 1), so
//   Q_USL  = v^2 + w^2 u^2 - (h w^2 / xi) u v  decreases by 1 - h^2 w^2 (1/xi - 1)
//                                              every step, strictly;
//   Q_USF  = v^2 + w^2 u^2 + h w^2 u v         is constant;
//   Q_MUSL = v^2 + w^2 u^2 - h w^2 u v         is constant.
// The energy 2 (K + S) / m = v^2 + w^2 u^2 differs from Q by +-h w^2 u v, and
// |h w^2 u v| <= (h w / 2)(v^2 + w^2 u^2), so for USF and MUSL
//   (1 - h w / 2) / (1 + h w / 2) <= E_n / E_0 <= (1 + h w / 2) / (1 - h w / 2):
// bounded, oscillating within O(h w) and no trend. For USL the same bound
// holds between E and Q, which decays as prod_n det_n ~ exp(-h w^2 t) at
// xi = 1/2: E(4 T) / E_0 ~ 0.21 at h w = 0.063. The physical energy of USL is
// not monotone step by step (at u = 0 it grows by h^2 w^2 v^2 / 2 in one
// step), so what is asserted is the derived quantity, Q_USL, step by step,
// and the energy sampled once per period.
// The particle moves (xi changes by ~1.6 %) and sigma = E (F - 1) F is not
// exactly linear; both perturb the maps at O(v0 / (w L)) = 1.6 % of the
// per-step change, hence the tolerances below.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include "core/diagnostics.hpp"
#include "core/registry.hpp"
#include "run.hpp"
#include "setup.hpp"

namespace mpmtb {
namespace update_order_test {

constexpr Real kPi = std::numbers::pi_v<Real>;
constexpr Real kOmega2 = 4 * kPi * kPi;  // E V / (m L^2) with E = 4 pi^2, rho = 1, L = 1

struct PointSample {
  Real energy;  // K + S from the diagnostics (the series' `total`)
  Real u, v;    // L (F - 1), particle velocity
  Real xi;      // x_p / L
};

std::vector<PointSample> run_single_point(UpdateOrder order, const std::string& kernel = "linear") {
  const Scene scene = load_scene("single_point", {.kernel = kernel});
  EXPECT_EQ(scene.dx(), 1);
  State<1> s = build_state<1>(scene);
  // The point at x = 0.5 and its mirror image, which holds node 0 at rest.
  EXPECT_EQ(s.particles.size(), 2u);
  const int q = s.particles.x[0][0] > 0 ? 0 : 1;
  Parameters params = scene.transfer_params;
  auto st = make_stepper<1>(scene.transfer, scene.kernel, params);
  st->set_update_order(order);
  std::vector<PointSample> out;
  const auto sample = [&] {
    const Diagnostics d = measure(s, *st);
    out.push_back({d.total, s.particles.F[q](0, 0) - 1, s.particles.v[q][0], s.particles.x[q][0]});
  };
  sample();
  const long steps = std::lround(scene.t_end / *scene.dt);
  for (long n = 0; n < steps; ++n) {
    st->step(s, *scene.dt);
    sample();
  }
  return out;
}

constexpr Real kDt = 0.01;  // the scene's step
constexpr int kStepsPerPeriod = 100;

TEST(SinglePoint, UslIsStrictlyDissipative) {
  const auto run = run_single_point(UpdateOrder::usl);
  ASSERT_EQ(run.size(), 4u * kStepsPerPeriod + 1);
  const Real h = kDt, w2 = kOmega2;
  auto Q = [&](const PointSample& p) {
    return p.v * p.v + w2 * p.u * p.u - h * w2 / p.xi * p.u * p.v;
  };
  Real predicted = 1;  // prod_n det_n
  for (std::size_t n = 0; n + 1 < run.size(); ++n) {
    const Real loss = h * h * w2 * (1 / run[n].xi - 1);  // 1 - det_n
    predicted *= 1 - loss;
    const Real ratio = Q(run[n + 1]) / Q(run[n]);
    ASSERT_LT(ratio, 1 - 0.9 * loss) << "step " << n;
    ASSERT_GT(ratio, 1 - 1.1 * loss) << "step " << n;
  }
  // The energy once per period: strictly decreasing, as the area factor says.
  for (int k = 1; k <= 4; ++k) {
    EXPECT_LT(run[k * kStepsPerPeriod].energy, run[(k - 1) * kStepsPerPeriod].energy) << k;
  }
  const Real kept = run.back().energy / run.front().energy;
  EXPECT_NEAR(kept, predicted, 0.1 * predicted);
  EXPECT_LT(kept, 0.3) << "about 80 % of the energy is lost in 4 periods at h w = 0.063";
  RecordProperty("usl_energy_kept_4T", std::to_string(kept));
}

void expect_bounded(UpdateOrder order, Real sign) {
  const auto run = run_single_point(order);
  const Real h = kDt, w2 = kOmega2, hw = h * std::sqrt(w2);
  auto Q = [&](const PointSample& p) {
    return p.v * p.v + w2 * p.u * p.u + sign * h * w2 * p.u * p.v;
  };
  const Real Q0 = Q(run.front()), E0 = run.front().energy;
  const Real lo = (1 - hw / 2) / (1 + hw / 2), hi = (1 + hw / 2) / (1 - hw / 2);
  Real e_min = 1, e_max = 1;
  for (const auto& p : run) {
    // Invariant up to the O(1.6 %) nonlinear and moving-particle terms of the
    // per-step change, which is itself O(h w) = 6 % of Q.
    ASSERT_NEAR(Q(p) / Q0, 1, 2e-3);
    e_min = std::min(e_min, p.energy / E0);
    e_max = std::max(e_max, p.energy / E0);
  }
  EXPECT_GE(e_min, lo - 2e-3);
  EXPECT_LE(e_max, hi + 2e-3);
  // It does oscillate at O(h w): the bound is not empty.
  EXPECT_LT(e_min, 1 - hw / 8);
  EXPECT_GT(e_max, 1 + hw / 8);
  // No trend: the energy at the end of every period is the initial one.
  for (int k = 1; k <= 4; ++k) EXPECT_NEAR(run[k * kStepsPerPeriod].energy / E0, 1, 2e-3) << k;
  ::testing::Test::RecordProperty(std::string(update_order_name(order)) + "_energy_range",
                                  std::to_string(e_min) + " " + std::to_string(e_max));
}

TEST(SinglePoint, UsfKeepsTheEnergyBounded) {
  expect_bounded(UpdateOrder::usf, +1);
}
TEST(SinglePoint, MuslKeepsTheEnergyBounded) {
  expect_bounded(UpdateOrder::musl, -1);
}

// The vibrating bar (16 cells, 4 periods, cfl 0.2) with FLIP. Its first mode
// has h w = 0.02, and the USL loss of the single point comes from the nodal
// velocity increment being 1/xi times the particle's; for a smooth mode with
// many particles per cell the two nearly agree, so the loss is a small
// fraction of h^2 w^2 per step. What carries over from the derivation is the
// direction: USL's step map contracts phase space relative to USF's and
// MUSL's (det < 1 against det = 1), so over 4 periods USL ends with less
// energy than either, and no order drifts by more than the O(h w) bound.
struct BarRun {
  nlohmann::json summary;
  std::vector<Real> period_energy;  // K + S averaged over each period, over E0
};

BarRun run_bar(const std::string& kernel, UpdateOrder order, int cells = 16, Real t_end = 40) {
  const Scene scene = load_scene("bar", {.cells = cells,
                                         .transfer = std::string("flip"),
                                         .kernel = kernel,
                                         .update_order = std::string(update_order_name(order)),
                                         .t_end = t_end});
  const auto dir = std::filesystem::temp_directory_path() /
                   ("mpmtb_bar_order_" + kernel + std::string(update_order_name(order)) +
                    std::to_string(cells) + "_" + std::to_string(static_cast<int>(t_end)));
  const RunOutcome r = run_scene(scene, dir);
  EXPECT_EQ(r.status, "ok") << r.reason;
  // series.csv: columns t (1) and total (5).
  std::ifstream in(dir / "series.csv");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("step,t,kinetic,strain,gravity,total,", 0), 0u) << line;
  constexpr Real kPeriod = 10;  // the bar's first mode
  const int periods = static_cast<int>(std::lround(t_end / kPeriod));
  std::vector<Real> sum(periods, 0), count(periods, 0);
  Real E0 = 0;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::vector<Real> cells_of_row;
    for (std::string c; std::getline(ss, c, ',') && cells_of_row.size() < 6;)
      cells_of_row.push_back(std::stod(c));
    const Real t = cells_of_row[1], total = cells_of_row[5];
    if (t == 0) E0 = total;
    const int k = std::min(periods - 1, static_cast<int>(t / kPeriod));
    sum[k] += total;
    count[k] += 1;
  }
  std::filesystem::remove_all(dir);
  BarRun out{r.summary, {}};
  for (int k = 0; k < periods; ++k) out.period_energy.push_back(sum[k] / count[k] / E0);
  return out;
}

class BarOrder : public ::testing::TestWithParam<std::string> {};

TEST_P(BarOrder, UslEndsWithLessEnergyAndNoOrderDrifts) {
  const std::string kernel = GetParam();
  const Real hw = 0.2 * 1.5625 / 10 * (2 * kPi / 10);  // cfl dx / c times omega_1
  std::map<UpdateOrder, Real> last;
  for (UpdateOrder o : {UpdateOrder::usl, UpdateOrder::usf, UpdateOrder::musl}) {
    const BarRun r = run_bar(kernel, o);
    ASSERT_EQ(r.period_energy.size(), 4u);
    last[o] = r.period_energy.back();
    for (Real e : r.period_energy) EXPECT_NEAR(e, 1, hw) << update_order_name(o);
    RecordProperty(std::string(update_order_name(o)) + "_energy_last_period",
                   std::to_string(last[o]));
  }
  EXPECT_LT(last[UpdateOrder::usl], last[UpdateOrder::usf]);
  EXPECT_LT(last[UpdateOrder::usl], last[UpdateOrder::musl]);
}

// MUSL keeps the exact-solution bands of bar_test.cpp (2.5 % of the v_cm
// amplitude: over 4 periods at 32 cells, and over the first period at 16),
// as USL does with the same transfer.
TEST_P(BarOrder, MuslKeepsTheVcmBands) {
  const std::string kernel = GetParam();
  const Real four_periods = run_bar(kernel, UpdateOrder::musl, 32).summary["error"]["vcm_rel"];
  EXPECT_LT(four_periods, 0.025);
  const Real one_period = run_bar(kernel, UpdateOrder::musl, 16, 10).summary["error"]["vcm_rel"];
  EXPECT_LT(one_period, 0.025);
}

INSTANTIATE_TEST_SUITE_P(Kernels, BarOrder, ::testing::Values("linear", "quadratic"));

}  // namespace update_order_test
}  // namespace mpmtb
