// The mpmtb subcommands. Each returns the process exit status.
#pragma once

#include <string>
#include <vector>

#include "run.hpp"
#include "scene.hpp"

namespace mpmtb {

enum ExitStatus { kExitOk = 0, kExitError = 1, kExitInvalid = 2, kExitUnstable = 3 };

struct RunRequest {
  std::string scene;
  Overrides overrides;
  std::string out;
  RunOptions options;
};

int command_list(const std::string& only);
int command_describe(const std::string& scene, const Overrides& overrides);
// Runs one scene, or, with --transfer all and/or --kernel all, every
// combination into DIR/<transfer>-<kernel>/ plus DIR/runs.csv.
int command_run(const RunRequest& request);

}  // namespace mpmtb
