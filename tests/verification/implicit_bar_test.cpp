// The implicit integrators on the vibrating bar (Bardenhagen 2002; 1D, mode 1,
// fixed-free, 16 cells, linear elastic so that the mode is exactly linear),
// against what each integrator's amplification predicts for one mode
// x'' = -omega^2 x (integrators/implicit_impl.hpp):
//   backward Euler: in the coordinates (omega u, v) the step is the rotation
//     by atan(omega dt) scaled by 1 / sqrt(1 + (omega dt)^2), so the energy
//     (v^2 + omega^2 u^2)/2 = K + S falls by exactly 1 / (1 + (omega dt)^2)
//     per step: by (1 + (omega dt)^2)^(-T/dt) per period T;
//   Newmark (trapezoidal): |A| = 1, the grid energy of each step is kept to
//     the solver's tolerance for a quadratic energy;
//   observed orders in dt: 1 and 2 (self-convergence at fixed t, dt halved);
//   below the explicit limit, backward Euler and explicit (symplectic Euler)
//   are both first order, so they differ by O(dt).
// omega = pi c / (2 L) (REFERENCE.md): 16 cells resolve it to 0.1 %, far
// inside the 10 % band of the decay test. FLIP (alpha = 1) moves the grid's
// velocity increments to the particles without the projection's per-step
// damping (PIC's), which would add a decay of its own.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "core/diagnostics.hpp"
#include "core/registry.hpp"
#include "references/reference.hpp"
#include "run.hpp"
#include "setup.hpp"

namespace mpmtb {
namespace implicit_bar_test {

constexpr Real kPi = std::numbers::pi_v<Real>;
constexpr Real kOmega = kPi * 10 / (2 * 25);  // beta_1 c, c = sqrt(E / rho) = 10, L = 25

struct BarRun {
  std::vector<Real> energy;  // K + S after each step (energy[0]: initial)
  std::vector<Real> grid_change, grid_energy;
  std::vector<Vec<1>> v, x;  // particles at the end
  long newton = 0, cg = 0;
  Real residual_max = 0;
  bool converged = true;
  Real dt = 0;
};

BarRun RunBar(Integrator integrator, Real cfl, Real t_end, const std::string& transfer = "flip") {
  const Scene scene =
      load_scene("bar", {.transfer = transfer, .model = std::string("linear-elastic")});
  State<1> s = build_state<1>(scene);
  auto reference = make_reference<1>(scene);
  reference->initialize(s);
  Parameters params = scene.transfer_params;
  auto stepper = make_stepper<1>(scene.transfer, scene.kernel, params);
  ImplicitOptions options;
  options.newton_tol = 1e-10;
  stepper->set_integrator(integrator, options);
  BarRun run;
  run.dt = cfl * scene.dx() / 10;
  const long steps = std::lround(t_end / run.dt);
  run.dt = t_end / steps;
  auto energy = [&] {
    const Diagnostics d = measure(s, *stepper);
    return d.kinetic + d.strain;
  };
  run.energy.push_back(energy());
  for (long n = 0; n < steps; ++n) {
    stepper->step(s, run.dt);
    run.energy.push_back(energy());
    if (const ImplicitStats* st = stepper->implicit_stats()) {
      run.newton += st->newton;
      run.cg += st->cg;
      run.residual_max = std::max(run.residual_max, st->residual);
      run.converged = run.converged && st->converged;
      run.grid_change.push_back(st->grid_energy_change);
      run.grid_energy.push_back(st->grid_energy);
    }
  }
  run.v = s.particles.v;
  run.x = s.particles.x;
  return run;
}

Real Distance(const std::vector<Vec<1>>& a, const std::vector<Vec<1>>& b) {
  Real sum = 0;
  for (std::size_t p = 0; p < a.size(); ++p) sum += (a[p] - b[p]).squaredNorm();
  return std::sqrt(sum / a.size());
}

// Runs `mpmtb run bar` through run_scene at a large CFL number: the status,
// and the solver's figures in series.csv and summary.json.
TEST(ImplicitBar, StaysOkFarBeyondTheExplicitLimit) {
  for (const Real cfl : {5.0, 20.0}) {
    for (const std::string integrator : {"backward-euler", "newmark"}) {
      const auto dir = std::filesystem::temp_directory_path() /
                       ("mpmtb_implicit_bar_" + integrator + std::to_string(int(cfl)));
      std::filesystem::create_directories(dir);
      const Scene scene = load_scene(
          "bar", {.transfer = std::string("flip"), .integrator = integrator, .cfl = cfl});
      const RunOutcome out = run_scene(scene, dir, {});
      EXPECT_EQ(out.status, "ok") << integrator << " cfl " << cfl << ": " << out.reason;
      const nlohmann::json& j = out.summary;
      ASSERT_TRUE(j.contains("implicit")) << j.dump();
      EXPECT_EQ(j["implicit"]["integrator"], integrator);
      EXPECT_GT(j["implicit"]["newton_total"].get<long>(), 0);
      EXPECT_GT(j["implicit"]["cg_total"].get<long>(), 0);
      EXPECT_LE(j["implicit"]["residual_max"].get<double>(), 1e-8);
      std::ifstream series(dir / "series.csv");
      std::string header;
      std::getline(series, header);
      EXPECT_NE(header.find("newton,cg,residual"), std::string::npos) << header;
      std::filesystem::remove_all(dir);
    }
  }
}

// The energy after whole periods against (1 + (omega dt)^2)^(-steps).
TEST(ImplicitBar, BackwardEulerDecayMatchesItsAmplificationFactor) {
  for (const Real cfl : {1.0, 5.0}) {
    const BarRun run = RunBar(Integrator::backward_euler, cfl, 10.0);
    ASSERT_TRUE(run.converged);
    const Real steps = static_cast<Real>(run.energy.size() - 1);
    const Real measured = std::log(run.energy.back() / run.energy.front());
    const Real derived = -steps * std::log(1 + kOmega * kOmega * run.dt * run.dt);
    std::printf("backward Euler, cfl %g: energy after one period %.4g, derived %.4g\n", cfl,
                std::exp(measured), std::exp(derived));
    EXPECT_NEAR(measured / derived, 1, 0.1)
        << "cfl " << cfl << ": energy ratio over a period " << std::exp(measured) << ", derived "
        << std::exp(derived);
  }
}

// Each step's grid energy (P2G's kinetic energy and Psi(F^n) against the
// solved velocities' and Psi(F^n+1)) is kept to the solver's tolerance, at
// any step; the particles' energy follows it up to the transfer's own error.
TEST(ImplicitBar, NewmarkKeepsTheEnergy) {
  for (const Real cfl : {1.0, 5.0, 20.0}) {
    const BarRun run = RunBar(Integrator::newmark, cfl, 40.0);
    ASSERT_TRUE(run.converged);
    Real worst = 0;
    for (std::size_t n = 0; n < run.grid_change.size(); ++n) {
      worst = std::max(worst, std::abs(run.grid_change[n]) / run.grid_energy[n]);
    }
    std::printf(
        "newmark, cfl %g: grid energy change per step <= %.3g; particles' energy kept %.4f "
        "(t = 40); %ld Newton, %ld CG iterations in %zu steps\n",
        cfl, worst, run.energy.back() / run.energy.front(), run.newton, run.cg,
        run.grid_change.size());
    EXPECT_LE(worst, 1e-8) << "cfl " << cfl;
    // Backward Euler at the same step has lost most of it by t = 40.
    const Real kept = run.energy.back() / run.energy.front();
    EXPECT_NEAR(kept, 1, 0.05) << "cfl " << cfl;
  }
}

// Self-convergence at t = 5 (half a period), dt halved twice, in the energy
// norm of the state difference, e^2 = mean_p |v_p - v'_p|^2 + omega^2 |x_p - x'_p|^2:
// at t = 5 the velocities are at their extremum (they see the amplitude,
// backward Euler's first-order decay) and the displacements cross zero (they
// see the phase, Newmark's second-order error). The steps are large enough
// that these dominate the transfer's own per-step error, which grows with
// the number of steps (the P2G projection of each step).
TEST(ImplicitBar, ObservedOrdersInTime) {
  struct Study {
    Integrator integrator;
    Real order;
    std::array<Real, 3> cfl;
  };
  for (const Study& study : {Study{Integrator::backward_euler, 1.0, {1.0, 0.5, 0.25}},
                             Study{Integrator::newmark, 2.0, {4.0, 2.0, 1.0}}}) {
    std::vector<BarRun> runs;
    for (const Real cfl : study.cfl) runs.push_back(RunBar(study.integrator, cfl, 5.0));
    auto error = [&](const BarRun& a, const BarRun& b) {
      return std::hypot(Distance(a.v, b.v), kOmega * Distance(a.x, b.x));
    };
    const Real e1 = error(runs[0], runs[1]), e2 = error(runs[1], runs[2]);
    const Real observed = std::log2(e1 / e2);
    std::printf("%s: e = %.4g, %.4g, observed order %.3f\n",
                std::string(integrator_name(study.integrator)).c_str(), e1, e2, observed);
    EXPECT_NEAR(observed, study.order, 0.3)
        << integrator_name(study.integrator) << ": e = " << e1 << ", " << e2;
  }
}

// Below the explicit limit the two first-order integrators agree to O(dt).
TEST(ImplicitBar, BackwardEulerAgreesWithExplicitToFirstOrder) {
  std::vector<Real> diff;
  for (const Real cfl : {0.4, 0.2, 0.1}) {
    const BarRun be = RunBar(Integrator::backward_euler, cfl, 5.0);
    const BarRun ex = RunBar(Integrator::explicit_euler, cfl, 5.0);
    diff.push_back(Distance(be.v, ex.v));
  }
  std::printf("backward Euler - explicit at cfl 0.4, 0.2, 0.1: %.4g, %.4g, %.4g\n", diff[0],
              diff[1], diff[2]);
  EXPECT_NEAR(std::log2(diff[0] / diff[1]), 1, 0.25) << diff[0] << " " << diff[1];
  EXPECT_NEAR(std::log2(diff[1] / diff[2]), 1, 0.25) << diff[1] << " " << diff[2];
}

}  // namespace implicit_bar_test
}  // namespace mpmtb
