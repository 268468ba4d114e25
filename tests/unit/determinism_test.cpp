// Determinism through the program: the same inputs and thread count give
// bit-identical series.csv and summary.json (timing fields aside); 1 and 2
// threads agree to round-off. The scenes have more than kParallelMinimum
// particles, so the loops do run in parallel.
#include <gtest/gtest.h>

#include <string>

#include <cmath>

#include "core/types.hpp"
#include "support/cli.hpp"

namespace mpmtb {
namespace determinism_test {

struct Output {
  std::string series;
  nlohmann::json summary;
};

Output run(const std::string& args, int threads) {
  const auto out = testing::scratch_path("determinism_" + std::to_string(threads));
  const auto r = testing::run_cli("run " + args + " --threads " + std::to_string(threads) +
                                  " --out " + out.string());
  EXPECT_EQ(r.status, 0) << r.err;
  Output o{testing::read_text(out / "series.csv"), testing::read_json(out / "summary.json")};
  EXPECT_GE(o.summary["particles"].get<long>(), kParallelMinimum);
  EXPECT_EQ(o.summary["threads"], threads);
  // Measured times and the thread count are not results.
  for (const char* key : {"wall_seconds", "step_seconds", "particle_steps_per_second",
                          "ns_per_particle_step", "threads"}) {
    o.summary.erase(key);
  }
  std::filesystem::remove_all(out);
  return o;
}

// Every number of two JSON documents agrees to `rel` of its magnitude (or of
// `floor` for numbers near zero, such as drifts that are round-off themselves);
// everything else is equal.
void expect_close(const nlohmann::json& a, const nlohmann::json& b, double rel, double floor,
                  const std::string& path = "") {
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    EXPECT_LE(std::abs(x - y), rel * std::max({std::abs(x), std::abs(y), floor})) << path;
  } else if (a.is_object() && b.is_object()) {
    EXPECT_EQ(a.size(), b.size()) << path;
    for (const auto& [k, v] : a.items()) {
      ASSERT_TRUE(b.contains(k)) << path << "." << k;
      expect_close(v, b[k], rel, floor, path + "." + k);
    }
  } else {
    EXPECT_EQ(a, b) << path;
  }
}

class Determinism : public ::testing::TestWithParam<std::string> {};

TEST_P(Determinism, SameThreadsBitIdenticalAcrossThreadsToRoundOff) {
  const Output a = run(GetParam(), 2), b = run(GetParam(), 2), one = run(GetParam(), 1);
  EXPECT_EQ(a.series, b.series) << "same inputs, same threads: bit-identical series";
  EXPECT_EQ(a.summary, b.summary) << "same inputs, same threads: bit-identical summary";
  // Scatter order is fixed, so only the reductions' order may differ: round-off.
  const auto csv_a = testing::read_csv_text(a.series), csv_1 = testing::read_csv_text(one.series);
  ASSERT_TRUE(csv_a.ok && csv_1.ok);
  ASSERT_EQ(csv_a.header, csv_1.header);
  ASSERT_EQ(csv_a.rows.size(), csv_1.rows.size());
  // Round-off of a vector component is relative to the vector (px, py, pz;
  // pin_impulse_x, _y, _z), since a component that is zero by symmetry has no scale.
  auto family = [](const std::string& name) {
    const auto n = name.size();
    if (n > 2 && name[n - 2] == '_' && std::string("xyz").find(name[n - 1]) != std::string::npos)
      return name.substr(0, n - 2);
    if (n == 2 && std::string("pL").find(name[0]) != std::string::npos) return name.substr(0, 1);
    return name;
  };
  for (std::size_t c = 0; c < csv_a.header.size(); ++c) {
    double scale = 0;
    for (std::size_t k = 0; k < csv_a.header.size(); ++k) {
      if (family(csv_a.header[k]) != family(csv_a.header[c])) continue;
      for (const auto& row : csv_a.rows) scale = std::max(scale, std::abs(row[k]));
    }
    for (std::size_t i = 0; i < csv_a.rows.size(); ++i) {
      EXPECT_LE(std::abs(csv_a.rows[i][c] - csv_1.rows[i][c]), 1e-12 * scale)
          << csv_a.header[c] << " row " << i;
    }
  }
  expect_close(a.summary, one.summary, 1e-10, 1e-2);
}

std::string SceneName(const ::testing::TestParamInfo<std::string>& info) {
  static const char* const names[] = {"rotating", "pinned_block", "rotating_xpic",
                                      "rotating_polypic"};
  return names[info.index];
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, Determinism,
    ::testing::Values(
        // 2D spinning square, affine transfer: 5,776 particles.
        "rotating --cells 64 --ppc 4 --t-end 0.03",
        // A pinned strip struck by a collider, FLIP: pins and colliders reduce over nodes.
        "pinned_block --transfer flip --cells 32 --t-end 0.004 --set time.output_interval=0.001",
        // The extra passes of XPIC (grid projections in P2G's colour order) and
        // PolyPIC's per-particle transfer state.
        "rotating --transfer xpic --cells 64 --ppc 4 --t-end 0.03",
        "rotating --transfer polypic --cells 64 --ppc 4 --t-end 0.03"),
    SceneName);

}  // namespace determinism_test
}  // namespace mpmtb
