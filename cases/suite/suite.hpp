// `mpmtb suite convergence|stability|speed-accuracy|all`: sweeps of whole runs,
// each a child process in its own folder, resumable, with CSV tables; split
// over machines with --shard K/N and put together with --collect.
//
// Layout under --out (default results/suites):
//   convergence/<case>.csv, <case>_dt.csv, orders.csv
//   stability/<case>.csv, stable_cfl.csv, failure_modes.csv
//   speed_accuracy/<case>.csv
//   <suite>/runs/<case>/<transfer>-<kernel>/<label>/  one run each (done.json last);
//   an implicit integrator's runs under <transfer>-<kernel>-<integrator>/
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
  // Filters (empty: everything): case names, transfers, kernels, time
  // integrators (explicit, backward-euler, newmark; the implicit ones run where
  // a case lists them, and in the convergence suite only when named here).
  std::vector<std::string> cases, transfers, kernels, integrators;
  // "K/N": run only the K-th of N disjoint parts of the run list, write no
  // tables (cases/suite/shard.hpp). Empty: every run, then the tables.
  std::string shard;
  // Run nothing: write the tables from the runs on disk, once all are done.
  bool collect = false;
};

// --collect found runs without their done.json (they are listed on stderr).
constexpr int kExitIncomplete = 4;

// Returns the exit status: 0 when every table was written (unstable runs are
// data) or, with a shard, when the shard's runs are done; 130 (SIGINT) or 143
// (SIGTERM) when stopped; kExitIncomplete for --collect with runs missing.
// Every shard and the collect step must be given the same name, level and
// filters: they define the run list that the shards split.
int command_suite(const SuiteRequest& request);

}  // namespace mpmtb
