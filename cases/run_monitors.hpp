// What a run carries from step to step besides the State: the conservation and
// time-step monitors and where the next output and checkpoint fall. Plain
// values only (trivially copyable), so that a checkpoint stores them as raw
// bytes and a resumed run continues with the same bits.
#pragma once

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>

#include "core/diagnostics.hpp"

namespace mpmtb {

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

struct RunMonitors {
  Diagnostics d0;  // the initial state: the energy put in is measured from it
  DriftMonitor drift;
  CflCheck cfl_check;
  Real c_max = 0;  // largest wave speed the CFL step used (hardening raises it)
  Real v_max = 0;  // max |v_p| after the last step: the next CFL step uses it
  // J range: of the total deformation at output times, and of det F_p (the
  // elastic part for plasticity) at every step, which is what inverts.
  Real J_min = 1, J_max = 1, J_elastic_min = 1, J_elastic_max = 1;
  Real dt_min = std::numeric_limits<Real>::infinity(), dt_max = 0;
  Real next_output = 0;
  Real next_checkpoint = 0;
  double step_seconds = 0;         // time spent stepping, over every session of the run
  double wall_seconds = 0;         // wall time of the sessions before this one
  std::uint64_t series_bytes = 0;  // series.csv's length at this state
  // Kernels with deformed domains (cpGIMP, CPDI): the most particles whose domain
  // was clamped to the support at an output time (-1: a fixed-domain kernel).
  long domains_clamped_max = -1;
  long sessions = 1;  // 1 + the times the run was resumed
};

}  // namespace mpmtb
