#include "run.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "archive.hpp"
#include "checkpoint.hpp"
#include "core/diagnostics.hpp"
#include "core/errors.hpp"
#include "core/registry.hpp"
#include "extra_columns.hpp"
#include "memory.hpp"
#include "output.hpp"
#include "progress.hpp"
#include "references/reference.hpp"
#include "run_monitors.hpp"
#include "series_stream.hpp"
#include "setup.hpp"
#include "stop.hpp"
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

template <int Dim>
Real gyration_radius(const State<Dim>& s, const Diagnostics& d) {
  Real sum = 0;
  for (std::size_t p = 0; p < s.particles.size(); ++p) {
    sum += s.particles.m[p] * (to3<Dim>(s.particles.x[p]) - d.center_of_mass).squaredNorm();
  }
  return d.mass > 0 ? std::sqrt(sum / d.mass) : 0;
}

// The implicit solve's figures: per series row and over the run.
struct ImplicitTally {
  long row_newton = 0, row_cg = 0;
  Real row_residual = 0;
  long steps = 0, newton_total = 0, newton_max = 0, cg_total = 0, cg_max = 0;
  Real residual_max = 0;
  void add(const ImplicitStats& st) {
    row_newton += st.newton;
    row_cg += st.cg;
    row_residual = std::max(row_residual, st.residual);
    ++steps;
    newton_total += st.newton;
    newton_max = std::max<long>(newton_max, st.newton);
    cg_total += st.cg;
    cg_max = std::max(cg_max, st.cg);
    residual_max = std::max(residual_max, st.residual);
  }
  void next_row() { row_newton = row_cg = 0, row_residual = 0; }
  nlohmann::json json(const Scene& scene) const {
    return {{"integrator", integrator_name(scene.integrator)},
            {"newton_tol", scene.implicit.newton_tol},
            {"newton_max_allowed", scene.implicit.newton_max},
            {"steps", steps},
            {"newton_total", newton_total},
            {"newton_max", newton_max},
            {"newton_mean", steps ? static_cast<double>(newton_total) / steps : 0.0},
            {"cg_total", cg_total},
            {"cg_max", cg_max},
            {"residual_max", residual_max}};
  }
};

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

// What a checkpoint records besides the evolving state: the resolved scene
// (base_summary's `config`) and the options that shape the output, so that
// `--resume` rebuilds the same run.
nlohmann::json checkpoint_meta(const Scene& scene, const RunOptions& options) {
  nlohmann::json j = base_summary(scene);
  j["threads"] = omp_get_max_threads();
  j["frames"] = {{"every", options.frames.every},
                 {"interval", options.frames.interval},
                 {"grid", options.frames.grid}};
  j["checkpoint_every"] = options.checkpoint_every;
  return j;
}

// Writes DIR/checkpoint/state.bin atomically and keeps the figures the summary
// reports (count, size, seconds).
struct CheckpointLog {
  long count = 0;
  std::size_t bytes = 0;
  double seconds = 0, seconds_max = 0;

  void write(const std::filesystem::path& out_dir, const ArchiveWriter& a) {
    const auto t0 = std::chrono::steady_clock::now();
    write_atomically(checkpoint_file(out_dir), a.bytes());
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++count;
    bytes = a.bytes().size();
    seconds += dt;
    seconds_max = std::max(seconds_max, dt);
  }
  void add_to(nlohmann::json& j) const {
    if (count == 0) return;
    j["checkpoints"] = {
        {"count", count}, {"bytes", bytes}, {"seconds", seconds}, {"seconds_max", seconds_max}};
  }
};

template <int Dim>
RunOutcome run_dim(const Scene& scene, const std::filesystem::path& out_dir,
                   const RunOptions& options) {
  State<Dim> s = build_state<Dim>(scene);
  Parameters transfer_params = scene.transfer_params;
  auto stepper = make_stepper<Dim>(scene.transfer, scene.kernel, transfer_params);
  stepper->set_update_order(scene.update_order);
  stepper->set_integrator(scene.integrator, scene.implicit);
  const bool implicit = scene.integrator != Integrator::explicit_euler;
  stepper->prepare(s);  // one-time allocations, outside the timed steps
  auto reference = make_reference<Dim>(scene);
  // Also on resume: a reference keeps what it needs of the initial state (the
  // manufactured solution's X_p); the checkpoint then overwrites the particles.
  if (reference) reference->initialize(s);

  std::vector<std::string> columns = kSeriesColumns;
  // Implicit integrators: the Newton and CG iterations summed over the steps
  // since the previous row, and the largest final relative residual among them.
  if (implicit) {
    for (const char* c : {"newton", "cg", "residual"}) columns.push_back(c);
  }
  ImplicitTally tally;
  const ExtraColumns<Dim> extra(s);
  for (const auto& c : extra.names()) columns.push_back(c);
  if (reference) {
    for (const auto& c : reference->columns()) columns.push_back(c);
  }
  auto sample = [&](const Diagnostics& d) {
    auto row = series_row(s.step, s.time, d);
    if (implicit) {
      row.push_back(static_cast<double>(tally.row_newton));
      row.push_back(static_cast<double>(tally.row_cg));
      row.push_back(tally.row_residual);
      tally.next_row();
    }
    for (double v : extra.values(s)) row.push_back(v);
    if (reference) {
      for (Real v : reference->sample(s, d)) row.push_back(v);
    }
    return row;
  };

  RunMonitors mon;
  FrameSeries<Dim> frames(out_dir, options.frames);
  SeriesStream series;
  const std::string header = CsvTable::render_header(columns);
  if (options.resume) {
    ArchiveReader& a = *options.resume;
    restore_state(a, s);
    a.get("monitors", mon);
    std::vector<Real> accumulated;
    a.get_vector("reference", accumulated);
    if (reference) reference->restore(accumulated);
    frames.restore(a);
    series.resume(out_dir / "series.csv", header, mon.series_bytes);
    ++mon.sessions;
  } else {
    // A checkpoint left by an earlier run in DIR must not be resumed into this one.
    std::filesystem::remove_all(out_dir / "checkpoint");
    mon.d0 = measure(s, *stepper);
    mon.drift.start(mon.d0);
    mon.drift.radius = gyration_radius(s, mon.d0);
    mon.drift.add(mon.d0, 0, Vec3::Zero());
    for (const auto& v : s.particles.v) mon.v_max = std::max(mon.v_max, v.norm());
    mon.J_min = mon.J_elastic_min = mon.d0.J_min;
    mon.J_max = mon.J_elastic_max = mon.d0.J_max;
    mon.next_output = scene.output_interval;
    mon.next_checkpoint = options.checkpoint_every;
    series.start(out_dir / "series.csv", header);
    series.append(CsvTable::render_row(sample(mon.d0)));
    frames.write(s);
  }
  const Diagnostics& d0 = mon.d0;

  const nlohmann::json meta = checkpoint_meta(scene, options);
  CheckpointLog checkpoints;
  const auto wall_start = std::chrono::steady_clock::now();
  auto wall_so_far = [&] {
    return mon.wall_seconds +
           std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  };
  auto write_checkpoint = [&] {
    RunMonitors saved = mon;
    saved.series_bytes = series.bytes();
    saved.wall_seconds = wall_so_far();
    ArchiveWriter a;
    a.put_string("meta", dump_json(meta));
    save_state(a, s);
    a.put("monitors", saved);
    a.put_vector("reference", reference ? reference->saved() : std::vector<Real>{});
    frames.save(a);
    checkpoints.write(out_dir, a);
  };

  const Real dx = s.grid.geo.dx;
  std::string status = "ok", reason;
  int stop_exit = -1;
  const StopWatch stops(options.wall_limit);
  Progress progress(options.label.empty() ? scene.name : options.label, options.progress);

  while (s.time < scene.t_end * (1 - 1e-12)) {
    const Real c = s.max_wave_speed();  // follows the current state (snow hardening)
    Real dt = scene.dt.value_or(0);
    if (!scene.dt) {
      mon.c_max = std::max(mon.c_max, c);
      dt = *scene.cfl * dx / (c + mon.v_max);
    }
    mon.dt_min = std::min(mon.dt_min, dt);  // the scheme's steps, before the last one is cut
    mon.dt_max = std::max(mon.dt_max, dt);
    mon.cfl_check.check(dt, dx / (c + mon.v_max), s.step, s.time, scene.source);
    dt = std::min(dt, scene.t_end - s.time);
    const auto t0 = std::chrono::steady_clock::now();
    const StepReport report = stepper->step(s, dt);
    mon.step_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    mon.v_max = report.v_max;
    progress.update(s.time / scene.t_end, s.step);
    reason = failure_reason(report, scene.J_floor);
    if (const ImplicitStats* st = stepper->implicit_stats()) {
      tally.add(*st);
      if (!st->converged && reason.empty()) {
        reason = fmt::format(
            "the Newton solve did not converge at step {} ({} iterations of method.newton_max = "
            "{}, residual {:.3g} of the step's initial one, tolerance {:.3g})",
            s.step, st->newton, scene.implicit.newton_max, st->residual, scene.implicit.newton_tol);
      }
    }
    if (!reason.empty()) {
      status = "unstable";
      break;
    }
    mon.J_elastic_min = std::min(mon.J_elastic_min, report.J_min);
    mon.J_elastic_max = std::max(mon.J_elastic_max, report.J_max);
    const bool last = s.time >= scene.t_end * (1 - 1e-12);
    frames.after_step(s, last, dt);
    if (s.time >= mon.next_output - 1e-9 * dt || last) {
      while (mon.next_output <= s.time + 1e-9 * dt) mon.next_output += scene.output_interval;
      const Diagnostics d = measure(s, *stepper);
      mon.J_min = std::min(mon.J_min, d.J_min);
      mon.J_max = std::max(mon.J_max, d.J_max);
      mon.domains_clamped_max = std::max(
          mon.domains_clamped_max, clamped_domains<Dim>(scene.kernel, s.particles.F, s.grid.geo.l));
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
      mon.drift.add(d, s.collider_work, impulse);
      series.append(CsvTable::render_row(row));  // on disk now: a stopped run keeps it
      if (status != "ok") break;
    }
    if (last) break;
    // At a step boundary, after this step's output: the state a checkpoint
    // holds is complete, and resuming it repeats nothing.
    if (options.checkpoint_every > 0 && s.time >= mon.next_checkpoint - 1e-9 * dt) {
      while (mon.next_checkpoint <= s.time + 1e-9 * dt)
        mon.next_checkpoint += options.checkpoint_every;
      write_checkpoint();
    }
    if (const auto stop = stops.due()) {
      status = "interrupted";
      reason = stop->reason;
      stop_exit = stop->exit_status;
      write_checkpoint();  // before the last frame below, which a resumed run rewrites
      break;
    }
  }
  progress.finish();
  frames.write(s);  // the last state, also of an unstable or stopped run (no-op if written)
  const double wall_seconds = wall_so_far();

  nlohmann::json j = base_summary(scene);
  j["status"] = status;
  if (status == "interrupted") {
    j["reason"] = reason;
    j["stop_step"] = s.step;
    j["stop_t"] = s.time;
    j["resume"] = {{"command", fmt::format("mpmtb run --resume {}", out_dir.string())},
                   {"checkpoint", checkpoint_file(out_dir).string()},
                   {"step", s.step},
                   {"t", s.time}};
  } else if (status != "ok") {
    j["reason"] = reason;
    j["fail_step"] = s.step;
    j["fail_t"] = s.time;
  }
  const double particle_steps = static_cast<double>(s.particles.size()) * s.step;
  j["particles"] = s.particles.size();
  j["steps"] = s.step;
  j["t"] = s.time;
  j["dt_min"] = mon.dt_min;
  j["dt_max"] = mon.dt_max;
  if (!scene.dt) j["wave_speed_max"] = mon.c_max;
  mon.cfl_check.add_to(j);
  j["threads"] = omp_get_max_threads();
  j["wall_seconds"] = wall_seconds;
  j["step_seconds"] = mon.step_seconds;
  j["particle_steps_per_second"] = mon.step_seconds > 0 ? particle_steps / mon.step_seconds : 0;
  j["ns_per_particle_step"] = particle_steps > 0 ? 1e9 * mon.step_seconds / particle_steps : 0;
  if (mon.sessions > 1) j["sessions"] = mon.sessions;
  checkpoints.add_to(j);
  j["drift"] = mon.drift.json();
  j["J_min"] = mon.J_min;
  j["J_max"] = mon.J_max;
  if (mon.domains_clamped_max >= 0) j["domains_clamped_max"] = mon.domains_clamped_max;
  j["J_elastic_min"] = mon.J_elastic_min;
  j["J_elastic_max"] = mon.J_elastic_max;
  if (frames.enabled()) j["frames"] = frames.summary();
  if (implicit) j["implicit"] = tally.json(scene);
  if (reference) {
    j["error"] = reference->errors();
    j["measured"] = reference->measured();
  }
  if (options.timing.repeats > 0 && status == "ok")
    j["timing"] = time_stepping(scene, options.timing);

  write_atomically(out_dir / "summary.json", dump_json(j));
  // A finished run needs no restart point (an unstable one would only repeat its failure).
  if (status != "interrupted") std::filesystem::remove_all(out_dir / "checkpoint");
  return {status, reason, j, stop_exit};
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
    // Before anything is allocated: a run too large for the machine is refused.
    check_memory(scene, options.frames, options.max_memory);
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
