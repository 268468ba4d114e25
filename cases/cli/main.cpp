// mpmtb: the command-line front end of the MPM verification testbed.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <exception>

#include "commands.hpp"
#include "core/errors.hpp"

namespace {

// Options that override a scene, shared by `run` and `describe`.
void add_override_options(CLI::App& cmd, mpmtb::Overrides& o) {
  cmd.add_option("--dim", o.dim, "dimension (1, 2 or 3; the scene lists which it supports)")
      ->check(CLI::Range(1, 3));
  cmd.add_option("--transfer", o.transfer, "transfer scheme (see `mpmtb list`), or `all`");
  cmd.add_option("--kernel", o.kernel, "kernel (linear, quadratic, cubic), or `all`");
  cmd.add_option("--model", o.model, "constitutive model for every material");
  // Ranges of --cells and --ppc are checked with the scene (grid.cells, grid.ppc).
  cmd.add_option("--cells", o.cells, "cells along the scene's grid.length");
  cmd.add_option("--ppc", o.ppc, "particles per cell per axis");
  auto* cfl = cmd.add_option("--cfl", o.cfl, "adaptive step dt = cfl dx / (c_p + max|v|)");
  auto* dt = cmd.add_option("--dt", o.dt, "fixed time step");
  cfl->excludes(dt);
  cmd.add_option("--t-end", o.t_end, "end time");
  cmd.add_option("--set", o.set, "override any scene field: key.path=value (repeatable)");
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
      ->check(CLI::Range(0, 4096));
  run->add_option("--out", run_request.out, "output folder")->required();

  std::string describe_scene;
  mpmtb::Overrides describe_overrides;
  auto* describe = app.add_subcommand("describe", "print a scene after overrides");
  describe->add_option("scene", describe_scene, "built-in scene name or scene file")->required();
  add_override_options(*describe, describe_overrides);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    // One line, like every other input error.
    fmt::print(stderr, "mpmtb: invalid input: command line: {}\n", one_line(e.what()));
    return mpmtb::kExitInvalid;
  }
  try {
    if (*list) return mpmtb::command_list(list_only);
    if (*describe) return mpmtb::command_describe(describe_scene, describe_overrides);
    return mpmtb::command_run(run_request);
  } catch (const mpmtb::InputError& e) {
    fmt::print(stderr, "mpmtb: invalid input: {}\n", one_line(e.what()));
    return mpmtb::kExitInvalid;
  } catch (const std::exception& e) {
    fmt::print(stderr, "mpmtb: error: {}\n", one_line(e.what()));
    return mpmtb::kExitError;
  }
}
