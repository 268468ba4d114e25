// The pinned block (3D, 32,768 particles, damage) with the implicit
// integrators at CFL 5, through the ball's impact (t = 0.1 s; the ball reaches
// the block at 0.06 s): every step's Newton solve converges, the pinned
// particles do not move (their nodes are constraints of the solve), J stays
// positive, and the momentum balance closes: p(t) = p(0) + M g t + the pins'
// and the collider's impulses (each the constraint's reaction in the solve).
// About 3.5 minutes for both integrators on 2 cores: label sweep.
#include <gtest/gtest.h>

#include "core/diagnostics.hpp"
#include "core/registry.hpp"
#include "setup.hpp"
#include "support/pinned.hpp"

namespace mpmtb {
namespace implicit_pinned_block_test {

TEST(ImplicitPinnedBlock, DamageAtCfl5HoldsThePinsAndClosesTheMomentumBalance) {
  for (const Integrator integrator : {Integrator::backward_euler, Integrator::newmark}) {
    const Scene scene = load_scene("pinned_block", {.transfer = std::string("apic")});
    State<3> s = build_state<3>(scene);
    Parameters params = scene.transfer_params;
    auto stepper = make_stepper<3>(scene.transfer, scene.kernel, params);
    stepper->set_integrator(integrator);
    const Real dt = 5 * scene.dx() / s.max_wave_speed();
    const std::vector<Vec<3>> pinned_x = testing::pinned_positions(s.particles);
    ASSERT_EQ(pinned_x.size(), 64u * 8u);  // the top layer of the 64 x 64 x 8 lattice
    const Diagnostics d0 = measure(s, *stepper);
    while (s.time < 0.1) {
      const StepReport r = stepper->step(s, dt);
      ASSERT_LT(r.non_finite, 0) << integrator_name(integrator) << " step " << s.step;
      ASSERT_GT(r.J_min, 0) << integrator_name(integrator) << " step " << s.step;
      ASSERT_TRUE(stepper->implicit_stats()->converged)
          << integrator_name(integrator) << " step " << s.step;
    }
    EXPECT_EQ(testing::largest_pinned_displacement(s.particles, pinned_x), 0)
        << integrator_name(integrator);
    const Diagnostics d = measure(s, *stepper);
    const Vec3 expected =
        d0.momentum + d0.mass * s.time * to3<3>(s.gravity) + s.pin_impulse + s.collider_impulse;
    const Real scale = d0.mass * (9.81 * s.time + 1.5);  // gravity's impulse, the ball's speed
    EXPECT_LE((d.momentum - expected).norm(), 1e-6 * scale)
        << integrator_name(integrator) << ": p = " << d.momentum.transpose() << ", expected "
        << expected.transpose();
  }
}

}  // namespace implicit_pinned_block_test
}  // namespace mpmtb
