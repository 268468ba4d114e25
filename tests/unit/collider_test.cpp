// A driven ball through a pinned hanging sheet (the pinned block in 2D): the
// momentum balance, pinning, penetration and energy budget of colliders.
#include <gtest/gtest.h>

#include "core/diagnostics.hpp"
#include "setup.hpp"
#include "support/combinations.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace {

std::string sheet(const std::string& wall) {
  return "[scene]\nname = \"sheet\"\ndim = 2\n"
         "[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
         "[grid]\ncells = 32\nppc = 2\n[method]\ntransfer = \"mls\"\nkernel = \"quadratic\"\n"
         "[time]\nt_end = 1.0\ndt = 2e-4\n[physics]\ngravity = [0.0, -9.81, 0.0]\n"
         "[materials.m]\nmodel = \"neo-hookean\"\nE = 2e4\nnu = 0.3\ndensity = 1000.0\n"
         "[[bodies]]\nshape = \"box\"\nmin = [0.4375, 0.25, 0.0]\nmax = [0.5625, 0.75, 0.0]\n"
         "material = \"m\"\n"
         "[[pins]]\nmin = [0.0, 0.74, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
         "[[colliders]]\nshape = \"sphere\"\ncenter = [0.75, 0.45, 0.0]\nradius = 0.08\n"
         "velocity = [-1.0, 0.0, 0.0]\nwall = \"" +
         wall + "\"\n";
}

class Collider : public ::testing::TestWithParam<std::string> {};

TEST_P(Collider, MomentumBalancePinningPenetrationAndEnergy) {
  for (const auto& transfer : transfer_list()) {
    const Scene scene = testing::scene_from_toml(sheet(GetParam()), {.transfer = transfer.name});
    State<2> s = build_state<2>(scene);
    Parameters params = scene.transfer_params;
    auto st = make_stepper<2>(transfer.name, "quadratic", params);
    const Diagnostics d0 = measure(s, *st);
    const auto x0 = s.particles.x;
    Real max_penetration = 0;
    for (int i = 0; i < 1000; ++i) {  // 0.2 s: the ball crosses the sheet
      st->step(s, 2e-4);
      max_penetration =
          std::max(max_penetration, s.colliders.max_penetration(s.particles.x, s.time));
    }
    const Diagnostics d = measure(s, *st);
    const std::string what = transfer.name + " " + GetParam();
    // Momentum: material change = gravity impulse + collider impulse + pin reaction.
    const Vec3 expected =
        d0.momentum + d0.mass * s.time * to3<2>(s.gravity) + s.collider_impulse + s.pin_impulse;
    EXPECT_LE((d.momentum - expected).norm(), 1e-10 * s.collider_impulse.norm()) << what;
    EXPECT_GT(s.collider_impulse.norm(), 0.1) << what << ": the ball must hit the sheet";
    for (std::size_t p = 0; p < x0.size(); ++p) {
      if (s.particles.pinned[p]) {
        ASSERT_EQ(s.particles.x[p], x0[p]) << what;
      }
    }
    // Grid-node collisions: particles may sink into the ball by less than a cell.
    EXPECT_LT(max_penetration, 0.5 * s.grid.geo.dx) << what;
    // The budget never gains more than the work done: the collision and the
    // transfers may only lose energy (a sticky impact is inelastic).
    const Real budget = d.total - s.collider_work - d0.total;
    EXPECT_LT(budget, 1e-3 * std::abs(s.collider_work)) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(Walls, Collider, ::testing::Values("sticky", "slip", "separate"));

}  // namespace
}  // namespace mpmtb
