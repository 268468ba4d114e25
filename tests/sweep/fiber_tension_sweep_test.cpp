// The long fiber_tension studies (label `sweep`; minutes on 2 cores):
// * mesh objectivity of the regularised damage: with the length scale fixed in
//   metres (l0 = 0.04 m, 2.6 cells at 64 and 5.1 at 128), the damaged band's
//   width and the dissipated energy change by less than 20 % from dx = 1/64 to
//   dx/2, for `damage` and for `aniso-damage` (fibres along x), and the crack
//   stays across the load at both;
// * the crack angle against the fibre angle, issue 20's acceptance test: within
//   10 degrees of theta for theta = 0, 30, 60, at 128 cells (l0 = 0.02 m, 2.6
//   cells), with the structural tensor in the driver and in the regularisation
//   (div(A_l grad d), core/nonlocal.hpp), and across the load (within 10
//   degrees of 0) for alpha = 0 and fiber_E = 0 (`damage`) with the fibres at
//   60 degrees. Why both tensors are needed, and why the grips must not
//   bounce: cases/README.md.
// `ctest -L sweep -R FiberTension -V` prints the measured tables.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "support/fiber_tension.hpp"

namespace mpmtb {
namespace fiber_tension_sweep_test {

using testing::aniso_crack;
using testing::Crack;
using testing::isotropic_crack;

void expect_objective(const char* model, const Crack& coarse, const Crack& fine) {
  std::printf(
      "%-13s dx = 1/64: band %.4f m, dissipated %.4g J/m; dx = 1/128: band %.4f m, "
      "dissipated %.4g J/m\n",
      model, coarse.band_width, coarse.dissipated, fine.band_width, fine.dissipated);
  EXPECT_LT(std::abs(fine.band_width / coarse.band_width - 1), 0.2) << model;
  EXPECT_LT(std::abs(fine.dissipated / coarse.dissipated - 1), 0.2) << model;
  for (const Crack& c : {coarse, fine}) {
    EXPECT_GT(c.damaged, 20) << model << ": the plate must tear";
    EXPECT_LT(std::abs(c.angle_deg), 10) << model;
  }
}

// At t = 0.2 s: the band (d >= 1/2) has crossed the plate at both resolutions
// and grows no more; later the separated halves, still pulled and ringing, gather
// damage below 1/2 (aniso-damage: +1.8 J/m at 64 cells, +3.4 at 128 by 0.3 s),
// which is not the band's energy.
TEST(FiberTensionSweep, RegularisedDamageIsMeshObjective) {
  const std::vector<std::string> l0 = {"materials.plate.l0=0.04"};
  const double t_end = 0.2;
  expect_objective("damage", isotropic_crack({.cells = 64, .t_end = t_end, .set = l0}),
                   isotropic_crack({.cells = 128, .t_end = t_end, .set = l0}));
  expect_objective("aniso-damage", aniso_crack(0, {.cells = 64, .t_end = t_end, .set = l0}),
                   aniso_crack(0, {.cells = 128, .t_end = t_end, .set = l0}));
}

TEST(FiberTensionSweep, CrackFollowsTheFibres) {
  for (double theta : {0.0, 30.0, 60.0}) {
    const Crack c = aniso_crack(theta, {.cells = 128});
    std::printf("theta = %4.1f: crack at %6.2f degrees, %.0f damaged particles\n", theta,
                c.angle_deg, c.damaged);
    EXPECT_GT(c.damaged, 20) << "theta = " << theta << ": the plate must tear";
    EXPECT_GT(c.length, 0.3) << "theta = " << theta << ": the crack must run from the slot";
    EXPECT_LT(std::abs(c.angle_deg - theta), 10) << "theta = " << theta;
  }
}

// The structural tensor in the driver only (alpha_l = 0): the scalar damage
// forgets the plane it failed on, and the crack from the slot turns only a
// little towards fibres at 30 degrees (7 at 128 cells), while cracks from the
// grips' corners run parallel to it, offset: the `crack` reference must count
// only the damage joined to the slot (its principal axis over all of them was
// 27 degrees, a false pass of the test above).
TEST(FiberTensionSweep, WithTheTensorInTheDriverOnlyTheCrackTurnsLittle) {
  const Crack c = aniso_crack(30, {.cells = 128, .set = {"materials.plate.alpha_l=0"}});
  std::printf("theta = 30, driver only: crack at %6.2f degrees, %.0f damaged\n", c.angle_deg,
              c.damaged);
  EXPECT_GT(c.damaged, 20) << "the plate must tear";
  EXPECT_LT(std::abs(c.angle_deg), 15) << "the crack from the slot stays near the load's normal";
}

// alpha = 0 and fiber_E = 0 (the `damage` model bit for bit), the fibres at 60
// degrees and the strength the grained plate has across them: no plane of
// weakness, the crack runs across the load (mode I). (With the fibres' stiffness
// kept, fiber_E = 10 E, the elastic anisotropy alone tilts it: -5.1 degrees at
// 64 cells, -6.1 at 128; cases/README.md.)
TEST(FiberTensionSweep, WithoutTheStructuralTensorTheCrackRunsAcrossTheLoad) {
  const Crack c = aniso_crack(60, {.cells = 128,
                                   .set = {"materials.plate.alpha=0", "materials.plate.fiber_E=0",
                                           "materials.plate.sigma_crit=2.48e3"}});
  std::printf("alpha = 0, fiber_E = 0, fibres at 60: crack at %6.2f degrees, %.0f damaged\n",
              c.angle_deg, c.damaged);
  EXPECT_GT(c.damaged, 20) << "the plate must tear";
  EXPECT_GT(c.length, 0.3) << "the crack must run from the slot";
  EXPECT_LT(std::abs(c.angle_deg), 10);
}

}  // namespace fiber_tension_sweep_test
}  // namespace mpmtb
