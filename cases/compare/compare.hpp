// `mpmtb compare OLD NEW`: two results trees (or two files), metric by metric.
//
// Files are paired by their path relative to each root (summary.json of single
// runs and suite runs, runs.csv of sweeps, the suites' tables); which files
// take part, how CSV rows pair up and each metric's tolerance come from the
// tolerance file (tolerances.toml beside this file, built in as the default).
// Numbers within tolerance, ignored provenance and timings do not count as
// changes; timings are summarised as ratios new/old.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "compare/tolerances.hpp"

namespace mpmtb::compare {

struct Change {
  std::string file;                  // relative path
  std::string metric;                // JSON path, or "row key: column" for a table
  std::string old_value, new_value;  // "(absent)" where one side lacks it
  double rel_diff = 0;               // (new - old) / |old|; NaN where not a number
  std::string tolerance;             // "exact", or "rel 1e-09 abs 1e-14"
};

struct Timing {
  std::string metric;
  double old_value = 0, new_value = 0;
};

struct Report {
  std::vector<std::string> only_old, only_new;  // files on one side only
  std::vector<Change> changes;
  std::vector<Timing> timings;
  long files = 0;   // files compared on both sides
  long values = 0;  // values compared (not counting ignored ones)
  bool changed() const { return !only_old.empty() || !only_new.empty() || !changes.empty(); }
};

// Throws InputError (naming the path) for a missing root or a malformed file.
Report compare_paths(const std::filesystem::path& old_root, const std::filesystem::path& new_root,
                     const Tolerances& tolerances);

// The report as text: the table of changes, the one-sided files, the timings.
// At most `limit` rows of the table (0: all), then a count of the rest.
std::string render(const Report& report, const std::string& old_name, const std::string& new_name,
                   std::size_t limit);

struct CompareRequest {
  std::string old_root, new_root;
  std::string tolerances;  // empty: the built-in cases/compare/tolerances.toml
  std::size_t limit = 50;
};

// The subcommand: prints the report; 0 when nothing changed, 1 when something
// did (InputError, i.e. exit status 2, for bad input).
int command_compare(const CompareRequest& request);

}  // namespace mpmtb::compare
