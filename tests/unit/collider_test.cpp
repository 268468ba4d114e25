// A driven ball through a pinned hanging sheet (the pinned block in 2D): the
// momentum balance, pinning, penetration and energy budget of colliders.
#include <gtest/gtest.h>

#include "core/diagnostics.hpp"
#include "setup.hpp"
#include "support/combinations.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace collider_test {

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

}  // namespace collider_test
}  // namespace mpmtb

namespace mpmtb {
namespace collider_test {

// With the damage model, the sheet tears where the ball passes. The ball also
// drags the sheet against its pinned edge, which may tear there too; damage
// anywhere else would be spurious, and most of it must be on the path.
TEST(PinnedSheet, DamageDevelopsAlongTheBallsPath) {
  std::string toml = sheet("sticky");
  toml.replace(toml.find("model = \"neo-hookean\""), 21, "model = \"damage\"\nsigma_crit = 3e3");
  const Scene scene = testing::scene_from_toml(toml);
  State<2> s = build_state<2>(scene);
  Parameters params;
  auto st = make_stepper<2>("mls", "quadratic", params);
  for (int i = 0; i < 1000; ++i) st->step(s, 2e-4);
  const SphereCollider& ball = scene.colliders[0];
  const int slot = 0;  // "damage" is the first state variable
  int on_path = 0, at_support = 0;
  const Real support = scene.pins[0].min[1];
  for (std::size_t p = 0; p < s.particles.size(); ++p) {
    if (s.particles.state_of(p)[slot] < 0.5) continue;
    // The ball moves along -x at height start.y: distance from that line.
    const Real off_path = std::abs(s.particles.x[p][1] - ball.start[1]);
    if (off_path < ball.radius + 3 * s.grid.geo.dx) {
      ++on_path;
    } else {
      ++at_support;
      EXPECT_GT(s.particles.x[p][1], support - 0.15) << "damage away from the path and the support";
    }
  }
  EXPECT_GT(on_path, 2 * at_support) << "the ball must tear the sheet along its path";
  EXPECT_LT(on_path + at_support, static_cast<int>(s.particles.size()) / 2)
      << "damage must stay local";
}

}  // namespace collider_test
}  // namespace mpmtb
