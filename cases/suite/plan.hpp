// A suite as data: its run list and how its tables are made from the results.
// Planning is separate from running so that the same list can be run whole
// (`mpmtb suite NAME`), split into shards on many machines (`--shard K/N`) or
// read back from disk (`--collect`), and the tables always come from the one
// function below, whichever way the results were obtained.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "runner.hpp"
#include "suite.hpp"

namespace mpmtb::suite {

struct Plan {
  std::string name;            // convergence | stability | speed-accuracy
  std::filesystem::path root;  // DIR/<folder>: the tables, and runs/ below
  std::vector<RunSpec> specs;
  // Writes every table under root from the results, in the order of specs.
  std::function<void(const std::vector<RunResult>&)> write_tables;
};

// Each suite's plan (suite.cpp, stability.cpp, speed_accuracy.cpp).
Plan plan_convergence(const SuiteRequest& request);
Plan plan_stability(const SuiteRequest& request);
Plan plan_speed_accuracy(const SuiteRequest& request);

// The plans of a request (one, or three for `all`), in the order they run.
std::vector<Plan> plan_suites(const SuiteRequest& request);

}  // namespace mpmtb::suite
