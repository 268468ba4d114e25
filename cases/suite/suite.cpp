// The convergence suite's plan and tables, and the plans of a request. The
// stability and speed-accuracy suites: stability.cpp, speed_accuracy.cpp.
#include "suite.hpp"

#include <fmt/format.h>

#include <map>

#include "analysis.hpp"
#include "common.hpp"
#include "plan.hpp"

namespace mpmtb::suite {
namespace {

namespace fs = std::filesystem;

void write_convergence_tables(const fs::path& root, const std::vector<Series>& series,
                              const std::vector<RunResult>& results) {
  std::map<std::string, Table> tables;  // file name -> table
  Table orders{
      {"case", "study", "transfer", "kernel", "integrator", "fitted_order", "fit_from_level",
       "fit_to_level", "fit_h_max", "fit_h_min", "finest_error", "levels_ok", "levels"},
      {}};
  for (const Series& g : series) {
    const bool dt = g.study == "dt";
    const std::string file = g.case_name + (dt ? "_dt.csv" : ".csv");
    Table& t = tables[file];
    if (t.header.empty()) {
      t.header = {"case",  "study", "transfer", "kernel", "integrator", "level",
                  "cells", "ppc",   "h",        "dt",     "status",     "failure",
                  "error", "order", "in_fit",   "reason"};
    }
    std::vector<double> e, step;
    for (std::size_t k = 0; k < g.runs.size(); ++k) {
      const RunResult& r = results[g.runs[k]];
      e.push_back(error_of(r, g.error_key));
      step.push_back(dt ? g.dt[k] : number_of(r.summary, "dt_max"));
    }
    // The time-step study refines dt at a fixed grid: the order is in dt.
    const std::vector<double>& size = dt ? g.dt : g.h;
    const auto p = observed_orders(size, e);
    const auto fit = fit_order(size, e);
    int ok = 0;
    const Method& m = g.method;
    for (std::size_t k = 0; k < g.runs.size(); ++k) {
      const RunResult& r = results[g.runs[k]];
      ok += r.status == "ok";
      const bool in_fit = static_cast<int>(k) >= fit.first && static_cast<int>(k) <= fit.last;
      t.rows.push_back({g.case_name, g.study, m.transfer, m.kernel, m.integrator, std::to_string(k),
                        int_text(r.summary, "cells"), int_text(r.summary, "ppc"), num(g.h[k]),
                        num(step[k]), r.status, failure_kind(r), num(e[k]), num(p[k]),
                        in_fit ? "1" : "0", r.status == "ok" ? "" : r.reason});
    }
    const bool has_fit = fit.first >= 0;
    orders.rows.push_back({g.case_name, g.study, m.transfer, m.kernel, m.integrator, num(fit.order),
                           has_fit ? std::to_string(fit.first) : "",
                           has_fit ? std::to_string(fit.last) : "",
                           has_fit ? num(size[fit.first]) : "", has_fit ? num(size[fit.last]) : "",
                           num(e.back()), std::to_string(ok), std::to_string(g.runs.size())});
  }
  for (const auto& [file, t] : tables) t.write(root / file);
  orders.write(root / "orders.csv");
}

}  // namespace

// Explicit by default; an implicit integrator joins when --integrator names it
// (every method that takes it, at the case's CFL).
Plan plan_convergence(const SuiteRequest& r) {
  Plan p{"convergence", fs::path(r.out) / "convergence", {}, {}};
  std::vector<Series> series;
  for (const auto& c : convergence_cases()) {
    if (!runnable(r, c.name, c.scene)) continue;
    std::vector<Method> m = methods(r);
    if (!r.integrators.empty()) {
      for (const auto& i : implicit_integrators(r)) {
        const auto more = methods(r, i);
        m.insert(m.end(), more.begin(), more.end());
      }
    }
    plan_refinement(r, c, m, r.full ? c.full : c.quick, c.cfl, true, false, "", p.specs, series);
  }
  p.write_tables = [root = p.root, series = std::move(series)](const auto& results) {
    write_convergence_tables(root, series, results);
  };
  return p;
}

std::vector<Plan> plan_suites(const SuiteRequest& request) {
  check_filters(request);
  const std::string& n = request.name;
  std::vector<Plan> plans;
  if (n == "convergence" || n == "all") plans.push_back(plan_convergence(request));
  if (n == "stability" || n == "all") plans.push_back(plan_stability(request));
  if (n == "speed-accuracy" || n == "all") plans.push_back(plan_speed_accuracy(request));
  return plans;
}

}  // namespace mpmtb::suite
