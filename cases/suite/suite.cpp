#include "suite.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "analysis.hpp"
#include "cases.hpp"
#include "core/registry.hpp"
#include "output.hpp"
#include "plan.hpp"
#include "runner.hpp"
#include "scene.hpp"
#include "setup.hpp"
#include "shard.hpp"

namespace mpmtb {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using suite::kNaN;
using suite::Plan;
using suite::RunResult;
using suite::RunSpec;

struct Method {
  std::string transfer, kernel;
  std::string name() const { return transfer + "-" + kernel; }
};

bool wanted(const std::vector<std::string>& filter, const std::string& name) {
  return filter.empty() || std::find(filter.begin(), filter.end(), name) != filter.end();
}

std::vector<Method> methods(const SuiteRequest& r) {
  std::vector<Method> m;
  for (const auto& t : transfer_list()) {
    for (const auto& k : kernel_list()) {
      if (wanted(r.transfers, t.name) && wanted(r.kernels, k.name) &&
          unsupported_reason(t.name, k.name).empty()) {
        m.push_back({t.name, k.name});
      }
    }
  }
  return m;
}

bool scene_exists(const std::string& name) {
  for (const auto& b : builtin_scenes()) {
    if (b.name == name) return true;
  }
  return false;
}

// A case runs if it passes the filter and its scene is built in.
bool runnable(const SuiteRequest& r, const std::string& name, const std::string& scene) {
  if (!wanted(r.cases, name)) return false;
  if (scene_exists(scene)) return true;
  if (!r.quiet)
    fmt::print(stderr, "suite: case '{}' skipped: no built-in scene '{}'\n", name, scene);
  return false;
}

// ------------------------------------------------------------- tables --

// A number for a table; NaN (missing, unstable) is an empty cell.
std::string num(double v) {
  return std::isfinite(v) ? fmt::format("{:.6g}", v) : "";
}

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  void write(const fs::path& path) const {
    std::string s;
    auto line = [&](const std::vector<std::string>& cells) {
      for (std::size_t i = 0; i < cells.size(); ++i) {
        if (i) s += ',';
        s += csv_field(cells[i]);
      }
      s += '\n';
    };
    line(header);
    for (const auto& r : rows) line(r);
    write_atomically(path, s);
  }
};

double number_of(const json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : kNaN;
}

double error_of(const RunResult& r, const std::string& key) {
  if (r.status != "ok" || !r.summary.contains("error")) return kNaN;
  return number_of(r.summary["error"], key.c_str());
}

std::string int_text(const json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? std::to_string(j[key].get<long>()) : "";
}

Overrides overrides_for(const std::string& /*scene*/, int dim, int cells,
                        const std::vector<std::string>& sets) {
  Overrides o;
  o.dim = dim;
  o.cells = cells;
  o.set = sets;
  return o;
}

// --------------------------------------------------------- convergence --

// One refinement series: a method on a case, grid or time-step study.
struct Series {
  std::string case_name, study, error_key;
  Method method;
  std::vector<std::size_t> runs;  // indices into the spec list, coarse to fine
  std::vector<double> h, dt;
};

RunSpec make_spec(const std::string& case_name, const std::string& scene, int dim, const Method& m,
                  int cells, double t_end, const std::vector<std::string>& sets) {
  RunSpec s;
  s.case_name = case_name;
  s.scene = scene;
  s.dim = dim;
  s.transfer = m.transfer;
  s.kernel = m.kernel;
  s.cells = cells;
  s.sets = sets;
  if (t_end > 0) s.t_end = t_end;
  return s;
}

// The methods of a speed-accuracy case: at the quick level its own subset.
std::vector<Method> timed_methods(const SuiteRequest& r, const suite::ConvergenceCase& c) {
  std::vector<Method> m;
  for (const Method& x : methods(r)) {
    if (r.full || (wanted(c.quick_transfers, x.transfer) && wanted(c.quick_kernels, x.kernel))) {
      m.push_back(x);
    }
  }
  return m;
}

// Timed runs of the speed-accuracy suite: repetitions and the stepping time of each.
constexpr int kTimingRepeats = 3;
constexpr double kTimingMinSeconds = 0.5;

// The grid study (and the time-step study when asked) of every method on a case;
// `timed`: every run also times its stepping, alone (speed-accuracy).
void plan_refinement(const SuiteRequest& r, const suite::ConvergenceCase& c, bool dt_study,
                     bool timed, std::vector<RunSpec>& specs, std::vector<Series>& series) {
  const suite::Levels levels = r.full ? c.full : c.quick;
  const double t_end = r.full ? c.t_end_full : c.t_end_quick;
  const int dt_cells = dt_study ? (r.full ? c.dt_cells_full : c.dt_cells_quick) : 0;
  const Scene base = load_scene(c.scene, overrides_for(c.scene, c.dim, 8, c.sets));
  const suite::CostModel model(base);
  double dt0 = kNaN;
  if (dt_cells > 0) {
    const Scene s = load_scene(c.scene, overrides_for(c.scene, c.dim, dt_cells, c.sets));
    dt0 = c.dt_cfl * s.dx() / max_wave_speed(s);
  }
  for (const Method& m : timed ? timed_methods(r, c) : methods(r)) {
    Series g{c.name, "grid", c.error_key, m, {}, {}, {}};
    const auto cells = levels.cells();
    for (std::size_t k = 0; k < cells.size(); ++k) {
      RunSpec s = make_spec(c.name, c.scene, c.dim, m, cells[k], t_end, c.sets);
      s.cfl = c.cfl;
      if (timed) {
        s.timing_repeats = kTimingRepeats;
        s.timing_min_seconds = kTimingMinSeconds;
      }
      s.dir = fs::path("runs") / c.name / m.name() / fmt::format("L{}", k);
      s.cost = model.cost(s);
      g.runs.push_back(specs.size());
      g.h.push_back(base.length / cells[k]);
      specs.push_back(std::move(s));
    }
    if (!g.runs.empty()) series.push_back(std::move(g));
    if (dt_cells <= 0) continue;
    Series d{c.name, "dt", c.error_key, m, {}, {}, {}};
    for (int k = 0; k < 5; ++k) {
      RunSpec s = make_spec(c.name, c.scene, c.dim, m, dt_cells, t_end, c.sets);
      s.dt = dt0 / (1 << k);
      s.dir = fs::path("runs") / c.name / m.name() / fmt::format("dt{}", k);
      s.cost = model.cost(s);
      d.runs.push_back(specs.size());
      d.h.push_back(base.length / dt_cells);
      d.dt.push_back(*s.dt);
      specs.push_back(std::move(s));
    }
    series.push_back(std::move(d));
  }
}

void write_convergence_tables(const fs::path& root, const std::vector<Series>& series,
                              const std::vector<RunResult>& results) {
  std::map<std::string, Table> tables;  // file name -> table
  Table orders{{"case", "study", "transfer", "kernel", "fitted_order", "fit_from_level",
                "fit_to_level", "fit_h_max", "fit_h_min", "finest_error", "levels_ok", "levels"},
               {}};
  for (const Series& g : series) {
    const bool dt = g.study == "dt";
    const std::string file = g.case_name + (dt ? "_dt.csv" : ".csv");
    Table& t = tables[file];
    if (t.header.empty()) {
      t.header = {"case", "study",  "transfer", "kernel", "level", "cells",  "ppc",   "h",
                  "dt",   "status", "failure",  "error",  "order", "in_fit", "reason"};
    }
    std::vector<double> e, step;
    for (std::size_t k = 0; k < g.runs.size(); ++k) {
      const RunResult& r = results[g.runs[k]];
      e.push_back(error_of(r, g.error_key));
      step.push_back(dt ? g.dt[k] : number_of(r.summary, "dt_max"));
    }
    // The time-step study refines dt at a fixed grid: the order is in dt.
    const std::vector<double>& size = dt ? g.dt : g.h;
    const auto p = suite::observed_orders(size, e);
    const auto fit = suite::fit_order(size, e);
    int ok = 0;
    for (std::size_t k = 0; k < g.runs.size(); ++k) {
      const RunResult& r = results[g.runs[k]];
      ok += r.status == "ok";
      const bool in_fit = static_cast<int>(k) >= fit.first && static_cast<int>(k) <= fit.last;
      t.rows.push_back({g.case_name, g.study, g.method.transfer, g.method.kernel, std::to_string(k),
                        int_text(r.summary, "cells"), int_text(r.summary, "ppc"), num(g.h[k]),
                        num(step[k]), r.status, suite::failure_kind(r), num(e[k]), num(p[k]),
                        in_fit ? "1" : "0", r.status == "ok" ? "" : r.reason});
    }
    const bool has_fit = fit.first >= 0;
    orders.rows.push_back({g.case_name, g.study, g.method.transfer, g.method.kernel, num(fit.order),
                           has_fit ? std::to_string(fit.first) : "",
                           has_fit ? std::to_string(fit.last) : "",
                           has_fit ? num(size[fit.first]) : "", has_fit ? num(size[fit.last]) : "",
                           num(e.back()), std::to_string(ok), std::to_string(g.runs.size())});
  }
  for (const auto& [file, t] : tables) t.write(root / file);
  orders.write(root / "orders.csv");
}

Plan plan_convergence(const SuiteRequest& r) {
  Plan p{"convergence", fs::path(r.out) / "convergence", {}, {}};
  std::vector<Series> series;
  for (const auto& c : suite::convergence_cases()) {
    if (runnable(r, c.name, c.scene)) plan_refinement(r, c, true, false, p.specs, series);
  }
  p.write_tables = [root = p.root, series = std::move(series)](const auto& results) {
    write_convergence_tables(root, series, results);
  };
  return p;
}

// ------------------------------------------------------------ stability --

std::vector<double> cfl_grid(const suite::StabilityCase& c, bool full) {
  const double step = full ? c.full_step : c.quick_step;
  const int n = static_cast<int>(std::floor((c.cfl_last - c.cfl_first) / step + 1e-9)) + 1;
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(std::round((c.cfl_first + i * step) * 1e6) / 1e6);
  return v;
}

std::map<std::string, std::vector<double>> read_series(const fs::path& path) {
  std::map<std::string, std::vector<double>> cols;
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> names;
  if (!std::getline(in, line)) return cols;
  std::stringstream hs(line);
  for (std::string n; std::getline(hs, n, ',');) names.push_back(n);
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::size_t i = 0;
    for (std::string v; std::getline(ls, v, ',') && i < names.size(); ++i) {
      cols[names[i]].push_back(std::strtod(v.c_str(), nullptr));
    }
  }
  return cols;
}

double failure_metric(const std::string& metric, const fs::path& dir, const RunResult& r) {
  if (r.status != "ok") return kNaN;
  auto s = read_series(dir / "series.csv");
  const auto& t = s["total"];
  if (t.empty() || s["strain"].size() != t.size() || s["kinetic"].size() != t.size()) return kNaN;
  if (metric == "strain_max_rel") {
    const double e0 = s["kinetic"][0] + s["strain"][0];
    return *std::max_element(s["strain"].begin(), s["strain"].end()) / e0;
  }
  if (metric == "energy_kept") return t.back() / t.front();
  if (metric == "L_change") {
    double d2 = 0, l2 = 0;
    for (const char* c : {"Lx", "Ly", "Lz"}) {
      const auto& L = s[c];
      if (L.empty()) return kNaN;
      d2 += (L.back() - L.front()) * (L.back() - L.front());
      l2 += L.front() * L.front();
    }
    return l2 > 0 ? std::sqrt(d2 / l2) : kNaN;
  }
  return kNaN;
}

struct Sweep {  // one method and ppc on a stability case: runs in CFL order
  std::string case_name;
  int dim;
  Method method;
  int ppc;
  std::vector<double> cfl;
  std::vector<std::size_t> runs;
};

void write_stability_tables(const fs::path& root, const std::vector<Sweep>& sweeps,
                            const std::vector<RunResult>& results) {
  std::map<std::string, Table> per_case;
  Table stable{{"case", "dim", "transfer", "kernel", "ppc", "stable_cfl", "first_unstable_cfl",
                "failure", "fail_step", "vn_low", "vn_high", "reason"},
               {}};
  for (const Sweep& s : sweeps) {
    Table& t = per_case[s.case_name];
    if (t.header.empty()) {
      t.header = {"case",   "transfer", "kernel",    "ppc",   "cfl",
                  "status", "failure",  "fail_step", "steps", "reason"};
    }
    std::vector<bool> ok;
    for (std::size_t i = 0; i < s.runs.size(); ++i) {
      const RunResult& r = results[s.runs[i]];
      ok.push_back(r.status == "ok");
      t.rows.push_back({s.case_name, s.method.transfer, s.method.kernel, std::to_string(s.ppc),
                        num(s.cfl[i]), r.status, suite::failure_kind(r),
                        int_text(r.summary, "fail_step"), int_text(r.summary, "steps"),
                        r.status == "ok" ? "" : r.reason});
    }
    const auto range = suite::largest_stable(s.cfl, ok);
    const auto vn = suite::von_neumann_cfl(s.method.kernel, s.dim);
    std::string kind, step, reason;
    if (range.first_unstable_index >= 0) {
      const RunResult& r = results[s.runs[range.first_unstable_index]];
      kind = suite::failure_kind(r);
      step = int_text(r.summary, "fail_step");
      reason = r.reason;
    }
    stable.rows.push_back({s.case_name, std::to_string(s.dim), s.method.transfer, s.method.kernel,
                           std::to_string(s.ppc), num(range.stable), num(range.first_unstable),
                           kind, step, num(vn.low), num(vn.high), reason});
  }
  for (const auto& [name, t] : per_case) t.write(root / (name + ".csv"));
  stable.write(root / "stable_cfl.csv");
}

// A failure mode shown on purpose: one method on a case, and its metric.
struct Mode {
  std::string case_name, metric;
  Method method;
  std::size_t run;
};

void write_failure_modes(const fs::path& root, const std::vector<RunSpec>& specs,
                         const std::vector<Mode>& modes, const std::vector<RunResult>& results) {
  Table t{{"case", "metric", "transfer", "kernel", "status", "value", "reason"}, {}};
  for (const Mode& m : modes) {
    const RunResult& res = results[m.run];
    t.rows.push_back({m.case_name, m.metric, m.method.transfer, m.method.kernel, res.status,
                      num(failure_metric(m.metric, root / specs[m.run].dir, res)),
                      res.status == "ok" ? "" : res.reason});
  }
  if (!modes.empty()) t.write(root / "failure_modes.csv");
}

Plan plan_stability(const SuiteRequest& r) {
  Plan p{"stability", fs::path(r.out) / "stability", {}, {}};
  std::vector<RunSpec>& specs = p.specs;
  std::vector<Sweep> sweeps;
  for (const auto& c : suite::stability_cases()) {
    if (!runnable(r, c.name, c.scene)) continue;
    const suite::CostModel model(
        load_scene(c.scene, overrides_for(c.scene, c.dim, c.cells, c.sets)));
    const auto grid = cfl_grid(c, r.full);
    for (const Method& m : methods(r)) {
      for (int ppc : r.full ? c.full_ppc : c.quick_ppc) {
        Sweep s{c.name, c.dim, m, ppc, grid, {}};
        for (double cfl : grid) {
          RunSpec spec = make_spec(c.name, c.scene, c.dim, m, c.cells, c.t_end, c.sets);
          spec.ppc = ppc;
          spec.cfl = cfl;
          spec.dir =
              fs::path("runs") / c.name / m.name() / fmt::format("ppc{}-cfl{:.3f}", ppc, cfl);
          spec.cost = model.cost(spec);
          s.runs.push_back(specs.size());
          specs.push_back(std::move(spec));
        }
        sweeps.push_back(std::move(s));
      }
    }
  }
  // Failure modes shown on purpose, every method on each case.
  std::vector<Mode> modes;
  for (const auto& c : suite::failure_mode_cases()) {
    if (!runnable(r, c.name, c.scene)) continue;
    const Scene base = load_scene(c.scene, {});
    const int cells = c.cells > 0 ? c.cells : base.cells;
    const suite::CostModel model(load_scene(c.scene, overrides_for(c.scene, c.dim, cells, c.sets)));
    for (const Method& m : methods(r)) {
      RunSpec spec = make_spec(c.name, c.scene, c.dim, m, cells, c.t_end, c.sets);
      spec.ppc = base.ppc;
      spec.dir = fs::path("runs") / "failure_modes" / c.name / m.name();
      spec.cost = model.cost(spec);
      modes.push_back({c.name, c.metric, m, specs.size()});
      specs.push_back(std::move(spec));
    }
  }
  p.write_tables = [root = p.root, specs = p.specs, sweeps = std::move(sweeps),
                    modes = std::move(modes)](const auto& results) {
    write_stability_tables(root, sweeps, results);
    write_failure_modes(root, specs, modes, results);
  };
  return p;
}

// ------------------------------------------------------- speed-accuracy --

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
    const auto front_time = suite::pareto_front(time, err);
    const auto front_work = suite::pareto_front(work, err);
    const auto front_period = suite::pareto_front(time, period);
    Table t{{"case",         "transfer",     "kernel",
             "level",        "cells",        "h",
             "particles",    "steps",        "particle_steps",
             "time_s",       "time_min_s",   "time_max_s",
             "cpu_s",        "cpu_min_s",    "cpu_max_s",
             "repeats",      "passes",       "particle_steps_per_second",
             "wall_seconds", "status",       "error_key",
             "error",        "energy_error", "period_error",
             "pareto_time",  "pareto_work",  "pareto_period"},
            {}};
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const auto& [g, k] = rows[i];
      const RunResult& res = results[g->runs[k]];
      const json& s = res.summary;
      const bool timed = res.status == "ok" && s.contains("timing");
      t.rows.push_back({name,
                        g->method.transfer,
                        g->method.kernel,
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

Plan plan_speed_accuracy(const SuiteRequest& r) {
  Plan p{"speed-accuracy", fs::path(r.out) / "speed_accuracy", {}, {}};
  std::vector<Series> series;
  for (const auto& c : suite::speed_accuracy_cases()) {
    if (runnable(r, c.name, c.scene)) plan_refinement(r, c, false, true, p.specs, series);
  }
  p.write_tables = [root = p.root, series = std::move(series)](const auto& results) {
    write_speed_tables(root, series, results);
  };
  return p;
}

}  // namespace

namespace suite {

std::vector<Plan> plan_suites(const SuiteRequest& request) {
  const std::string& n = request.name;
  std::vector<Plan> plans;
  if (n == "convergence" || n == "all") plans.push_back(plan_convergence(request));
  if (n == "stability" || n == "all") plans.push_back(plan_stability(request));
  if (n == "speed-accuracy" || n == "all") plans.push_back(plan_speed_accuracy(request));
  return plans;
}

}  // namespace suite
}  // namespace mpmtb
