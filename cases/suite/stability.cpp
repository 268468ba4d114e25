// The stability suite's plan and tables: each method's runs over a CFL grid
// per particles-per-cell count (the explicit integrator up to a little past its
// von Neumann limit, the implicit ones far beyond it), the largest stable CFL,
// and the failure modes shown on purpose.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "analysis.hpp"
#include "common.hpp"
#include "plan.hpp"
#include "setup.hpp"
#include "shard.hpp"

namespace mpmtb::suite {
namespace {

namespace fs = std::filesystem;

std::vector<double> cfl_grid(const StabilityCase& c, bool full) {
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
  Table stable{{"case", "dim", "transfer", "kernel", "integrator", "ppc", "stable_cfl",
                "first_unstable_cfl", "failure", "fail_step", "vn_low", "vn_high", "reason"},
               {}};
  for (const Sweep& s : sweeps) {
    Table& t = per_case[s.case_name];
    if (t.header.empty()) {
      t.header = {"case",   "transfer", "kernel",    "integrator", "ppc",   "cfl",
                  "status", "failure",  "fail_step", "steps",      "reason"};
    }
    std::vector<bool> ok;
    for (std::size_t i = 0; i < s.runs.size(); ++i) {
      const RunResult& r = results[s.runs[i]];
      ok.push_back(r.status == "ok");
      t.rows.push_back({s.case_name, s.method.transfer, s.method.kernel, s.method.integrator,
                        std::to_string(s.ppc), num(s.cfl[i]), r.status, failure_kind(r),
                        int_text(r.summary, "fail_step"), int_text(r.summary, "steps"),
                        r.status == "ok" ? "" : r.reason});
    }
    const auto range = largest_stable(s.cfl, ok);
    // The von Neumann estimate is symplectic Euler's: no limit for the implicit ones.
    const auto vn =
        s.method.is_explicit() ? von_neumann_cfl(s.method.kernel, s.dim) : CflEstimate{kNaN, kNaN};
    std::string kind, step, reason;
    if (range.first_unstable_index >= 0) {
      const RunResult& r = results[s.runs[range.first_unstable_index]];
      kind = failure_kind(r);
      step = int_text(r.summary, "fail_step");
      reason = r.reason;
    }
    stable.rows.push_back({s.case_name, std::to_string(s.dim), s.method.transfer, s.method.kernel,
                           s.method.integrator, std::to_string(s.ppc), num(range.stable),
                           num(range.first_unstable), kind, step, num(vn.low), num(vn.high),
                           reason});
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
  Table t{{"case", "metric", "transfer", "kernel", "integrator", "status", "value", "reason"}, {}};
  for (const Mode& m : modes) {
    const RunResult& res = results[m.run];
    t.rows.push_back({m.case_name, m.metric, m.method.transfer, m.method.kernel,
                      m.method.integrator, res.status,
                      num(failure_metric(m.metric, root / specs[m.run].dir, res)),
                      res.status == "ok" ? "" : res.reason});
  }
  if (!modes.empty()) t.write(root / "failure_modes.csv");
}

}  // namespace

Plan plan_stability(const SuiteRequest& r) {
  Plan p{"stability", fs::path(r.out) / "stability", {}, {}};
  std::vector<RunSpec>& specs = p.specs;
  std::vector<Sweep> sweeps;
  for (const auto& c : stability_cases()) {
    if (!runnable(r, c.name, c.scene)) continue;
    const CostModel model(load_scene(c.scene, overrides_for(c.dim, c.cells, c.sets)));
    const auto sweep = [&](const Method& m, int ppc, const std::vector<double>& grid) {
      Sweep s{c.name, c.dim, m, ppc, grid, {}};
      for (double cfl : grid) {
        RunSpec spec = make_spec(c.name, c.scene, c.dim, m, c.cells, c.t_end, c.sets);
        spec.ppc = ppc;
        spec.cfl = cfl;
        spec.dir = fs::path("runs") / c.name / m.name() / fmt::format("ppc{}-cfl{:.3f}", ppc, cfl);
        spec.cost = model.cost(spec);
        s.runs.push_back(specs.size());
        specs.push_back(std::move(spec));
      }
      sweeps.push_back(std::move(s));
    };
    const auto grid = cfl_grid(c, r.full);
    const auto& ppcs = r.full ? c.full_ppc : c.quick_ppc;
    for (const Method& m : methods(r)) {
      for (int ppc : ppcs) sweep(m, ppc, grid);
    }
    // The implicit integrators on their own CFL grid: the quick level's few
    // methods at one ppc, or with --full every method that takes them at every ppc.
    const auto& implicit_grid = r.full ? c.implicit_cfl_full : c.implicit_cfl_quick;
    if (implicit_grid.empty()) continue;
    for (const auto& integrator : implicit_integrators(r)) {
      const auto listed = r.full ? methods(r, integrator)
                                 : methods(r, integrator, c.implicit_transfers, c.implicit_kernels);
      for (const Method& m : listed) {
        if (r.full) {
          for (int ppc : ppcs) sweep(m, ppc, implicit_grid);
        } else {
          sweep(m, c.implicit_ppc, implicit_grid);
        }
      }
    }
  }
  // Failure modes shown on purpose, every method on each case.
  std::vector<Mode> modes;
  for (const auto& c : failure_mode_cases()) {
    if (!runnable(r, c.name, c.scene)) continue;
    const Scene base = load_scene(c.scene, {});
    const int cells = c.cells > 0 ? c.cells : base.cells;
    const CostModel model(load_scene(c.scene, overrides_for(c.dim, cells, c.sets)));
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

}  // namespace mpmtb::suite
