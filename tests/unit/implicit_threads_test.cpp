// The implicit step is bit-identical for 1 and 2 threads, as the explicit one
// is (step_test.cpp, ThreadCountDoesNotChangeTheResult): its particle-to-node
// sums scatter over P2G's block colours, and its sums over particles add each
// particle's term in index order (integrators/implicit_particles.hpp). The
// scenes have enough particles for the parallel loops (kParallelMinimum), and
// the steps are far beyond the explicit limit so that Newton and CG iterate:
// a hanging block held by pins under gravity (walls, pins, a nonlinear model)
// in 2D and 3D, and the manufactured solution in 2D (a body force).
#include <gtest/gtest.h>
#include <omp.h>

#include <string>

#include "core/registry.hpp"
#include "references/reference.hpp"
#include "setup.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace implicit_threads_test {

std::string HangingBlock(int dim, int cells) {
  return "[scene]\nname = \"hang\"\ndim = " + std::to_string(dim) +
         "\ndims = [2, 3]\n"
         "[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
         "[grid]\ncells = " +
         std::to_string(cells) +
         "\nppc = 2\n"
         "[method]\ntransfer = \"apic\"\nkernel = \"quadratic\"\n"
         "[time]\nt_end = 0.5\ndt = 0.01\n"
         "[physics]\ngravity = [0.0, -9.81, 0.0]\n"
         "[boundary]\ndefault = \"slip\"\ny_min = \"sticky\"\n"
         "[materials.jelly]\nmodel = \"neo-hookean\"\nE = 1e4\nnu = 0.3\ndensity = 10.0\n"
         "[[bodies]]\nshape = \"box\"\nmin = [0.125, 0.125, 0.25]\nmax = [0.875, 0.875, 0.75]\n"
         "material = \"jelly\"\n"
         "[[pins]]\nmin = [0.0, 0.8, 0.0]\nmax = [1.0, 1.0, 1.0]\n";
}

struct Result {
  std::vector<Real> values;  // x, v, F of every particle, in order
  long newton = 0, cg = 0;
};

template <int Dim>
Result Run(const Scene& scene, Integrator integrator, int threads, int steps, Real cfl) {
  omp_set_num_threads(threads);
  State<Dim> s = build_state<Dim>(scene);
  auto reference = make_reference<Dim>(scene);  // mms_axis: initial field, body force
  if (reference) reference->initialize(s);
  EXPECT_GE(static_cast<long>(s.particles.size()), kParallelMinimum);
  Parameters params = scene.transfer_params;
  auto stepper = make_stepper<Dim>(scene.transfer, scene.kernel, params);
  stepper->set_integrator(integrator);
  const Real dt = cfl * s.grid.geo.dx / s.max_wave_speed();
  Result r;
  for (int n = 0; n < steps; ++n) {
    const StepReport report = stepper->step(s, dt);
    EXPECT_LT(report.non_finite, 0);
    r.newton += stepper->implicit_stats()->newton;
    r.cg += stepper->implicit_stats()->cg;
  }
  const auto& P = s.particles;
  for (std::size_t p = 0; p < P.size(); ++p) {
    for (int a = 0; a < Dim; ++a) r.values.push_back(P.x[p][a]);
    for (int a = 0; a < Dim; ++a) r.values.push_back(P.v[p][a]);
    for (int a = 0; a < Dim * Dim; ++a) r.values.push_back(P.F[p].data()[a]);
  }
  omp_set_num_threads(2);
  return r;
}

template <int Dim>
void ExpectSameForOneAndTwoThreads(const Scene& scene, int steps, Real cfl) {
  for (Integrator integrator : {Integrator::backward_euler, Integrator::newmark}) {
    const Result one = Run<Dim>(scene, integrator, 1, steps, cfl);
    const Result two = Run<Dim>(scene, integrator, 2, steps, cfl);
    const std::string name =
        scene.name + " " + std::to_string(Dim) + "D " + std::string(integrator_name(integrator));
    EXPECT_GT(one.cg, steps) << name << ": the solve must iterate";
    EXPECT_EQ(one.newton, two.newton) << name;
    EXPECT_EQ(one.cg, two.cg) << name;
    ASSERT_EQ(one.values.size(), two.values.size()) << name;
    std::size_t differ = 0;
    for (std::size_t i = 0; i < one.values.size(); ++i) differ += one.values[i] != two.values[i];
    EXPECT_EQ(differ, 0u) << name << ": values that differ between 1 and 2 threads";
  }
}

TEST(ImplicitThreads, HangingBlock2D) {
  ExpectSameForOneAndTwoThreads<2>(testing::scene_from_toml(HangingBlock(2, 64)), 3, 5);
}

TEST(ImplicitThreads, HangingBlock3D) {
  ExpectSameForOneAndTwoThreads<3>(testing::scene_from_toml(HangingBlock(3, 16)), 1, 5);
}

TEST(ImplicitThreads, ManufacturedSolutionWithBodyForce2D) {
  const Scene scene =
      load_scene("mms_axis", {.dim = 2, .cells = 48, .transfer = std::string("flip")});
  ExpectSameForOneAndTwoThreads<2>(scene, 2, 4);
}

}  // namespace implicit_threads_test
}  // namespace mpmtb
