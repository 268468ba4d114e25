#include "run.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "core/diagnostics.hpp"
#include "core/errors.hpp"
#include "core/registry.hpp"
#include "extra_columns.hpp"
#include "output.hpp"
#include "progress.hpp"
#include "references/reference.hpp"
#include "setup.hpp"
#include "version.hpp"
#include "vtk/frames.hpp"

namespace mpmtb {
namespace {

const std::vector<std::string> kSeriesColumns = {
    "step", "t",  "kinetic", "strain", "gravity", "total", "px",    "py",
    "pz",   "Lx", "Ly",      "Lz",     "volume",  "J_min", "J_max", "dissipated"};

std::vector<double> series_row(long step, Real t, const Diagnostics& d) {
  return {static_cast<double>(step),
          t,
          d.kinetic,
          d.strain,
          d.gravity,
          d.total,
          d.momentum[0],
          d.momentum[1],
          d.momentum[2],
          d.angular_momentum[0],
          d.angular_momentum[1],
          d.angular_momentum[2],
          d.volume,
          d.J_min,
          d.J_max,
          d.dissipated};
}

bool all_finite(const std::vector<double>& row) {
  for (double v : row) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

// Tracks the run's conservation figures from the output samples.
struct DriftMonitor {
  Diagnostics first, last;
  Real mechanical_max = 0;  // max of kinetic + strain
  Real energy_dev_max = 0;  // max |E(t) - E(0)|
  Real radius = 0;          // radius of gyration at t = 0

  void start(const Diagnostics& d) { first = last = d; }
  // work and impulse: what colliders, pinned nodes and gravity have done to the
  // material so far; taken off so that the drifts are the scheme's own (wall
  // reactions are not tracked and stay in the momentum drift).
  void add(Diagnostics d, Real work, const Vec3& impulse) {
    d.total -= work;
    d.momentum -= impulse;
    last = d;
    mechanical_max = std::max(mechanical_max, d.kinetic + d.strain);
    energy_dev_max = std::max(energy_dev_max, std::abs(d.total - first.total));
  }
  nlohmann::json json() const {
    // Scales: momentum sqrt(2 M K_max), angular momentum that times the radius of
    // gyration, energy the largest kinetic + strain energy seen.
    const Real p_scale = std::sqrt(2 * first.mass * mechanical_max);
    const Real L_scale = p_scale * radius;
    auto ratio = [](Real num, Real den) { return den > 0 ? num / den : num; };
    nlohmann::json j;
    j["mass"] = ratio(std::abs(last.mass - first.mass), first.mass);
    j["momentum"] = ratio((last.momentum - first.momentum).norm(), p_scale);
    j["angular_momentum"] = ratio((last.angular_momentum - first.angular_momentum).norm(), L_scale);
    j["energy"] = ratio(last.total - first.total, mechanical_max);
    j["energy_max"] = ratio(energy_dev_max, mechanical_max);
    j["volume"] = ratio(last.volume - first.volume, first.volume);
    return j;
  }
};

template <int Dim>
Real gyration_radius(const State<Dim>& s, const Diagnostics& d) {
  Real sum = 0;
  for (std::size_t p = 0; p < s.particles.size(); ++p) {
    sum += s.particles.m[p] * (to3<Dim>(s.particles.x[p]) - d.center_of_mass).squaredNorm();
  }
  return d.mass > 0 ? std::sqrt(sum / d.mass) : 0;
}

// The reason a step's report marks the run unstable, or empty.
std::string failure_reason(const StepReport& r, Real J_floor) {
  if (r.non_finite >= 0)
    return fmt::format("non-finite value (NaN/Inf) at particle {}", r.non_finite);
  if (r.J_min <= 0) return fmt::format("J <= 0 (J_min = {:.3g}): inverted element", r.J_min);
  if (r.J_min <= J_floor) {
    return fmt::format("J <= checks.J_floor = {:.3g} (J_min = {:.3g}): element crushed", J_floor,
                       r.J_min);
  }
  if (r.outside >= 0) return fmt::format("particle {} left the domain", r.outside);
  return {};
}

// Compares each step with the CFL limit of the current state, dt_cfl = dx /
// (c_p + max|v|) (CFL number 1; Courant, Friedrichs & Lewy 1928), and warns
// once on stderr when the step exceeds it.
struct CflCheck {
  Real ratio_max = 0;  // max over the run of dt / dt_cfl
  long first_step = -1;
  Real first_t = 0;

  void check(Real dt, Real dt_cfl, long step, Real t, const std::string& source) {
    const Real ratio = dt / dt_cfl;
    if (ratio > ratio_max) ratio_max = ratio;
    if (ratio > 1 && first_step < 0) {
      first_step = step;
      first_t = t;
      fmt::print(stderr,
                 "mpmtb: warning: {}: dt = {:.4g} exceeds the CFL limit dx / (c_p + max|v|) = "
                 "{:.4g} at step {} (t = {:.4g}); the explicit step may be unstable\n",
                 source, dt, dt_cfl, step, t);
    }
  }
  void add_to(nlohmann::json& j) const {
    j["dt_cfl_ratio_max"] = ratio_max;
    if (first_step >= 0) {
      j["dt_cfl_exceeded"] = {
          {"ratio_max", ratio_max}, {"first_step", first_step}, {"first_t", first_t}};
    }
  }
};

nlohmann::json base_summary(const Scene& scene) {
  nlohmann::json j;
  j["scene"] = scene.name;
  j["source"] = scene.source;
  j["dim"] = scene.dim;
  j["transfer"] = scene.transfer;
  j["kernel"] = scene.kernel;
  nlohmann::json models = nlohmann::json::array();
  for (const auto& m : scene.materials) models.push_back(m.model);
  j["models"] = models;
  j["cells"] = scene.cells;
  j["dx"] = scene.dx();
  j["ppc"] = scene.ppc;
  j["t_end"] = scene.t_end;
  if (scene.cfl) j["cfl"] = *scene.cfl;
  if (scene.dt) j["dt"] = *scene.dt;
  j["git_revision"] = build_info().git_revision;
  j["build_type"] = build_info().build_type;
  j["version"] = version_json();
  j["config"] = toml_to_json(scene.resolved);
  return j;
}

template <int Dim>
RunOutcome run_dim(const Scene& scene, const std::filesystem::path& out_dir,
                   const RunOptions& options) {
  State<Dim> s = build_state<Dim>(scene);
  Parameters transfer_params = scene.transfer_params;
  auto stepper = make_stepper<Dim>(scene.transfer, scene.kernel, transfer_params);
  stepper->set_update_order(scene.update_order);
  stepper->prepare(s);  // one-time allocations, outside the timed steps
  auto reference = make_reference<Dim>(scene);
  if (reference) reference->initialize(s);

  CsvTable series;
  series.header = kSeriesColumns;
  const ExtraColumns<Dim> extra(s);
  for (const auto& c : extra.names()) series.header.push_back(c);
  if (reference) {
    for (const auto& c : reference->columns()) series.header.push_back(c);
  }
  auto sample = [&](const Diagnostics& d) {
    auto row = series_row(s.step, s.time, d);
    for (double v : extra.values(s)) row.push_back(v);
    if (reference) {
      for (Real v : reference->sample(s, d)) row.push_back(v);
    }
    return row;
  };

  const Diagnostics d0 = measure(s, *stepper);
  DriftMonitor drift;
  drift.start(d0);
  drift.radius = gyration_radius(s, d0);
  drift.add(d0, 0, Vec3::Zero());
  series.rows.push_back(sample(d0));

  const Real dx = s.grid.geo.dx;
  Real c_max = 0;  // largest wave speed the CFL step used (hardening raises it)
  Real v_max = 0;
  for (const auto& v : s.particles.v) v_max = std::max(v_max, v.norm());
  // J range: of the total deformation at output times, and of det F_p (the
  // elastic part for plasticity) at every step, which is what inverts.
  Real J_min = d0.J_min, J_max = d0.J_max, J_elastic_min = d0.J_min, J_elastic_max = d0.J_max;
  Real dt_min = std::numeric_limits<Real>::infinity(), dt_max = 0;
  CflCheck cfl_check;
  Real next_output = scene.output_interval;
  std::string status = "ok", reason;
  double step_seconds = 0;
  const auto wall_start = std::chrono::steady_clock::now();
  FrameSeries<Dim> frames(out_dir, options.frames);
  frames.write(s);
  Progress progress(options.label.empty() ? scene.name : options.label, options.progress);

  while (s.time < scene.t_end * (1 - 1e-12)) {
    const Real c = s.max_wave_speed();  // follows the current state (snow hardening)
    Real dt = scene.dt.value_or(0);
    if (!scene.dt) {
      c_max = std::max(c_max, c);
      dt = *scene.cfl * dx / (c + v_max);
    }
    dt_min = std::min(dt_min, dt);  // the scheme's steps, before the last one is cut
    dt_max = std::max(dt_max, dt);
    cfl_check.check(dt, dx / (c + v_max), s.step, s.time, scene.source);
    dt = std::min(dt, scene.t_end - s.time);
    const auto t0 = std::chrono::steady_clock::now();
    const StepReport report = stepper->step(s, dt);
    step_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    v_max = report.v_max;
    progress.update(s.time / scene.t_end, s.step);
    reason = failure_reason(report, scene.J_floor);
    if (!reason.empty()) {
      status = "unstable";
      break;
    }
    J_elastic_min = std::min(J_elastic_min, report.J_min);
    J_elastic_max = std::max(J_elastic_max, report.J_max);
    const bool last = s.time >= scene.t_end * (1 - 1e-12);
    frames.after_step(s, last, dt);
    if (s.time >= next_output - 1e-9 * dt || last) {
      while (next_output <= s.time + 1e-9 * dt) next_output += scene.output_interval;
      const Diagnostics d = measure(s, *stepper);
      J_min = std::min(J_min, d.J_min);
      J_max = std::max(J_max, d.J_max);
      auto row = sample(d);
      // Energy above the limit times what was put in (initial kinetic + strain
      // energy plus the work of gravity and colliders) means the scheme is amplifying.
      const Real put_in = d0.kinetic + d0.strain + d0.gravity - d.gravity + s.collider_work;
      if (!all_finite(row)) {
        status = "unstable";
        reason = "non-finite diagnostics";
        break;
      }
      if (d.kinetic + d.strain > scene.energy_limit * std::max(put_in, Real(1e-300))) {
        status = "unstable";
        reason = fmt::format("energy grew to {:.3g} times the energy put in",
                             (d.kinetic + d.strain) / put_in);
      }
      const Vec3 impulse =
          s.collider_impulse + s.pin_impulse + d0.mass * s.time * to3<Dim>(s.gravity);
      drift.add(d, s.collider_work, impulse);
      series.rows.push_back(std::move(row));
      if (status != "ok") break;
    }
  }
  progress.finish();
  frames.write(s);  // the last state, also of an unstable run (no-op if written)
  const double wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  nlohmann::json j = base_summary(scene);
  j["status"] = status;
  if (status != "ok") {
    j["reason"] = reason;
    j["fail_step"] = s.step;
    j["fail_t"] = s.time;
  }
  const double particle_steps = static_cast<double>(s.particles.size()) * s.step;
  j["particles"] = s.particles.size();
  j["steps"] = s.step;
  j["t"] = s.time;
  j["dt_min"] = dt_min;
  j["dt_max"] = dt_max;
  if (!scene.dt) j["wave_speed_max"] = c_max;
  cfl_check.add_to(j);
  j["threads"] = omp_get_max_threads();
  j["wall_seconds"] = wall_seconds;
  j["step_seconds"] = step_seconds;
  j["particle_steps_per_second"] = step_seconds > 0 ? particle_steps / step_seconds : 0;
  j["ns_per_particle_step"] = particle_steps > 0 ? 1e9 * step_seconds / particle_steps : 0;
  j["drift"] = drift.json();
  j["J_min"] = J_min;
  j["J_max"] = J_max;
  j["J_elastic_min"] = J_elastic_min;
  j["J_elastic_max"] = J_elastic_max;
  if (frames.enabled()) j["frames"] = frames.summary();
  if (reference) {
    j["error"] = reference->errors();
    j["measured"] = reference->measured();
  }

  write_atomically(out_dir / "series.csv", series.render());
  write_atomically(out_dir / "summary.json", dump_json(j));
  return {status, reason, j};
}

}  // namespace

std::string dump_json(const nlohmann::json& j) {
  // Invalid UTF-8 (say, in a file name) is replaced, never a reason to lose a summary.
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

nlohmann::json toml_to_json(const toml::node& node) {
  if (const auto* t = node.as_table()) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [k, v] : *t) j[std::string(k.str())] = toml_to_json(v);
    return j;
  }
  if (const auto* a = node.as_array()) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& v : *a) j.push_back(toml_to_json(v));
    return j;
  }
  if (node.is_integer()) return node.value<std::int64_t>().value();
  if (node.is_floating_point()) return node.value<double>().value();
  if (node.is_boolean()) return node.value<bool>().value();
  if (node.is_string()) return node.value<std::string>().value();
  return nullptr;
}

RunOutcome run_scene(const Scene& scene, const std::filesystem::path& out_dir,
                     const RunOptions& options) {
  if (options.threads > 0) omp_set_num_threads(options.threads);
  try {
    switch (scene.dim) {
      case 1:
        return run_dim<1>(scene, out_dir, options);
      case 2:
        return run_dim<2>(scene, out_dir, options);
      default:
        return run_dim<3>(scene, out_dir, options);
    }
  } catch (const InputError& e) {
    // Set-up errors (seeding, references, refused combinations) name the scene too.
    throw InputError(fmt::format("{}: {}", scene.source, e.what()));
  }
}

RunOutcome write_invalid(const std::filesystem::path& out_dir, const std::string& reason,
                         const nlohmann::json& context) {
  nlohmann::json j = context;
  j["status"] = "invalid";
  j["reason"] = reason;
  j["version"] = version_json();
  write_atomically(out_dir / "summary.json", dump_json(j));
  return {"invalid", reason, j};
}

}  // namespace mpmtb
