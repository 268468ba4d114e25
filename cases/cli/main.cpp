// mpmtb: the command-line front end of the MPM verification testbed.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <exception>
#include <new>

#include "boundary/walls.hpp"
#include "commands.hpp"
#include "compare/compare.hpp"
#include "core/errors.hpp"
#include "core/registry.hpp"
#include "models/registry.hpp"
#include "suite/suite.hpp"
#include "version.hpp"

#ifndef MPMTB_SOURCE_DIR
#define MPMTB_SOURCE_DIR "."
#endif

namespace {

template <class List>
std::string names(const List& list) {
  std::vector<std::string> n;
  for (const auto& v : list) n.push_back(v.name);
  return fmt::format("{}", fmt::join(n, ", "));
}

// Options that override a scene, shared by `run` and `describe`. Their default
// is the scene's own value (`mpmtb describe SCENE` prints it).
void add_override_options(CLI::App& cmd, mpmtb::Overrides& o) {
  cmd.add_option("--dim", o.dim, "dimension: 1, 2 or 3 (default: the scene's [scene] dim)")
      ->check(CLI::Range(1, 3));
  // Ranges of --cells and --ppc are checked with the scene (grid.cells, grid.ppc).
  cmd.add_option("--transfer", o.transfer,
                 fmt::format("transfer scheme: {}, or `all` for a sweep (default: the scene's "
                             "[method] transfer)",
                             names(mpmtb::transfer_list())));
  cmd.add_option(
      "--kernel", o.kernel,
      fmt::format("kernel: {}, or `all` for a sweep (default: the scene's [method] kernel)",
                  names(mpmtb::kernel_list())));
  cmd.add_option("--update-order", o.update_order,
                 fmt::format("stress-update order: {} (default: the scene's [method] "
                             "update_order, or usl)",
                             fmt::join(mpmtb::kUpdateOrderNames, ", ")));
  cmd.add_option("--integrator", o.integrator,
                 fmt::format("time integrator: {} (default: the scene's [method] integrator, "
                             "or explicit; the implicit ones need a gradient-based transfer)",
                             fmt::join(mpmtb::kIntegratorNames, ", ")));
  cmd.add_option("--model", o.model,
                 fmt::format("constitutive model for every material: {} (default: each "
                             "material's own)",
                             names(mpmtb::model_list())));
  cmd.add_option("--cells", o.cells,
                 "cells along the scene's grid.length, integer >= 1 (default: [grid] cells)");
  cmd.add_option("--ppc", o.ppc, "particles per cell per axis, 1..16 (default: [grid] ppc, or 2)");
  auto* cfl = cmd.add_option("--cfl", o.cfl,
                             "adaptive step dt = cfl dx / (c_p + max|v|), > 0 (replaces the "
                             "scene's dt or cfl)");
  auto* dt = cmd.add_option("--dt", o.dt, "fixed time step, > 0 (replaces the scene's dt or cfl)");
  cfl->excludes(dt);
  cmd.add_option("--t-end", o.t_end, "end time, > 0 (default: [time] t_end)");
  cmd.add_option("--set", o.set,
                 "override any scene field: key.path=value, the value in TOML, e.g. "
                 "materials.steel.E=2e9 or bodies.0.velocity=[1,0] (repeatable)");
}

// `mpmtb render RUN_DIR ...`: hands the arguments to analysis/render.py.
int forward_to_render(const std::vector<std::string>& args) {
  const std::string script = std::string(MPMTB_SOURCE_DIR) + "/analysis/render.py";
  std::vector<std::string> argv_s = {"/usr/bin/python3", script};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  ::execv(argv[0], argv.data());
  fmt::print(stderr, "mpmtb: cannot run {} {}\n", argv_s[0], script);
  return mpmtb::kExitError;
}

// `mpmtb suite ...`: resumable parallel sweeps (cases/suite/).
CLI::App* add_suite_command(CLI::App& app, mpmtb::SuiteRequest& r) {
  auto* cmd = app.add_subcommand("suite", "run a suite of runs and write its tables");
  cmd->add_option("name", r.name, "convergence | stability | speed-accuracy | all")
      ->required()
      ->check(CLI::IsMember({"convergence", "stability", "speed-accuracy", "all"}));
  auto* quick = cmd->add_flag("--quick")->description("the quick levels (default)");
  cmd->add_flag("--full", r.full, "the full levels, for real studies")->excludes(quick);
  cmd->add_option("--jobs", r.jobs, "runs at once, each with one thread (default: cores)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--out", r.out, "output folder (default results/suites)");
  cmd->add_flag("--quiet", r.quiet, "no progress on stderr");
  cmd->add_option("--case", r.cases, "only these cases (repeatable)");
  cmd->add_option("--transfer", r.transfers, "only these transfers (repeatable)");
  cmd->add_option("--kernel", r.kernels, "only these kernels (repeatable)");
  cmd->add_option("--integrator", r.integrators,
                  fmt::format("only these time integrators (repeatable): {}; the implicit ones run "
                              "where a case lists them, in the convergence suite only when named",
                              fmt::join(mpmtb::kIntegratorNames, ", ")));
  auto* shard = cmd->add_option(
      "--shard", r.shard,
      "K/N: run only the K-th of N disjoint parts of the run list (balanced by estimated cost), "
      "write no tables; every shard and --collect take the same NAME, level, filters and --out");
  cmd->add_flag("--collect", r.collect,
                "run nothing: write the tables once every run has its done.json, otherwise list "
                "the missing runs and exit with status 4")
      ->excludes(shard);
  return cmd;
}

// `mpmtb compare OLD NEW`: results trees metric by metric (cases/compare/).
CLI::App* add_compare_command(CLI::App& app, mpmtb::compare::CompareRequest& r) {
  auto* cmd = app.add_subcommand(
      "compare",
      "compare two results trees (summary.json, runs.csv, suite tables) metric by metric; exit "
      "status 0 when nothing changed beyond tolerance, 1 when something did, 2 for bad input");
  cmd->add_option("old", r.old_root, "the reference tree (or file), e.g. results/baseline")
      ->required();
  cmd->add_option("new", r.new_root, "the tree (or file) to check")->required();
  cmd->add_option("--tolerances", r.tolerances,
                  "tolerance file (TOML; default: the built-in cases/compare/tolerances.toml)");
  cmd->add_option("--limit", r.limit, "rows of the table of changes to print, 0: all")
      ->capture_default_str();
  return cmd;
}

// A message on one line: control characters from user strings are escaped.
std::string one_line(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (static_cast<unsigned char>(c) < 0x20) {
      out += fmt::format("\\x{:02x}", static_cast<unsigned char>(c));
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "mpmtb: Material Point Method verification testbed.\n"
      "Runs MPM variants (transfer x kernel x model) on canonical scenes and writes\n"
      "series.csv and summary.json; see `mpmtb list` and `mpmtb <command> --help`.\n"
      "Exit status: 0 ok, 1 program error, 2 invalid input, 3 unstable run."};
  app.require_subcommand(1);
  // Version, git revision and the flags that decide the floating-point results.
  app.set_version_flag("--version", mpmtb::version_text(), "print the version and build flags");

  std::string list_only;
  auto* list = app.add_subcommand(
      "list", "list transfers, kernels, models, walls and scenes, with citations");
  list->add_option("what", list_only,
                   "print only the names of one group: transfers|kernels|models|scenes")
      ->check(CLI::IsMember({"transfers", "kernels", "models", "scenes"}));
  bool list_bibtex = false;
  list->add_flag("--bibtex", list_bibtex,
                 "print the BibTeX of the papers behind every registered transfer, kernel and "
                 "model, each entry once with the variants it backs");

  mpmtb::RunRequest run_request;
  auto* run = app.add_subcommand(
      "run",
      "run a scene and write DIR/series.csv and DIR/summary.json (and ParaView frames with "
      "--frames-every/--frames-dt)");
  auto* scene_opt = run->add_option("scene", run_request.scene,
                                    "built-in scene name (see `mpmtb list`) or a "
                                    "scene file (.toml)");
  auto* config_opt = run->add_option(
      "--config", run_request.config,
      "re-run the configuration recorded in a summary.json (scene tree after every override, "
      "and its thread count unless --threads is given); further overrides apply on top");
  scene_opt->excludes(config_opt);
  add_override_options(*run, run_request.overrides);
  run->add_option("--threads", run_request.options.threads,
                  "OpenMP threads, 0: OpenMP's default (OMP_NUM_THREADS or all cores)")
      ->check(CLI::Range(0, 4096))
      ->capture_default_str();
  run->add_option("--frames-every", run_request.options.frames.every,
                  "write a particle frame every K steps (0: off) to DIR/frames/*.vtp, indexed "
                  "by DIR/particles.pvd for ParaView")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  run->add_option("--frames-dt", run_request.options.frames.interval,
                  "write a particle frame every T of simulated time (0: off); may be combined "
                  "with --frames-every. The first and last states are always written")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  run->add_flag("--frames-grid", run_request.options.frames.grid,
                "with frames, also write the grid (nodal mass, velocity) as DIR/frames/*.vti "
                "and DIR/grid.pvd")
      ->capture_default_str();
  run->add_flag("-q,--quiet", run_request.quiet,
                "no progress line and no status line (a progress line is drawn only when "
                "stderr is a terminal)")
      ->capture_default_str();
  run->add_option("--out", run_request.out,
                  "output folder (created; files in it are replaced); required unless --resume");
  run->add_option("--wall-limit", run_request.options.wall_limit,
                  "stop cleanly after SECONDS of wall time, as on SIGINT/SIGTERM: series and "
                  "summary (status interrupted) written, a checkpoint to --resume, exit 124")
      ->check(CLI::PositiveNumber);
  run->add_option("--checkpoint-every", run_request.options.checkpoint_every,
                  "write the complete state to DIR/checkpoint/state.bin every T of simulated "
                  "time (atomically; removed when the run finishes)")
      ->check(CLI::PositiveNumber);
  auto* resume_opt = run->add_option(
      "--resume", run_request.resume,
      "continue the stopped run in DIR from DIR/checkpoint/ with its own scene, options and "
      "thread count; the result equals an uninterrupted run byte for byte");
  resume_opt->excludes(scene_opt)->excludes(config_opt);
  run->add_option("--timing-repeats", run_request.options.timing.repeats,
                  "after a stable run, time its stepping N more times on a fresh state, each "
                  "repetition repeating the run until it has stepped --timing-min-seconds; "
                  "summary `timing`: seconds per run (wall, CPU) median/min/max (0: off)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  run->add_option("--timing-min-seconds", run_request.options.timing.min_seconds,
                  "stepping time of each timing repetition, at least")
      ->check(CLI::Range(0.0, 3600.0))
      ->capture_default_str();
  run->add_option("--max-memory", run_request.max_memory,
                  "memory the run may use, e.g. 64G or 512M (default: the machine's "
                  "MemAvailable); larger estimates are refused before anything is allocated");

  std::string describe_scene;
  mpmtb::Overrides describe_overrides;
  auto* describe = app.add_subcommand(
      "describe", "print a scene's effective parameters (defaults marked) after overrides");
  describe->add_option("scene", describe_scene, "built-in scene name or scene file")->required();
  add_override_options(*describe, describe_overrides);

  mpmtb::SuiteRequest suite_request;
  auto* suite = add_suite_command(app, suite_request);
  mpmtb::compare::CompareRequest compare_request;
  auto* compare = add_compare_command(app, compare_request);
  std::vector<std::string> render_args;
  auto* render = app.add_subcommand(
      "render",
      "draw a run's frames to PNG/GIF (forwards to /usr/bin/python3 analysis/render.py; "
      "`mpmtb render --help` lists its options)");
  render->allow_extras();
  render->prefix_command();
  render->set_help_flag();  // --help goes to render.py

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    // One line, like every other input error.
    fmt::print(stderr, "mpmtb: invalid input: command line: {}\n", one_line(e.what()));
    return mpmtb::kExitInvalid;
  }
  try {
    if (*list) return mpmtb::command_list(list_only, list_bibtex);
    if (*describe) return mpmtb::command_describe(describe_scene, describe_overrides);
    if (*suite) return mpmtb::command_suite(suite_request);
    if (*compare) return mpmtb::compare::command_compare(compare_request);
    if (*render) return forward_to_render(render->remaining());
    if (run_request.scene.empty() && run_request.config.empty() && run_request.resume.empty()) {
      throw mpmtb::InputError(
          "run: give a scene (name or file), --config DIR/summary.json or --resume DIR");
    }
    return mpmtb::command_run(run_request);
  } catch (const mpmtb::InputError& e) {
    fmt::print(stderr, "mpmtb: invalid input: {}\n", one_line(e.what()));
    return mpmtb::kExitInvalid;
  } catch (const std::bad_alloc&) {
    // The estimate (cases/memory.hpp) refuses what clearly does not fit; this is
    // what slips past it (other processes took the memory meanwhile).
    fmt::print(stderr,
               "mpmtb: invalid input: the run needs more memory than the machine could give (an "
               "allocation failed); reduce grid.cells, grid.ppc or the domain\n");
    return mpmtb::kExitInvalid;
  } catch (const std::exception& e) {
    fmt::print(stderr, "mpmtb: error: {}\n", one_line(e.what()));
    return mpmtb::kExitError;
  }
}
