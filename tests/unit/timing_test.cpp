// Timings worth plotting (cases/timing.hpp): repetitions, minimum stepping
// time, and the statistics the work-precision tables read.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "run.hpp"
#include "suite/runner.hpp"
#include "timing.hpp"

namespace mpmtb {
namespace timing_test {

TEST(Timing, MedianOfOddAndEvenCounts) {
  EXPECT_EQ(median({3, 1, 2}), 2);
  EXPECT_EQ(median({4, 1, 3, 2}), 2.5);
  EXPECT_TRUE(std::isnan(median({})));
}

TEST(Timing, EachRepetitionStepsAtLeastTheMinimumAndCountsTheRunsWork) {
  Overrides o;
  o.cells = 8;
  o.t_end = 1.0;
  const Scene scene = load_scene("bar", o);
  const RunOutcome run =
      run_scene(scene, std::filesystem::temp_directory_path() / "mpmtb_timing_test");
  ASSERT_EQ(run.status, "ok");
  const nlohmann::json t = time_stepping(scene, {3, 0.02});
  EXPECT_EQ(t["repeats"], 3);
  ASSERT_EQ(t["repetitions"].size(), 3u);
  for (const auto& rep : t["repetitions"]) {
    EXPECT_GE(rep["seconds"].get<double>(), 0.02);
    EXPECT_GE(rep["passes"].get<long>(), 1);
    EXPECT_NEAR(rep["seconds_per_pass"].get<double>() * rep["passes"].get<double>(),
                rep["seconds"].get<double>(), 1e-12);
  }
  // A pass repeats the run exactly: its work is the run's.
  EXPECT_EQ(t["particle_steps"].get<double>(),
            run.summary["particles"].get<double>() * run.summary["steps"].get<double>());
  const auto& s = t["seconds_per_pass"];
  EXPECT_LE(s["min"].get<double>(), s["median"].get<double>());
  EXPECT_LE(s["median"].get<double>(), s["max"].get<double>());
  EXPECT_THROW(time_stepping(scene, {0, 0.5}), std::invalid_argument);
}

TEST(Timing, TimedSuiteRunsAskForTheirRepetitions) {
  suite::RunSpec spec;
  spec.scene = "bar";
  spec.transfer = "apic";
  spec.kernel = "quadratic";
  EXPECT_FALSE(spec.serial());
  spec.timing_repeats = 3;
  EXPECT_TRUE(spec.serial());
  const auto a = spec.arguments("out");
  const auto at = std::find(a.begin(), a.end(), "--timing-repeats");
  ASSERT_NE(at, a.end());
  EXPECT_EQ(*(at + 1), "3");
  EXPECT_NE(std::find(a.begin(), a.end(), "--timing-min-seconds"), a.end());
}

}  // namespace timing_test
}  // namespace mpmtb
