// XPIC(m) (Hammerquist & Nairn 2017): XPIC(1) is PIC, and on the colliding
// disks (Sulsky et al. 1994) the energy kept grows with m toward FLIP's, the
// paper's trend (XPIC(m) moves from PIC's dissipation toward
// FLIP as m grows). The disks run to their scene's end, t = 3.5 s (3500 steps
// of ~800 particles; about 8 s in Release for the five runs together).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/diagnostics.hpp"
#include "core/errors.hpp"
#include "core/registry.hpp"
#include "setup.hpp"
#include "support/gaps.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace xpic_test {

struct Outcome {
  std::vector<Vec<2>> x, v;
  Real kept = 0;  // (kinetic + strain) at the end over at the start
};

Outcome run_2d(const Scene& scene, int steps, Real dt) {
  State<2> s = build_state<2>(scene);
  Parameters params = scene.transfer_params;
  auto st = make_stepper<2>(scene.transfer, scene.kernel, params);
  const Diagnostics d0 = measure(s, *st);
  for (int i = 0; i < steps; ++i) {
    // Stop at the first non-finite or escaped particle (a broken scheme), so
    // the test fails on NaN instead of binning NaN positions.
    const StepReport r = st->step(s, dt);
    if (r.non_finite >= 0 || r.outside >= 0) {
      return {s.particles.x, s.particles.v, std::numeric_limits<Real>::quiet_NaN()};
    }
  }
  const Diagnostics d1 = measure(s, *st);
  return {s.particles.x, s.particles.v, (d1.kinetic + d1.strain) / (d0.kinetic + d0.strain)};
}

Outcome free_body(const std::string& transfer, const std::vector<std::string>& set = {}) {
  const Scene scene =
      testing::scene_from_toml(testing::free_body_toml(2, transfer, "quadratic"), {.set = set});
  return run_2d(scene, 50, 1e-3);
}

// v* = sum_k (-1)^{k+1} C(1,k) S+ P^{k-1} v_p = S+ v_p = v^n: the update is S v^{n+1}.
TEST(Xpic, OrderOneIsPic) {
  const Outcome pic = free_body("pic"), xpic1 = free_body("xpic", {"xpic.m=1"});
  // To round-off: XPIC keeps v_old apart, PIC folds the force (support/gaps.hpp).
  EXPECT_LT(testing::relative_gap(xpic1.x, pic.x), testing::kReorderedSumsTolerance);
  EXPECT_LT(testing::relative_gap(xpic1.v, pic.v), testing::kReorderedSumsTolerance);
  const Outcome xpic2 = free_body("xpic", {"xpic.m=2"});
  EXPECT_NE(xpic2.v, pic.v) << "m = 2 must keep some of the particle velocity";
}

TEST(Xpic, EnergyKeptGrowsWithOrderTowardFlip) {
  auto disks = [](const std::string& transfer, const std::vector<std::string>& set) {
    const Scene scene =
        load_scene("disks", {.transfer = transfer, .kernel = "quadratic", .set = set});
    return run_2d(scene, static_cast<int>(std::lround(scene.t_end / *scene.dt)), *scene.dt).kept;
  };
  const Real flip = disks("flip", {}), pic = disks("pic", {});
  Real previous = pic;
  for (int m : {1, 2, 4, 8}) {
    const Real kept = disks("xpic", {"xpic.m=" + std::to_string(m)});
    if (m == 1) {
      // The whole collision (thousands of steps) from sums in another order.
      EXPECT_NEAR(kept, pic, 1e-9 * pic);
    } else {
      EXPECT_GT(kept, previous) << "m = " << m;
    }
    EXPECT_LE(kept, flip) << "m = " << m;
    previous = kept;
  }
  // PIC loses nearly all of it; XPIC(8) keeps most of what FLIP keeps.
  EXPECT_LT(pic, 0.1 * flip);
  EXPECT_GT(previous, 0.75 * flip);
}

TEST(Xpic, OrderOutOfRangeIsRejected) {
  for (const char* m : {"0", "2.5", "21"}) {
    try {
      free_body("xpic", {std::string("xpic.m=") + m});
      ADD_FAILURE() << "accepted xpic.m = " << m;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("xpic.m"), std::string::npos) << e.what();
    }
  }
}

}  // namespace xpic_test
}  // namespace mpmtb
