// `mpmtb suite`: the three ways to go through a plan (plan.hpp): every run and
// then the tables; one shard of the runs; the tables from the runs on disk.
#include <fmt/format.h>

#include <csignal>
#include <optional>
#include <thread>

#include "core/errors.hpp"
#include "plan.hpp"
#include "shard.hpp"
#include "suite.hpp"

namespace mpmtb {
namespace {

using suite::Plan;
using suite::RunResult;
using suite::RunSpec;

suite::RunnerOptions runner_options(const SuiteRequest& r, const std::string& title) {
  suite::RunnerOptions o;
  o.jobs = r.jobs > 0 ? r.jobs : std::max(1u, std::thread::hardware_concurrency());
  o.quiet = r.quiet;
  o.title = title;
  return o;
}

void note(const SuiteRequest& r, const std::string& text) {
  if (!r.quiet) fmt::print(stderr, "{}\n", text);
}

// Every run, then each suite's tables: the plain `mpmtb suite NAME`.
int run_whole(const SuiteRequest& r, const std::vector<Plan>& plans) {
  for (const Plan& p : plans) {
    p.write_tables(suite::run_all(p.specs, p.root, runner_options(r, "suite " + p.name)));
    note(r, fmt::format("suite {}: tables in {}", p.name, p.root.string()));
  }
  return 0;
}

// A run's id across the suites of a request: its folder under --out, the same
// on every host whatever path the shared filesystem is mounted at.
std::string run_id(const Plan& p, const RunSpec& s) {
  return (p.root.filename() / s.dir).generic_string();
}

// One shard's runs. The suites of `all` are split as one list, so that N shards
// get equal work even though the three suites differ in size.
int run_shard(const SuiteRequest& r, const suite::Shard& shard, const std::vector<Plan>& plans) {
  std::vector<suite::ShardItem> items;
  for (const Plan& p : plans) {
    for (const RunSpec& s : p.specs) items.push_back({run_id(p, s), s.cost});
  }
  const std::vector<int> owner = suite::assign_shards(items, shard.count);
  std::size_t next = 0, mine = 0;
  for (const Plan& p : plans) {
    std::vector<RunSpec> specs;
    for (const RunSpec& s : p.specs) {
      if (owner[next++] == shard.index) specs.push_back(s);
    }
    mine += specs.size();
    suite::run_all(
        specs, p.root,
        runner_options(r, fmt::format("suite {} shard {}/{}", p.name, shard.index, shard.count)));
  }
  note(r, fmt::format("suite {} shard {}/{}: its {} of {} runs are done; the tables come from "
                      "`mpmtb suite {} --collect --out {}` once every shard is",
                      r.name, shard.index, shard.count, mine, items.size(), r.name, r.out));
  return 0;
}

// The tables from the runs on disk, all or nothing: a table from part of the
// runs would look complete and be wrong.
int collect(const SuiteRequest& r, const std::vector<Plan>& plans) {
  std::vector<std::vector<RunResult>> results(plans.size());
  std::vector<std::string> missing;
  std::size_t total = 0;
  for (std::size_t i = 0; i < plans.size(); ++i) {
    for (const RunSpec& s : plans[i].specs) {
      ++total;
      auto check = suite::check_run(s, plans[i].root);
      if (check.result) {
        results[i].push_back(std::move(*check.result));
      } else {
        missing.push_back(fmt::format("{}: {}", (plans[i].root / s.dir).string(), check.missing));
      }
    }
  }
  if (!missing.empty()) {
    fmt::print(stderr,
               "mpmtb: suite {} --collect: {} of {} runs are not finished, no table written "
               "(run the missing shards, or `mpmtb suite {} --out {}`):\n",
               r.name, missing.size(), total, r.name, r.out);
    for (const auto& m : missing) fmt::print(stderr, "  {}\n", m);
    return kExitIncomplete;
  }
  for (std::size_t i = 0; i < plans.size(); ++i) {
    plans[i].write_tables(results[i]);
    note(r, fmt::format("suite {}: {} runs collected, tables in {}", plans[i].name,
                        results[i].size(), plans[i].root.string()));
  }
  return 0;
}

}  // namespace

int command_suite(const SuiteRequest& request) {
  if (request.collect && !request.shard.empty()) {
    throw InputError(fmt::format("suite: --collect runs nothing and takes no --shard (given '{}')",
                                 request.shard));
  }
  // Bad input is refused before anything is planned or run.
  const auto shard = request.shard.empty()
                         ? std::optional<suite::Shard>()
                         : std::optional<suite::Shard>(suite::parse_shard(request.shard));
  try {
    const std::vector<Plan> plans = suite::plan_suites(request);
    if (request.collect) return collect(request, plans);
    if (shard) return run_shard(request, *shard, plans);
    return run_whole(request, plans);
  } catch (const suite::Interrupted& e) {
    fmt::print(stderr, "suite: stopped by {}; finished runs are kept, run again to resume\n",
               e.signal == SIGTERM ? "SIGTERM" : "SIGINT");
    return 128 + e.signal;
  }
}

}  // namespace mpmtb
