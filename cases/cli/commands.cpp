#include "commands.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <iostream>
#include <set>

#include "citations.hpp"
#include "core/errors.hpp"
#include "core/registry.hpp"
#include "models/registry.hpp"
#include "output.hpp"
#include "progress.hpp"
#include "reproduce.hpp"

namespace mpmtb {
namespace {

std::string number_field(const nlohmann::json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? fmt::format("{:.10g}", j[key].get<double>()) : "";
}

// DIR/runs.csv: one row per combination; the error norms against the reference
// as error_<name> columns and what the case measured (bar: period; column:
// run-out) as measured_<name> columns, numbers only.
void write_runs_table(const std::filesystem::path& dir,
                      const std::vector<std::pair<std::string, RunOutcome>>& runs) {
  const std::array<std::string, 2> groups = {"error", "measured"};
  std::array<std::set<std::string>, 2> names;
  for (const auto& [name, r] : runs) {
    for (std::size_t g = 0; g < groups.size(); ++g) {
      if (!r.summary.contains(groups[g]) || !r.summary[groups[g]].is_object()) continue;
      for (const auto& [k, v] : r.summary[groups[g]].items())
        if (v.is_number()) names[g].insert(k);
    }
  }
  std::string out =
      "run,transfer,kernel,dim,status,reason,particles,steps,wall_seconds,"
      "particle_steps_per_second,drift_energy,drift_momentum,drift_angular_momentum,drift_volume";
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (const auto& e : names[g]) out += fmt::format(",{}_{}", groups[g], e);
  out += '\n';
  for (const auto& [name, r] : runs) {
    const auto& j = r.summary;
    const nlohmann::json drift = j.value("drift", nlohmann::json::object());
    out += fmt::format(
        "{},{},{},{},{},{},{},{},{},{},{},{},{},{}", name, j.value("transfer", ""),
        j.value("kernel", ""), j.contains("dim") ? std::to_string(j["dim"].get<int>()) : "",
        r.status, csv_field(r.reason), number_field(j, "particles"), number_field(j, "steps"),
        number_field(j, "wall_seconds"), number_field(j, "particle_steps_per_second"),
        number_field(drift, "energy"), number_field(drift, "momentum"),
        number_field(drift, "angular_momentum"), number_field(drift, "volume"));
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const nlohmann::json values = j.value(groups[g], nlohmann::json::object());
      for (const auto& e : names[g]) {
        out += ',';
        out += values.is_object() ? number_field(values, e.c_str()) : "";
      }
    }
    out += '\n';
  }
  write_atomically(dir / "runs.csv", out);
}

std::vector<std::string> expand(const std::optional<std::string>& choice,
                                const std::vector<VariantInfo>& all) {
  if (!choice || *choice != "all") return {choice.value_or("")};
  std::vector<std::string> names;
  for (const auto& v : all) names.push_back(v.name);
  return names;
}

int exit_status(const std::string& status) {
  if (status == "ok") return kExitOk;
  if (status == "unstable") return kExitUnstable;
  return kExitInvalid;
}

}  // namespace

int command_list(const std::string& only, bool bibtex) {
  if (bibtex) {
    fmt::print("{}", bibtex_listing());
    return kExitOk;
  }
  auto section = [&](const char* title, const char* how, const auto& items) {
    if (!only.empty() && only != title) return;
    if (only.empty()) fmt::print("{} ({}):\n", title, how);
    for (const auto& i : items) {
      if (only.empty()) {
        fmt::print("  {:<16} {}\n", i.name, i.description);
      } else {
        fmt::print("{}\n", i.name);
      }
    }
  };
  section("transfers", "--transfer, [method] transfer", transfer_list());
  section("kernels", "--kernel, [method] kernel", kernel_list());
  section("models", "--model, [materials.NAME] model", model_list());
  std::vector<VariantInfo> scenes;
  for (const auto& b : builtin_scenes()) {
    const Scene s = load_scene(b.name);
    scenes.push_back({b.name, fmt::format("{} (dims {})", s.description, fmt::join(s.dims, ","))});
  }
  section("scenes", "mpmtb run NAME; mpmtb describe NAME for its parameters", scenes);
  if (only.empty()) {
    const std::vector<VariantInfo> walls = {
        {"free", "open: nothing imposed"},
        {"sticky", "v = 0 on the face (no-slip)"},
        {"slip", "normal velocity removed, tangential kept"},
        {"separate", "normal velocity removed only while pressing into the wall"}};
    section("walls", "[boundary] x_min ... z_max, default; [[colliders]] wall", walls);
    std::vector<std::string> refused;
    for (const auto& t : transfer_list()) {
      for (const auto& k : kernel_list()) {
        if (auto r = unsupported_reason(t.name, k.name); !r.empty()) refused.push_back(r);
      }
    }
    fmt::print("refused combinations:{}\n", refused.empty() ? " none" : "");
    for (const auto& r : refused) fmt::print("  {}\n", r);
  }
  return kExitOk;
}

int command_run(const RunRequest& request) {
  const auto transfers = expand(request.overrides.transfer, transfer_list());
  const auto kernels = expand(request.overrides.kernel, kernel_list());
  const bool sweep = transfers.size() > 1 || kernels.size() > 1;
  std::vector<std::pair<std::string, RunOutcome>> runs;
  int worst = kExitOk;
  // --config: the recorded scene (and thread count, for identical output).
  nlohmann::json recorded;
  RunOptions options = request.options;
  if (!request.config.empty()) {
    recorded = read_summary(request.config);
    if (options.threads == 0) options.threads = recorded_threads(recorded).value_or(0);
  }
  auto load = [&](const Overrides& o) {
    return request.config.empty() ? load_scene(request.scene, o)
                                  : load_recorded_scene(recorded, request.config, o);
  };
  options.progress = Progress::wanted(request.quiet);
  const std::string label = request.config.empty() ? request.scene : request.config;
  for (const auto& t : transfers) {
    for (const auto& k : kernels) {
      Overrides o = request.overrides;
      if (!t.empty()) o.transfer = t;
      if (!k.empty()) o.kernel = k;
      const std::string name = fmt::format("{}-{}", t, k);
      const std::filesystem::path dir =
          sweep ? std::filesystem::path(request.out) / name : std::filesystem::path(request.out);
      RunOutcome r;
      try {
        const Scene scene = load(o);
        if (sweep) {
          if (auto why = unsupported_reason(scene.transfer, scene.kernel); !why.empty()) {
            // A refused combination is a data point of a sweep, not a failure.
            r = write_invalid(dir, why, {{"transfer", t}, {"kernel", k}, {"dim", scene.dim}});
            runs.emplace_back(name, r);
            if (!request.quiet) fmt::print(stderr, "{:<24} refused: {}\n", name, why);
            continue;
          }
        }
        options.label = sweep ? name : label;
        r = run_scene(scene, dir, options);
      } catch (const InputError& e) {
        if (!sweep) throw;
        r = write_invalid(dir, e.what(), {{"transfer", t}, {"kernel", k}});
      }
      if (!request.quiet) {
        fmt::print(stderr, "{:<24} {}{}{}\n", sweep ? name : label, r.status,
                   r.reason.empty() ? "" : ": ", r.reason);
      }
      worst = std::max(worst, exit_status(r.status));
      runs.emplace_back(name, std::move(r));
    }
  }
  if (sweep) write_runs_table(request.out, runs);
  return worst;
}

}  // namespace mpmtb
