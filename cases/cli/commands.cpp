#include "commands.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <iostream>
#include <set>

#include "archive.hpp"
#include "checkpoint.hpp"
#include "citations.hpp"
#include "core/errors.hpp"
#include "core/registry.hpp"
#include "memory.hpp"
#include "models/registry.hpp"
#include "output.hpp"
#include "progress.hpp"
#include "reproduce.hpp"
#include "version.hpp"

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

int exit_status(const RunOutcome& r) {
  if (r.status == "interrupted") return r.stop_exit;
  return exit_status(r.status);
}

// --out must be a folder, or a path where one can be made: an existing file
// there (or in its place among its parents) is refused before anything runs or
// is written, instead of a filesystem error part way.
void check_out_dir(const std::filesystem::path& out) {
  std::error_code ec;
  for (auto p = out; !p.empty(); p = p.parent_path()) {
    if (!std::filesystem::exists(p, ec)) {
      if (p == p.parent_path()) break;
      continue;
    }
    if (!std::filesystem::is_directory(p, ec)) {
      throw InputError(fmt::format(
          "--out '{}': '{}' is an existing file, not a folder; give a new or an existing folder",
          out.string(), p.string()));
    }
    break;
  }
}

bool any_override(const Overrides& o) {
  return o.dim || o.cells || o.ppc || o.transfer || o.kernel || o.update_order || o.integrator ||
         o.model || o.cfl || o.dt || o.t_end || !o.set.empty();
}

// `mpmtb run --resume DIR`: the checkpoint's scene and options, continued in DIR.
int resume_run(const RunRequest& request, RunOptions options) {
  const std::filesystem::path dir = request.resume;
  if (!request.scene.empty() || !request.config.empty() || any_override(request.overrides)) {
    throw InputError(
        "--resume continues a run as it was configured: give no scene, --config or scene "
        "override (--dim, --cells, --set, ...)");
  }
  std::error_code ec;
  if (!request.out.empty() && std::filesystem::weakly_canonical(request.out, ec) !=
                                  std::filesystem::weakly_canonical(dir, ec)) {
    throw InputError(fmt::format(
        "--resume continues the run in its own folder '{}': drop --out '{}' (or give the same "
        "folder)",
        dir.string(), request.out));
  }
  const auto file = checkpoint_file(dir);
  if (!std::filesystem::is_regular_file(file, ec)) {
    throw InputError(fmt::format(
        "--resume '{}': no checkpoint ({} is missing). A run writes one when it is stopped "
        "(SIGINT, SIGTERM, --wall-limit) and every --checkpoint-every T, and removes it when "
        "it finishes",
        dir.string(), file.string()));
  }
  ArchiveReader archive = ArchiveReader::from_file(file);
  const nlohmann::json meta = read_checkpoint_meta(archive);
  const Scene scene = load_recorded_scene(meta, meta.value("source", file.string()));
  const std::optional<int> threads = recorded_threads(meta);
  if (options.threads == 0) {
    options.threads = threads.value_or(0);
  } else if (threads && *threads != options.threads) {
    fmt::print(stderr,
               "mpmtb: warning: resuming with {} threads, the run used {}: the output agrees to "
               "round-off, not bit for bit\n",
               options.threads, *threads);
  }
  if (meta.value("git_revision", "") != build_info().git_revision) {
    fmt::print(stderr,
               "mpmtb: warning: the checkpoint was written by revision {}, this is {}: the "
               "output may differ from an uninterrupted run\n",
               meta.value("git_revision", "?"), build_info().git_revision);
  }
  if (const auto& f = meta["frames"]; f.is_object()) {
    options.frames.every = f.value("every", 0L);
    options.frames.interval = f.value("interval", 0.0);
    options.frames.grid = f.value("grid", false);
  }
  if (options.checkpoint_every == 0) options.checkpoint_every = meta.value("checkpoint_every", 0.0);
  options.resume = &archive;
  options.label = dir.string();
  const RunOutcome r = run_scene(scene, dir, options);
  if (!request.quiet) {
    fmt::print(stderr, "{:<24} {}{}{}\n", dir.string(), r.status, r.reason.empty() ? "" : ": ",
               r.reason);
  }
  return exit_status(r);
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
  RunOptions options = request.options;
  options.progress = Progress::wanted(request.quiet);
  if (!request.max_memory.empty())
    options.max_memory = parse_bytes(request.max_memory, "--max-memory");
  if (!request.resume.empty()) return resume_run(request, options);
  if (request.out.empty()) throw InputError("run: --out DIR is required (the output folder)");
  check_out_dir(request.out);
  const auto transfers = expand(request.overrides.transfer, transfer_list());
  const auto kernels = expand(request.overrides.kernel, kernel_list());
  const bool sweep = transfers.size() > 1 || kernels.size() > 1;
  std::vector<std::pair<std::string, RunOutcome>> runs;
  int worst = kExitOk;
  // --config: the recorded scene (and thread count, for identical output).
  nlohmann::json recorded;
  if (!request.config.empty()) {
    recorded = read_summary(request.config);
    if (options.threads == 0) options.threads = recorded_threads(recorded).value_or(0);
  }
  auto load = [&](const Overrides& o) {
    return request.config.empty() ? load_scene(request.scene, o)
                                  : load_recorded_scene(recorded, request.config, o);
  };
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
      const bool stopped = r.status == "interrupted";
      worst = stopped ? exit_status(r) : std::max(worst, exit_status(r));
      runs.emplace_back(name, std::move(r));
      if (stopped) break;  // a stop ends the sweep too
    }
    if (!runs.empty() && runs.back().second.status == "interrupted") break;
  }
  if (sweep) write_runs_table(request.out, runs);
  return worst;
}

}  // namespace mpmtb
