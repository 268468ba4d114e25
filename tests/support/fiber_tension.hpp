// Runs of the fiber_tension scene (cases/scenes/fiber_tension.toml) for the
// verification and sweep tests: the aniso-damage plate with its fibres at
// theta degrees, or the same plate with the isotropic `damage` model at the
// plate's strength across the fibres (sigma_crit / (1 + alpha)^2).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "run.hpp"
#include "scene.hpp"

namespace mpmtb::testing {

struct Crack {
  double angle_deg = 0, length = 0, band_width = 0, dissipated = 0, damaged = 0;
};

inline Crack crack_of(const RunOutcome& r) {
  const auto& m = r.summary["measured"];
  return {m["crack_angle_deg"], m["crack_length"], m["band_width"], m["dissipated"],
          m["damaged_particles"]};
}

inline std::string fiber_tension_text() {
  for (const auto& s : builtin_scenes())
    if (s.name == "fiber_tension") return s.text;
  ADD_FAILURE() << "no built-in scene fiber_tension";
  return {};
}

// The plate with the `damage` model: the aniso-damage keys and the fibre are
// taken out, sigma_crit set to the aniso plate's strength across its fibres.
inline std::string isotropic_fiber_tension_text() {
  std::string text = fiber_tension_text();
  const auto drop_line = [&](const std::string& start) {
    const auto at = text.find("\n" + start);
    if (at == std::string::npos) return;
    text.erase(at, text.find('\n', at + 1) - at);
  };
  for (const char* key : {"alpha = ", "fiber_E = ", "fiber_k = ", "fiber = ", "sigma_crit = "})
    drop_line(key);
  const std::string model = "model = \"aniso-damage\"";
  text.replace(text.find(model), model.size(), "model = \"damage\"\nsigma_crit = 2.48e3");
  return text;
}

inline RunOutcome run_fiber_tension(const std::string& text, const std::string& label,
                                    const Overrides& o) {
  const Scene scene = scene_from_text(text, "fiber_tension", o);
  // Runs of one label with other overrides (the end time, the sets) get their
  // own folder: ctest runs the tests in parallel.
  std::string key = std::to_string(o.t_end.value_or(0));
  for (const std::string& s : o.set) key += ";" + s;
  const auto dir = std::filesystem::temp_directory_path() /
                   ("mpmtb_fiber_tension_" + label + "_" +
                    std::to_string(std::hash<std::string>{}(key) % 1000003));
  const RunOutcome r = run_scene(scene, dir, {.threads = 1});
  EXPECT_EQ(r.status, "ok") << label << ": " << r.reason;
  std::filesystem::remove_all(dir);
  return r;
}

// aniso-damage with the fibres at theta degrees from x, in the x-y plane.
inline Crack aniso_crack(double theta_deg, Overrides o = {}) {
  const double t = theta_deg * std::numbers::pi / 180;
  o.set.push_back("bodies.0.fiber=[" + std::to_string(std::cos(t)) + "," +
                  std::to_string(std::sin(t)) + ",0.0]");
  const std::string label = "theta" + std::to_string(static_cast<int>(theta_deg)) + "_c" +
                            std::to_string(o.cells.value_or(0)) + "_d" +
                            std::to_string(o.dim.value_or(2));
  return crack_of(run_fiber_tension(fiber_tension_text(), label, o));
}

inline Crack isotropic_crack(const Overrides& o = {}) {
  const std::string label =
      "iso_c" + std::to_string(o.cells.value_or(0)) + "_d" + std::to_string(o.dim.value_or(2));
  return crack_of(run_fiber_tension(isotropic_fiber_tension_text(), label, o));
}

}  // namespace mpmtb::testing
