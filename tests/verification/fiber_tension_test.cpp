// The notched plate with a grain (scene fiber_tension; aniso-damage, AnisoMPM,
// Wolper et al. 2020), pulled apart along y, at 32 cells (a second each):
//   * isotropic damage: the crack runs across the load, along x (mode I:
//     the largest principal stress is sigma_yy), within 10 degrees;
//   * fibres along x (theta = 0): the crack runs along the fibres, which is
//     across the load too, within 10 degrees;
//   * fibres along the load (theta = 90): at the same pull, t = 0.12 s (the
//     grips 0.012 m apart, 3 % of the plate's height), the plate with fibres
//     across the load has torn while the one with fibres along it is still
//     whole: its planes of weakness carry no normal stress under a uniform
//     stretch (only where the slot and the grips hold back its contraction),
//     and the fibres' own strength sigma_crit (3e5 Pa) is far off (sigma_yy <=
//     (lambda + 2 mu + fiber_E) * strain = 1.1e6 * 0.03): the grain sets
//     where the plate is weak. (Pulled on, to t_end, it splits along its fibres
//     from the slot, as notched composites loaded along their fibres do.)
// The crack angle at theta = 30 and 60 degrees is issue 20's acceptance test, at
// 128 cells (tests/sweep/fiber_tension_sweep_test.cpp; cases/README.md).
#include <gtest/gtest.h>

#include <cmath>

#include "support/fiber_tension.hpp"

namespace mpmtb {
namespace fiber_tension_test {

using testing::aniso_crack;
using testing::isotropic_crack;

TEST(FiberTension, IsotropicCrackRunsAcrossTheLoad) {
  const auto c = isotropic_crack({.cells = 32});
  EXPECT_GT(c.damaged, 20) << "the plate must tear";
  EXPECT_GT(c.length, 0.3) << "the crack must run from the slot";
  EXPECT_LT(std::abs(c.angle_deg), 10);
}

TEST(FiberTension, CrackFollowsFibresAcrossTheLoad) {
  const auto c = aniso_crack(0, {.cells = 32});
  EXPECT_GT(c.damaged, 20) << "the plate must tear";
  EXPECT_GT(c.length, 0.3) << "the crack must run from the slot";
  EXPECT_LT(std::abs(c.angle_deg), 10);
}

TEST(FiberTension, FibresAlongTheLoadDoNotTear) {
  const auto across = aniso_crack(0, {.cells = 32, .t_end = 0.12});
  const auto along = aniso_crack(90, {.cells = 32, .t_end = 0.12});
  EXPECT_GT(across.damaged, 20);
  EXPECT_EQ(along.damaged, 0) << "fibres along the load: no plane of weakness is loaded";
  EXPECT_EQ(along.dissipated, 0);
}

}  // namespace fiber_tension_test
}  // namespace mpmtb
