// Forced blow-ups through the program: each failure reason the step loop
// detects ends the run as `unstable` (exit status 3) with its step, time and
// reason, and a partial series that parses back with finite rows. And the
// time-step check against the CFL limit dt_cfl = dx / (c_p + max|v|).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "support/cli.hpp"

namespace mpmtb {
namespace failure_test {

using testing::run_cli;
using testing::scratch_path;

constexpr int kUnstable = 3;

struct RunFiles {
  testing::CliResult cli;
  nlohmann::json summary;
  testing::Csv series;
};

RunFiles run_scene(const std::string& args) {
  const auto out = scratch_path("failure_out");
  RunFiles r;
  r.cli = run_cli("run " + args + " --out " + out.string());
  r.summary = testing::read_json(out / "summary.json");
  r.series = testing::read_csv(out / "series.csv");
  // Atomic writes leave no temporary file behind.
  for (const auto& f : std::filesystem::directory_iterator(out)) {
    EXPECT_EQ(f.path().filename().string().find(".tmp"), std::string::npos) << f.path();
  }
  std::filesystem::remove_all(out);
  return r;
}

// The contract of an unstable run; `reason` must appear in the summary's reason.
void expect_unstable(const RunFiles& r, const std::string& reason) {
  EXPECT_EQ(r.cli.status, kUnstable) << r.cli.err;
  const auto& j = r.summary;
  ASSERT_EQ(j["status"], "unstable");
  EXPECT_NE(j["reason"].get<std::string>().find(reason), std::string::npos) << j["reason"];
  EXPECT_GE(j["fail_step"].get<long>(), 1);
  EXPECT_EQ(j["fail_step"], j["steps"]);
  EXPECT_GT(j["fail_t"].get<double>(), 0);
  EXPECT_LT(j["fail_t"].get<double>(), j["t_end"].get<double>());
  // The series up to the failure: the header, then rows of finite numbers
  // whose steps increase and stop at or before the failing step.
  ASSERT_TRUE(r.series.ok) << r.series.problem;
  ASSERT_GE(r.series.rows.size(), 1u);
  const int step = r.series.column("step");
  ASSERT_EQ(step, 0);
  EXPECT_EQ(r.series.rows.front()[step], 0);
  double last = -1;
  for (const auto& row : r.series.rows) {
    for (double v : row) EXPECT_TRUE(std::isfinite(v));
    EXPECT_GT(row[step], last);
    last = row[step];
  }
  EXPECT_LE(last, j["fail_step"].get<double>());
  EXPECT_NE(r.cli.err.find(" unstable: "), std::string::npos) << r.cli.err;
  EXPECT_NE(r.cli.err.find(reason), std::string::npos) << r.cli.err;
}

// Bar (E = 100, rho = 1, dx = 25/16, c = 10): its mode-1 velocity v0 sin(beta x),
// beta = pi / 50, compresses the bar at x = 0 when v0 < 0; one step of dt = 1 maps
// J to 1 + dt v0 beta, which is -0.26 for v0 = -20: the element inverts.
TEST(Unstable, InvertedElement) {
  expect_unstable(run_scene("bar --dt 1 --set reference.v0=-20"), "J <= 0");
}

// The same with v0 = -5: J = 1 - 5 pi / 50 = 0.69, above zero, below a floor of 0.8.
TEST(Unstable, VolumeBelowTheConfiguredFloor) {
  const RunFiles r = run_scene("bar --dt 1 --set reference.v0=-5 --set checks.J_floor=0.8");
  expect_unstable(r, "J <= checks.J_floor = 0.8");
  const RunFiles fine = run_scene("bar --dt 1 --t-end 1 --set reference.v0=-5");
  EXPECT_EQ(fine.summary["status"], "ok") << "without the floor, J = 0.69 is accepted";
}

// A body thrown at 100 m/s, one step of 0.1 s: it travels 10 domain widths.
TEST(Unstable, ParticleLeavesTheDomain) {
  expect_unstable(run_scene("rotating --dt 0.1 --set bodies.0.velocity=[100,0]"),
                  "left the domain");
}

// E = 1e300 with dt 1e150 times the CFL limit: the stress overflows to Inf
// within two steps. The energy check (at output times only) is pushed away so
// that the per-step NaN/Inf check is what stops the run.
TEST(Unstable, NonFiniteValues) {
  expect_unstable(run_scene("rotating --dt 0.01 --t-end 100 --set materials.jelly.E=1e300 "
                            "--set checks.energy_limit=1e299 --set time.output_interval=100"),
                  "non-finite value (NaN/Inf)");
}

// dt = 1.6 dx / c: past the explicit stability limit (dt <= dx / c), every
// mode with a large enough wave number is amplified each step, and the energy
// soon exceeds twice what was put in while J stays positive.
TEST(Unstable, EnergyAboveTheBound) {
  const RunFiles r = run_scene("bar --dt 0.25");
  expect_unstable(r, "energy grew to");
  const testing::Csv& s = r.series;
  const int kinetic = s.column("kinetic"), strain = s.column("strain");
  const auto& first = s.rows.front();
  const auto& last = s.rows.back();
  EXPECT_GT(last[kinetic] + last[strain], 2 * (first[kinetic] + first[strain]))
      << "the last row is the one that crossed the bound";
}

// --dt above the CFL limit of the current state: one warning on stderr and
// the largest ratio with its first step in the summary.
TEST(TimeStep, FixedStepAboveTheCflLimitIsReported) {
  const RunFiles r = run_scene("bar --dt 0.17 --t-end 1.7");
  const size_t warnings = [&] {
    size_t n = 0;
    for (auto at = r.cli.err.find("warning:"); at != std::string::npos;
         at = r.cli.err.find("warning:", at + 1))
      ++n;
    return n;
  }();
  EXPECT_EQ(warnings, 1u) << r.cli.err;
  EXPECT_NE(r.cli.err.find("exceeds the CFL limit"), std::string::npos);
  const auto& j = r.summary;
  ASSERT_TRUE(j.contains("dt_cfl_exceeded")) << j.dump(2);
  EXPECT_EQ(j["dt_cfl_exceeded"]["first_step"], 0);
  // dt_cfl <= dx / c = 0.15625, so the ratio is at least 0.17 / 0.15625.
  EXPECT_GE(j["dt_cfl_exceeded"]["ratio_max"].get<double>(), 0.17 / 0.15625);
  EXPECT_EQ(j["dt_cfl_exceeded"]["ratio_max"], j["dt_cfl_ratio_max"]);
}

TEST(TimeStep, FixedStepBelowTheCflLimitIsNotReported) {
  const RunFiles r = run_scene("bar --dt 0.05 --t-end 2");
  EXPECT_EQ(r.summary["status"], "ok");
  EXPECT_EQ(r.cli.err.find("warning"), std::string::npos) << r.cli.err;
  EXPECT_FALSE(r.summary.contains("dt_cfl_exceeded"));
  // dt / dt_cfl = dt (c + max|v|) / dx with max|v| <= v0 = 0.1.
  EXPECT_NEAR(r.summary["dt_cfl_ratio_max"].get<double>(), 0.05 * 10.05 / 1.5625,
              0.05 * 0.05 / 1.5625);
}

// With --cfl the step is recomputed from the current state every step, so
// dt / dt_cfl equals the CFL number throughout (the last step may be shorter),
// while dt itself follows max|v|.
TEST(TimeStep, CflStepIsAdaptedEachStep) {
  const RunFiles r = run_scene("bar --cfl 0.5 --t-end 4 --set reference.v0=2");
  EXPECT_EQ(r.summary["status"], "ok");
  EXPECT_NEAR(r.summary["dt_cfl_ratio_max"].get<double>(), 0.5, 1e-14);
  EXPECT_FALSE(r.summary.contains("dt_cfl_exceeded"));
  // dt = 0.5 dx / (c + max|v|), c = 10. The fastest particle sits at L - dx/4
  // (2 per cell), so the first step has max|v| = 2 sin(beta (L - dx/4)) =
  // 2 cos(pi dx / (8 L)) = 2 cos(pi / 128); at a quarter period (t = 2.5) the
  // bar is at rest and max|v| << 1.
  const double dt_min = r.summary["dt_min"], dt_max = r.summary["dt_max"];
  const double v_first = 2 * std::cos(std::numbers::pi / 128);
  EXPECT_NEAR(dt_min, 0.5 * 1.5625 / (10 + v_first), 1e-12);
  EXPECT_GT(dt_max, 0.5 * 1.5625 / 11);
  EXPECT_LE(dt_max, 0.5 * 1.5625 / 10 * (1 + 1e-12));
}

}  // namespace failure_test
}  // namespace mpmtb
