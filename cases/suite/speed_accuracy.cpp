// The speed-accuracy suite's plan and work-precision tables: every run timed
// alone, its error against its cost, with the Pareto fronts. A method is a
// transfer x kernel x integrator; the implicit integrators run at larger steps.
#include <fmt/format.h>

#include <algorithm>
#include <map>

#include "analysis.hpp"
#include "common.hpp"
#include "plan.hpp"

namespace mpmtb::suite {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A statistic of the summary's `timing` (timing.hpp): timing.<group>.<stat>.
double timing_of(const RunResult& r, const char* group, const char* stat) {
  if (r.status != "ok" || !r.summary.contains("timing")) return kNaN;
  const json& t = r.summary["timing"];
  return t.contains(group) ? number_of(t[group], stat) : kNaN;
}

// The fewest passes of a timed run's repetitions (how often the run was repeated
// to reach the minimum stepping time).
std::string fewest_passes(const RunResult& r) {
  if (r.status != "ok" || !r.summary.contains("timing")) return "";
  long fewest = -1;
  for (const json& rep : r.summary["timing"].value("repetitions", json::array())) {
    const long n = rep.value("passes", 0L);
    fewest = fewest < 0 ? n : std::min(fewest, n);
  }
  return fewest < 0 ? "" : std::to_string(fewest);
}

// The work-precision tables: the error of each run against its cost, the
// median time of one run (min and max of the repetitions beside it), its CPU
// time and its particle-steps, with the Pareto fronts of error against time
// (`pareto_time`), against particle-steps (`pareto_work`) and, where the case
// has a period error (the bar), of the period error against time
// (`pareto_period`: the front a period-only metric would draw).
void write_speed_tables(const fs::path& root, const std::vector<Series>& series,
                        const std::vector<RunResult>& results) {
  std::map<std::string, std::vector<const Series*>> by_case;
  for (const auto& g : series) by_case[g.case_name].push_back(&g);
  for (const auto& [name, groups] : by_case) {
    std::vector<double> time, work, err, period;
    std::vector<std::pair<const Series*, std::size_t>> rows;
    for (const Series* g : groups) {
      for (std::size_t k = 0; k < g->runs.size(); ++k) {
        const RunResult& res = results[g->runs[k]];
        const double ok = res.status == "ok" ? 1.0 : kNaN;
        time.push_back(timing_of(res, "seconds_per_pass", "median"));
        work.push_back(ok * number_of(res.summary, "particles") * number_of(res.summary, "steps"));
        err.push_back(error_of(res, g->error_key));
        period.push_back(error_of(res, "period_rel"));
        rows.emplace_back(g, k);
      }
    }
    const auto front_time = pareto_front(time, err);
    const auto front_work = pareto_front(work, err);
    const auto front_period = pareto_front(time, period);
    Table t{{"case",         "transfer",     "kernel",         "integrator",
             "cfl",          "level",        "cells",          "h",
             "particles",    "steps",        "particle_steps", "time_s",
             "time_min_s",   "time_max_s",   "cpu_s",          "cpu_min_s",
             "cpu_max_s",    "repeats",      "passes",         "particle_steps_per_second",
             "wall_seconds", "status",       "error_key",      "error",
             "energy_error", "period_error", "pareto_time",    "pareto_work",
             "pareto_period"},
            {}};
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const auto& [g, k] = rows[i];
      const RunResult& res = results[g->runs[k]];
      const json& s = res.summary;
      const bool timed = res.status == "ok" && s.contains("timing");
      t.rows.push_back({name,
                        g->method.transfer,
                        g->method.kernel,
                        g->method.integrator,
                        num(g->cfl),
                        std::to_string(k),
                        int_text(s, "cells"),
                        num(g->h[k]),
                        int_text(s, "particles"),
                        int_text(s, "steps"),
                        num(work[i]),
                        num(time[i]),
                        num(timing_of(res, "seconds_per_pass", "min")),
                        num(timing_of(res, "seconds_per_pass", "max")),
                        num(timing_of(res, "cpu_seconds_per_pass", "median")),
                        num(timing_of(res, "cpu_seconds_per_pass", "min")),
                        num(timing_of(res, "cpu_seconds_per_pass", "max")),
                        timed ? int_text(s["timing"], "repeats") : "",
                        fewest_passes(res),
                        num(timing_of(res, "particle_steps_per_second", "median")),
                        num(number_of(s, "wall_seconds")),
                        res.status,
                        g->error_key,
                        num(err[i]),
                        num(error_of(res, "energy_rel")),
                        num(period[i]),
                        front_time[i] ? "1" : "0",
                        front_work[i] ? "1" : "0",
                        front_period[i] ? "1" : "0"});
    }
    t.write(root / (name + ".csv"));
  }
}

// The methods of a case's explicit runs: at the quick level its own subset.
std::vector<Method> timed_methods(const SuiteRequest& r, const ConvergenceCase& c) {
  std::vector<Method> m;
  for (const Method& x : methods(r)) {
    if (r.full || (wanted(c.quick_transfers, x.transfer) && wanted(c.quick_kernels, x.kernel))) {
      m.push_back(x);
    }
  }
  return m;
}

}  // namespace

// Each case: the explicit methods at the case's CFL on its levels, then each
// (implicit integrator, CFL) pair of the case on the quick level's grids.
Plan plan_speed_accuracy(const SuiteRequest& r) {
  Plan p{"speed-accuracy", fs::path(r.out) / "speed_accuracy", {}, {}};
  std::vector<Series> series;
  for (const auto& c : speed_accuracy_cases()) {
    if (!runnable(r, c.name, c.scene)) continue;
    plan_refinement(r, c, timed_methods(r, c), r.full ? c.full : c.quick, c.cfl, false, true, "",
                    p.specs, series);
    for (const IntegratorStep& step : c.implicit_steps) {
      const auto m =
          r.full ? methods(r, step.integrator, c.implicit_transfers_full, c.implicit_kernels_full)
                 : methods(r, step.integrator, c.implicit_transfers, c.implicit_kernels);
      plan_refinement(r, c, m, c.quick, step.cfl, false, true, fmt::format("cfl{:g}", step.cfl),
                      p.specs, series);
    }
  }
  p.write_tables = [root = p.root, series = std::move(series)](const auto& results) {
    write_speed_tables(root, series, results);
  };
  return p;
}

}  // namespace mpmtb::suite
