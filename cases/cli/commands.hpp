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
  std::string config;  // a summary.json to re-run instead of `scene`
  std::string resume;  // a run folder whose checkpoint to continue, instead of `scene`
  Overrides overrides;
  std::string out;
  RunOptions options;
  std::string max_memory;  // --max-memory SIZE as given (parse_bytes)
  bool quiet = false;      // no progress line and no per-run status lines
};

// `only`: the names of one group; `bibtex`: the papers behind the variants instead.
int command_list(const std::string& only, bool bibtex = false);
// The scene's effective parameters (defaults included) after overrides, then its TOML.
int command_describe(const std::string& scene, const Overrides& overrides);
// Runs one scene, or, with --transfer all and/or --kernel all, every
// combination into DIR/<transfer>-<kernel>/ plus DIR/runs.csv.
int command_run(const RunRequest& request);

}  // namespace mpmtb
