#include "common.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>

#include "analysis.hpp"
#include "core/errors.hpp"
#include "core/registry.hpp"
#include "core/stepper.hpp"
#include "output.hpp"
#include "scene.hpp"
#include "setup.hpp"
#include "shard.hpp"

namespace mpmtb::suite {

namespace fs = std::filesystem;
using nlohmann::json;

bool wanted(const std::vector<std::string>& filter, const std::string& name) {
  return filter.empty() || std::find(filter.begin(), filter.end(), name) != filter.end();
}

namespace {

template <class List>
std::vector<std::string> names_of(const List& list) {
  std::vector<std::string> n;
  for (const auto& v : list) n.push_back(std::string(v.name));
  return n;
}

void check_names(const char* option, const std::vector<std::string>& given,
                 const std::vector<std::string>& allowed) {
  for (const auto& g : given) {
    if (std::find(allowed.begin(), allowed.end(), g) == allowed.end()) {
      throw InputError(fmt::format("suite: {} '{}' is unknown; allowed: {}", option, g,
                                   fmt::join(allowed, ", ")));
    }
  }
}

// true when the transfer takes the implicit integrator (Stepper::set_integrator
// decides; a 1D stepper is enough: the rule does not depend on the dimension).
bool takes_integrator(const std::string& transfer, const std::string& kernel,
                      const std::string& integrator) {
  Parameters params;
  auto stepper = make_stepper<1>(transfer, kernel, params);
  try {
    stepper->set_integrator(parse_integrator(integrator));
    return true;
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace

void check_filters(const SuiteRequest& r) {
  check_names("--transfer", r.transfers, names_of(transfer_list()));
  check_names("--kernel", r.kernels, names_of(kernel_list()));
  std::vector<std::string> integrators;
  for (const auto n : kIntegratorNames) integrators.emplace_back(n);
  check_names("--integrator", r.integrators, integrators);
}

std::vector<Method> methods(const SuiteRequest& r, const std::string& integrator,
                            const std::vector<std::string>& transfers,
                            const std::vector<std::string>& kernels) {
  std::vector<Method> m;
  if (!wanted(r.integrators, integrator)) return m;
  const bool implicit = integrator != "explicit";
  for (const auto& t : transfer_list()) {
    for (const auto& k : kernel_list()) {
      // A reduced build (MPMTB_COMBINATIONS=reduced, the sanitizer tree) plans
      // only the combinations it compiles; the default build compiles every one.
      if (!wanted(r.transfers, t.name) || !wanted(r.kernels, k.name) ||
          !unsupported_reason(t.name, k.name).empty() || !compiled_combination(t.name, k.name)) {
        continue;
      }
      if (implicit && (!wanted(transfers, t.name) || !wanted(kernels, k.name) ||
                       !takes_integrator(t.name, k.name, integrator))) {
        continue;
      }
      m.push_back({t.name, k.name, integrator});
    }
  }
  return m;
}

std::vector<std::string> implicit_integrators(const SuiteRequest& r) {
  std::vector<std::string> out;
  for (const auto n : kIntegratorNames) {
    if (n != "explicit" && wanted(r.integrators, std::string(n))) out.emplace_back(n);
  }
  return out;
}

namespace {
bool scene_exists(const std::string& name) {
  for (const auto& b : builtin_scenes()) {
    if (b.name == name) return true;
  }
  return false;
}
}  // namespace

bool runnable(const SuiteRequest& r, const std::string& name, const std::string& scene) {
  if (!wanted(r.cases, name)) return false;
  if (scene_exists(scene)) return true;
  if (!r.quiet)
    fmt::print(stderr, "suite: case '{}' skipped: no built-in scene '{}'\n", name, scene);
  return false;
}

std::string num(double v) {
  return std::isfinite(v) ? fmt::format("{:.6g}", v) : "";
}

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

void Table::write(const fs::path& path) const {
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

RunSpec make_spec(const std::string& case_name, const std::string& scene, int dim, const Method& m,
                  int cells, double t_end, const std::vector<std::string>& sets) {
  RunSpec s;
  s.case_name = case_name;
  s.scene = scene;
  s.dim = dim;
  s.transfer = m.transfer;
  s.kernel = m.kernel;
  if (!m.is_explicit()) s.integrator = m.integrator;
  s.cells = cells;
  s.sets = sets;
  if (t_end > 0) s.t_end = t_end;
  return s;
}

Overrides overrides_for(int dim, int cells, const std::vector<std::string>& sets) {
  Overrides o;
  o.dim = dim;
  o.cells = cells;
  o.set = sets;
  return o;
}

namespace {
// Timed runs of the speed-accuracy suite: repetitions and the stepping time of each.
constexpr int kTimingRepeats = 3;
constexpr double kTimingMinSeconds = 0.5;
}  // namespace

void plan_refinement(const SuiteRequest& r, const ConvergenceCase& c,
                     const std::vector<Method>& methods, const Levels& levels, double cfl,
                     bool dt_study, bool timed, const std::string& folder,
                     std::vector<RunSpec>& specs, std::vector<Series>& series) {
  const double t_end = r.full ? c.t_end_full : c.t_end_quick;
  const int dt_cells = dt_study ? (r.full ? c.dt_cells_full : c.dt_cells_quick) : 0;
  const Scene base = load_scene(c.scene, overrides_for(c.dim, 8, c.sets));
  const CostModel model(base);
  double dt0 = kNaN;
  if (dt_cells > 0) {
    const Scene s = load_scene(c.scene, overrides_for(c.dim, dt_cells, c.sets));
    dt0 = c.dt_cfl * s.dx() / max_wave_speed(s);
  }
  for (const Method& m : methods) {
    const fs::path dir = folder.empty() ? fs::path("runs") / c.name / m.name()
                                        : fs::path("runs") / c.name / m.name() / folder;
    Series g{c.name, "grid", c.error_key, m, cfl, {}, {}, {}};
    const auto cells = levels.cells();
    for (std::size_t k = 0; k < cells.size(); ++k) {
      RunSpec s = make_spec(c.name, c.scene, c.dim, m, cells[k], t_end, c.sets);
      s.cfl = cfl;
      if (timed) {
        s.timing_repeats = kTimingRepeats;
        s.timing_min_seconds = kTimingMinSeconds;
      }
      s.dir = dir / fmt::format("L{}", k);
      s.cost = model.cost(s);
      g.runs.push_back(specs.size());
      g.h.push_back(base.length / cells[k]);
      specs.push_back(std::move(s));
    }
    if (!g.runs.empty()) series.push_back(std::move(g));
    if (dt_cells <= 0) continue;
    Series d{c.name, "dt", c.error_key, m, cfl, {}, {}, {}};
    for (int k = 0; k < 5; ++k) {
      RunSpec s = make_spec(c.name, c.scene, c.dim, m, dt_cells, t_end, c.sets);
      s.dt = dt0 / (1 << k);
      s.dir = dir / fmt::format("dt{}", k);
      s.cost = model.cost(s);
      d.runs.push_back(specs.size());
      d.h.push_back(base.length / dt_cells);
      d.dt.push_back(*s.dt);
      specs.push_back(std::move(s));
    }
    series.push_back(std::move(d));
  }
}

}  // namespace mpmtb::suite
