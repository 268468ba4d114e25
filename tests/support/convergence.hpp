// Refinement studies on a scene with an analytic reference: run it over grid
// levels (the time step follows at the scene's fixed CFL) and read its error.
#pragma once

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "run.hpp"

namespace mpmtb::testing {

// summary.json's error.<norm> of one run; +inf for an unstable run (so that it
// counts as "not falling"). Single-threaded: the result is deterministic.
inline Real run_error(const std::string& scene_name, const Overrides& o,
                      const std::string& norm = "disp_l2") {
  const Scene scene = load_scene(scene_name, o);
  std::string tag = fmt::format("{}_{}d_{}_{}_{}", scene.name, scene.dim, scene.transfer,
                                scene.kernel, scene.cells);
  for (const auto& s : o.set) tag += fmt::format("_{}", std::hash<std::string>{}(s) % 100000);
  const auto dir = std::filesystem::temp_directory_path() / ("mpmtb_conv_" + tag);
  RunOptions options;
  options.threads = 1;
  const RunOutcome r = run_scene(scene, dir, options);
  if (r.status != "ok") return std::numeric_limits<Real>::infinity();
  return r.summary["error"][norm].get<Real>();
}

inline std::vector<Real> errors_over(const std::string& scene, const std::vector<int>& levels,
                                     Overrides o) {
  std::vector<Real> e;
  for (const int n : levels) {
    o.cells = n;
    e.push_back(run_error(scene, o));
  }
  return e;
}

// Observed orders log2(e_{k-1} / e_k).
inline std::vector<Real> orders_of(const std::vector<Real>& e) {
  std::vector<Real> r;
  for (std::size_t k = 1; k < e.size(); ++k) r.push_back(std::log2(e[k - 1] / e[k]));
  return r;
}

inline std::string error_table(const std::vector<int>& levels, const std::vector<Real>& e) {
  std::string s;
  for (std::size_t k = 0; k < e.size(); ++k) {
    s += std::isinf(e[k]) ? fmt::format("{} cells: unstable", levels[k])
                          : fmt::format("{} cells: {:.3e}", levels[k], e[k]);
    if (k > 0) s += fmt::format(" (order {:.2f})", std::log2(e[k - 1] / e[k]));
    s += "\n";
  }
  return s;
}

// The manufactured bar's large amplitude (REFERENCE.md: G = 0.05).
inline const std::vector<std::string> kLarge = {"reference.amplitude=0.05"};

using Combination = std::tuple<std::string, std::string>;  // transfer, kernel
inline std::string combination_name(const ::testing::TestParamInfo<Combination>& info) {
  return std::get<0>(info.param) + "_" + std::get<1>(info.param);
}

}  // namespace mpmtb::testing
