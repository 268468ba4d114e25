#include "timing.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>
#include <stdexcept>

#include "core/registry.hpp"
#include "references/reference.hpp"
#include "setup.hpp"

namespace mpmtb {
namespace {

double cpu_now() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Pass {
  double wall = 0, cpu = 0, particle_steps = 0;
};

// One run from a fresh state to t_end with the run driver's time steps
// (run.cpp), without diagnostics or output: only the stepping is timed.
template <int Dim>
Pass one_pass(const Scene& scene) {
  State<Dim> s = build_state<Dim>(scene);
  Parameters transfer_params = scene.transfer_params;
  auto stepper = make_stepper<Dim>(scene.transfer, scene.kernel, transfer_params);
  stepper->set_update_order(scene.update_order);
  stepper->set_integrator(scene.integrator, scene.implicit);
  stepper->prepare(s);
  auto reference = make_reference<Dim>(scene);
  if (reference) reference->initialize(s);
  Real v_max = 0;
  for (const auto& v : s.particles.v) v_max = std::max(v_max, v.norm());
  const Real dx = s.grid.geo.dx;
  const double cpu0 = cpu_now();
  const auto wall0 = std::chrono::steady_clock::now();
  while (s.time < scene.t_end * (1 - 1e-12)) {
    Real dt = scene.dt ? *scene.dt : *scene.cfl * dx / (s.max_wave_speed() + v_max);
    dt = std::min(dt, scene.t_end - s.time);
    const StepReport report = stepper->step(s, dt);
    v_max = report.v_max;
    if (report.non_finite >= 0 || report.J_min <= 0 || report.outside >= 0) {
      throw std::runtime_error(
          fmt::format("timing: a pass of '{}' failed at step {}", scene.source, s.step));
    }
  }
  Pass p;
  p.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  p.cpu = cpu_now() - cpu0;
  p.particle_steps = static_cast<double>(s.particles.size()) * static_cast<double>(s.step);
  return p;
}

Pass timed_pass(const Scene& scene) {
  switch (scene.dim) {
    case 1:
      return one_pass<1>(scene);
    case 2:
      return one_pass<2>(scene);
    default:
      return one_pass<3>(scene);
  }
}

nlohmann::json stats(const std::vector<double>& v) {
  return {{"median", median(v)},
          {"min", *std::min_element(v.begin(), v.end())},
          {"max", *std::max_element(v.begin(), v.end())}};
}

}  // namespace

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

nlohmann::json time_stepping(const Scene& scene, const TimingOptions& o) {
  if (o.repeats < 1) throw std::invalid_argument("timing: repeats must be at least 1");
  std::vector<double> wall, cpu, rate;
  nlohmann::json reps = nlohmann::json::array();
  double particle_steps = 0;
  for (int r = 0; r < o.repeats; ++r) {
    Pass sum;
    long passes = 0;
    while (passes == 0 || sum.wall < o.min_seconds) {
      const Pass p = timed_pass(scene);
      sum.wall += p.wall;
      sum.cpu += p.cpu;
      sum.particle_steps += p.particle_steps;
      particle_steps = p.particle_steps;
      ++passes;
    }
    const double n = static_cast<double>(passes);
    wall.push_back(sum.wall / n);
    cpu.push_back(sum.cpu / n);
    rate.push_back(sum.wall > 0 ? sum.particle_steps / sum.wall : 0);
    reps.push_back({{"passes", passes},
                    {"seconds", sum.wall},
                    {"cpu_seconds", sum.cpu},
                    {"seconds_per_pass", wall.back()},
                    {"cpu_seconds_per_pass", cpu.back()}});
  }
  return {{"repeats", o.repeats},
          {"min_seconds", o.min_seconds},
          {"particle_steps", particle_steps},
          {"seconds_per_pass", stats(wall)},
          {"cpu_seconds_per_pass", stats(cpu)},
          {"particle_steps_per_second", stats(rate)},
          {"repetitions", reps}};
}

}  // namespace mpmtb
