// Convergence orders on the manufactured solutions (shared/REFERENCE.md,
// "Manufactured solutions"; cases/scenes/mms_bar.toml, mms_axis.toml). The
// grid and the time step are refined together at the scenes' fixed CFL, and
// the observed order is log2(e_{k-1} / e_k) of the volume-weighted L2
// displacement error (max over one period).
//
// Bands.
// * B-splines (and the linear hat at small amplitude) are second order in
//   space; the symplectic Euler step is leapfrog, second order in time once
//   started half a step back (the references do that). So orders in
//   [1.7, 2.4] between successive levels; 1.7 is the published band of the issue.
// * PIC is first order: its G2P projection damps like a grid diffusion of
//   coefficient ~ h^2 / dt per step, and at fixed CFL there are ~ 1/h steps, so
//   its error is O(h) (orders in [0.5, 1.3], approaching 1 from below).
// * Large amplitude (G = 0.05: a displacement amplitude of 0.4 to 3.2 cells at 8 to 64):
//   with the linear hat the cell-crossing error does not fall under refinement
//   in updated-Lagrangian MPM (Bardenhagen & Kober 2004; Steffen, Kirby &
//   Berzins 2008, "Analysis and reduction of quadrature errors in the material
//   point method", IJNME 76); the B-splines' error falls.
#include <gtest/gtest.h>

#include <cstdio>
#include <tuple>

#include "support/convergence.hpp"

namespace mpmtb {
namespace mms_test {

using testing::error_table;
using testing::errors_over;
using testing::orders_of;

using testing::Combination;
using testing::combination_name;
using testing::kLarge;

// ---- 1D bar, small amplitude G = 1e-4 --------------------------------------
// Levels 8..64: at 8 cells the quadratic and cubic stencils (3 and 4 cells)
// already resolve sin(pi X) and the ratios are within a few % of 4; at 128
// cells the linear hat reaches its floor (the published plateau), so the
// quick levels stop at 64.
class SmallBar : public ::testing::TestWithParam<Combination> {};

TEST_P(SmallBar, ConvergesAtSecondOrder) {
  const auto& [transfer, kernel] = GetParam();
  const std::vector<int> levels = {8, 16, 32, 64};
  const auto e = errors_over("mms_bar", levels, {.transfer = transfer, .kernel = kernel});
  for (const Real order : orders_of(e)) {
    EXPECT_GE(order, 1.7) << error_table(levels, e);
    EXPECT_LE(order, 2.4) << error_table(levels, e);
  }
  std::printf("%s", error_table(levels, e).c_str());
}

INSTANTIATE_TEST_SUITE_P(AllKernels, SmallBar,
                         ::testing::Combine(::testing::Values("flip", "apic", "mls"),
                                            ::testing::Values("linear", "quadratic", "cubic",
                                                              "gimp")),
                         combination_name);

TEST(SmallBarPic, ConvergesAtFirstOrderOnly) {
  for (const std::string kernel : {"linear", "quadratic", "cubic"}) {
    const std::vector<int> levels = {16, 32, 64};
    const auto e = errors_over("mms_bar", levels, {.transfer = "pic", .kernel = kernel});
    for (const Real order : orders_of(e)) {
      EXPECT_GE(order, 0.5) << kernel << "\n" << error_table(levels, e);
      EXPECT_LE(order, 1.3) << kernel << "\n" << error_table(levels, e);
    }
  }
}

// ---- 1D bar, large amplitude G = 0.05 ---------------------------------------
class LargeBarLinear : public ::testing::TestWithParam<std::string> {};

// The published failure: the error does not keep falling; at 64 cells it is
// larger than at 32 (an unstable run counts as larger).
TEST_P(LargeBarLinear, ErrorDoesNotKeepFalling) {
  const std::vector<int> levels = {8, 16, 32, 64};
  const auto e =
      errors_over("mms_bar", levels, {.transfer = GetParam(), .kernel = "linear", .set = kLarge});
  EXPECT_TRUE(std::isinf(e[3]) || e[3] > e[2]) << error_table(levels, e);
  std::printf("%s", error_table(levels, e).c_str());
}

INSTANTIATE_TEST_SUITE_P(AllTransfers, LargeBarLinear,
                         ::testing::Values("pic", "flip", "apic", "mls"));

// The B-splines' error falls, at second order except with PIC (first order). Levels 8..32:
// beyond 64 cells the quadratic B-spline meets its own, smaller, crossing
// error floor (its gradient jumps in slope at the knots), which is reported by
// the sweep, not asserted here.
class LargeBarBSpline : public ::testing::TestWithParam<Combination> {};

TEST_P(LargeBarBSpline, ErrorFalls) {
  const auto& [transfer, kernel] = GetParam();
  const std::vector<int> levels = {8, 16, 32};
  const auto e =
      errors_over("mms_bar", levels, {.transfer = transfer, .kernel = kernel, .set = kLarge});
  // PIC: first order, approached from below (~0.5 between 8 and 16 cells).
  const Real lowest = transfer == "pic" ? 0.3 : 1.7;
  for (const Real order : orders_of(e)) EXPECT_GE(order, lowest) << error_table(levels, e);
  std::printf("%s", error_table(levels, e).c_str());
}

INSTANTIATE_TEST_SUITE_P(AllTransfers, LargeBarBSpline,
                         ::testing::Combine(::testing::Values("pic", "flip", "apic", "mls"),
                                            ::testing::Values("quadratic", "cubic")),
                         combination_name);

// The particle-domain kernels (issue 21), FLIP, levels 16..128 (a fraction of a
// second in 1D): uGIMP's fixed domains stall like the B-splines' (order below 1
// from 64 to 128 cells: measured -0.73), while cpGIMP's and CPDI1's domains
// follow F and their error keeps falling (measured orders 2.0; the band
// >= 1.5). The 2D case at these levels is the sweep's
// (tests/sweep/particle_domain_sweep_test.cpp).
class LargeBarParticleDomain : public ::testing::TestWithParam<std::string> {};

TEST_P(LargeBarParticleDomain, DeformedDomainsKeepConverging) {
  const std::string kernel = GetParam();
  const std::vector<int> levels = {16, 32, 64, 128};
  const auto e =
      errors_over("mms_bar", levels, {.transfer = "flip", .kernel = kernel, .set = kLarge});
  const auto orders = orders_of(e);
  if (kernel == "gimp") {
    EXPECT_LT(orders.back(), 1.0) << error_table(levels, e);
  } else {
    for (const Real order : orders) EXPECT_GE(order, 1.5) << error_table(levels, e);
  }
  std::printf("%s\n%s", kernel.c_str(), error_table(levels, e).c_str());
}

INSTANTIATE_TEST_SUITE_P(Kernels, LargeBarParticleDomain,
                         ::testing::Values("gimp", "cpgimp", "cpdi"));

// ---- 2D axis-aligned (Wallstedt & Guilkey 2008), A = 0.05 -------------------
// Levels 8..32 (displacement amplitude 0.4 to 1.6 cells): the B-splines' O(h^2)
// error dominates there. At 64 cells the quadratic B-spline's crossing floor
// starts to show (order ~1.5 with MLS), which is why the quick band stops at 32.
class AxisAligned2D : public ::testing::TestWithParam<Combination> {};

TEST_P(AxisAligned2D, ConvergesAtSecondOrder) {
  const auto& [transfer, kernel] = GetParam();
  const std::vector<int> levels = {8, 16, 32};
  const auto e =
      errors_over("mms_axis", levels, {.dim = 2, .transfer = transfer, .kernel = kernel});
  for (const Real order : orders_of(e)) {
    EXPECT_GE(order, 1.7) << error_table(levels, e);
    EXPECT_LE(order, 2.4) << error_table(levels, e);
  }
  std::printf("%s", error_table(levels, e).c_str());
}

INSTANTIATE_TEST_SUITE_P(BSplines, AxisAligned2D,
                         ::testing::Combine(::testing::Values("flip", "apic", "mls"),
                                            ::testing::Values("quadratic", "cubic")),
                         combination_name);

}  // namespace mms_test
}  // namespace mpmtb
