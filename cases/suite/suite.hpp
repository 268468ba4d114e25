// `mpmtb suite convergence|stability|speed-accuracy|all`: sweeps of whole runs,
// each a child process in its own folder, resumable, with CSV tables.
//
// Layout under --out (default results/suites):
//   convergence/<case>.csv, <case>_dt.csv, orders.csv
//   stability/<case>.csv, stable_cfl.csv, failure_modes.csv
//   speed_accuracy/<case>.csv
//   <suite>/runs/<case>/<transfer>-<kernel>/<label>/  one run each (done.json last)
#pragma once

#include <string>
#include <vector>

namespace mpmtb {

struct SuiteRequest {
  std::string name;  // convergence | stability | speed-accuracy | all
  bool full = false;
  int jobs = 0;  // 0: the number of hardware threads
  std::string out = "results/suites";
  bool quiet = false;
  // Filters (empty: everything): case names, transfers, kernels.
  std::vector<std::string> cases, transfers, kernels;
};

// Returns the exit status: 0 when every table was written (unstable runs are
// data), 130 when interrupted by SIGINT/SIGTERM.
int command_suite(const SuiteRequest& request);

}  // namespace mpmtb
