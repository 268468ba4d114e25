// mpmtb: the command-line front end of the MPM verification testbed.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <exception>

#include "commands.hpp"
#include "core/errors.hpp"
#include "suite/suite.hpp"

namespace {

// Options that override a scene, shared by `run` and `describe`.
void add_override_options(CLI::App& cmd, mpmtb::Overrides& o) {
  cmd.add_option("--dim", o.dim, "dimension (1, 2 or 3; the scene lists which it supports)")
      ->check(CLI::Range(1, 3));
  cmd.add_option("--transfer", o.transfer, "transfer scheme (see `mpmtb list`), or `all`");
  cmd.add_option("--kernel", o.kernel, "kernel (linear, quadratic, cubic), or `all`");
  cmd.add_option("--model", o.model, "constitutive model for every material");
  cmd.add_option("--cells", o.cells, "cells along the scene's grid.length")
      ->check(CLI::PositiveNumber);
  cmd.add_option("--ppc", o.ppc, "particles per cell per axis")->check(CLI::PositiveNumber);
  auto* cfl = cmd.add_option("--cfl", o.cfl, "adaptive step dt = cfl dx / (c_p + max|v|)");
  auto* dt = cmd.add_option("--dt", o.dt, "fixed time step");
  cfl->excludes(dt);
  cmd.add_option("--t-end", o.t_end, "end time");
  cmd.add_option("--set", o.set, "override any scene field: key.path=value (repeatable)");
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
  return cmd;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mpmtb: Material Point Method verification testbed"};
  app.require_subcommand(1);

  std::string list_only;
  auto* list = app.add_subcommand("list", "list transfers, kernels, models and scenes");
  list->add_option("what", list_only, "print only the names of: transfers|kernels|models|scenes")
      ->check(CLI::IsMember({"transfers", "kernels", "models", "scenes"}));

  mpmtb::RunRequest run_request;
  auto* run = app.add_subcommand("run", "run a scene and write DIR/series.csv, DIR/summary.json");
  run->add_option("scene", run_request.scene, "built-in scene name or scene file")->required();
  add_override_options(*run, run_request.overrides);
  run->add_option("--threads", run_request.options.threads, "OpenMP threads (0: default)")
      ->check(CLI::NonNegativeNumber);
  run->add_option("--out", run_request.out, "output folder")->required();

  std::string describe_scene;
  mpmtb::Overrides describe_overrides;
  auto* describe = app.add_subcommand("describe", "print a scene after overrides");
  describe->add_option("scene", describe_scene, "built-in scene name or scene file")->required();
  add_override_options(*describe, describe_overrides);

  mpmtb::SuiteRequest suite_request;
  auto* suite = add_suite_command(app, suite_request);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : mpmtb::kExitInvalid;
  }
  try {
    if (*list) return mpmtb::command_list(list_only);
    if (*describe) return mpmtb::command_describe(describe_scene, describe_overrides);
    if (*suite) return mpmtb::command_suite(suite_request);
    return mpmtb::command_run(run_request);
  } catch (const mpmtb::InputError& e) {
    fmt::print(stderr, "mpmtb: invalid input: {}\n", e.what());
    return mpmtb::kExitInvalid;
  } catch (const std::exception& e) {
    fmt::print(stderr, "mpmtb: error: {}\n", e.what());
    return mpmtb::kExitError;
  }
}
