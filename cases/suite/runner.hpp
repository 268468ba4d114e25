// Runs many `mpmtb run` invocations as child processes, up to N at once.
//
// Each run owns a folder. A run is finished when its folder holds `done.json`,
// the completion marker, written last and atomically after the child has
// exited and its summary.json is final. A later call skips finished runs, so
// a suite killed at any moment (even by SIGKILL) resumes where it stopped and
// redoes only the unfinished runs. The marker records the run's arguments and
// the git revision of the build; a run whose definition or revision has changed
// since is redone (uncommitted changes do not count: remove the folder then). A child that crashes
// or hangs is a data point (status `crashed`), never a crash of the suite.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace mpmtb::suite {

// One `mpmtb run` of a suite.
struct RunSpec {
  std::string case_name, scene;
  int dim = 1;
  std::string transfer, kernel;
  std::string integrator;  // empty: explicit (no --integrator argument)
  int cells = 16, ppc = 2;
  std::optional<double> cfl, dt, t_end;
  std::vector<std::string> sets;  // --set key=value
  std::filesystem::path dir;      // the run's folder, relative to the suite root
  // Free-form labels copied into the tables (level, study, ...).
  nlohmann::json tags = nlohmann::json::object();
  // Estimated work (suite::CostModel), only to balance shards.
  double cost = 1;
  // Timed: --timing-repeats N (timing.hpp), and run alone: nothing else of the
  // suite runs beside it, whatever --jobs says, so that runs do not time each
  // other's contention for the cores.
  int timing_repeats = 0;
  double timing_min_seconds = 0.5;
  bool serial() const { return timing_repeats > 0; }

  std::vector<std::string> arguments(const std::filesystem::path& out) const;
};

struct RunResult {
  std::string status;  // ok | unstable | invalid | crashed
  std::string reason;
  nlohmann::json summary;  // the run's summary.json
};

struct RunnerOptions {
  int jobs = 1;
  bool quiet = false;
  std::string title;             // shown in progress lines
  double timeout_seconds = 600;  // a run longer than this is killed (`crashed`)
  std::string executable;        // default: this program (/proc/self/exe)
};

struct RunnerStats {
  int total = 0, finished_before = 0, ran = 0;
};

// Thrown when SIGINT or SIGTERM stops the suite (or one of its runs: a batch
// system's time limit signals every process of the job); unfinished runs keep
// no marker.
struct Interrupted : std::runtime_error {
  explicit Interrupted(int sig) : std::runtime_error("interrupted"), signal(sig) {}
  int signal;  // SIGINT or SIGTERM
};

// Runs every spec not yet finished under `root`, then returns every result in
// the order of `specs`.
std::vector<RunResult> run_all(const std::vector<RunSpec>& specs, const std::filesystem::path& root,
                               const RunnerOptions& options, RunnerStats* stats = nullptr);

// A run's state on disk: its result when its marker is there and records the
// same definition and git revision, otherwise why it counts as not finished.
struct RunCheck {
  std::optional<RunResult> result;
  std::string missing;  // "no done.json", "done.json of revision ...", ...
};
RunCheck check_run(const RunSpec& spec, const std::filesystem::path& root);

// The failure class of an unstable or crashed run's reason: nan, J<=0,
// left-domain, energy-growth, crashed, invalid, or empty for ok runs.
std::string failure_kind(const RunResult& r);

}  // namespace mpmtb::suite
