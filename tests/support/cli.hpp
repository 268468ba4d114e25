// Runs the mpmtb program from tests and reads back what it wrote.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/csv.hpp"

namespace mpmtb::testing {

struct CliResult {
  int status;       // exit status
  std::string err;  // everything written to stderr
};

// A path under the temporary folder unique to this process and `name`; removed if present.
inline std::filesystem::path scratch_path(const std::string& name) {
  const auto p = std::filesystem::temp_directory_path() /
                 ("mpmtb_test_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(p);
  return p;
}

// Runs `mpmtb ARGS` (ARGS is passed through the shell) and captures stderr.
inline CliResult run_cli(const std::string& args) {
  static int calls = 0;  // one capture file per call: ctest runs tests in parallel processes
  const auto log = scratch_path("stderr_" + std::to_string(calls++));
  const int rc = std::system((std::string(MPMTB_CLI) + " " + args + " 2>" + log.string()).c_str());
  std::ifstream in(log);
  std::string err((std::istreambuf_iterator<char>(in)), {});
  std::filesystem::remove(log);
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, err};
}

}  // namespace mpmtb::testing
