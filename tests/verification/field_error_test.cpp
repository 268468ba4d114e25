// The bar's field error (error.field_rel, issue 22) against what the physics
// predicts, and the ranking it gives PIC and APIC.
//
// field_rel = max over output times t of ||u_h(t) - u(t)|| / ||U||, the
// V0-weighted L2 norms over the particles of the displacement error and of the
// exact mode's amplitude field U (cases/references/vibrating_bar.hpp).
// Bands (derived): a mode whose discrete frequency is omega_h = omega (1 - e),
// e = e_n (beta h)^2 the lumped-mass B-spline dispersion (bar_test.cpp), and
// whose amplitude has fallen by a fraction a, has at time t the error
// |sin(omega t) - (1 - a) sin(omega_h t)|. Near the last zero of sin(omega_h t)
// before the end this is |sin(omega t)| ~ omega e t, so over 4 periods
//   field_rel >= 2 pi 4 e  (sampled every 0.1 s of a 10 s period: 0.8 of it),
//   field_rel <= 2 pi 4 e + a,  a = 1 - sqrt(1 - energy_rel)
// (the displacement amplitude goes as the square root of the energy).
// PIC projects the particle velocities onto the grid every step and damps the
// mode (REFERENCE.md: PIC dissipation): it keeps the period but loses most of
// the amplitude, so a = 1 - sqrt(E_end / E0) is O(1) and its field error is
// O(1), while APIC's is the few per cent of the phase error: at least 10x apart
// (the ranking). A period-only metric ranks PIC as well as APIC.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "run.hpp"

namespace mpmtb {
namespace field_error_test {

nlohmann::json run_bar(const std::string& transfer, const std::string& kernel, int cells = 16) {
  Overrides o;
  o.transfer = transfer;
  o.kernel = kernel;
  o.cells = cells;
  const Scene scene = load_scene("bar", o);
  const auto dir = std::filesystem::temp_directory_path() /
                   ("mpmtb_field_" + transfer + kernel + std::to_string(cells));
  const RunOutcome r = run_scene(scene, dir);
  EXPECT_EQ(r.status, "ok") << r.reason;
  return r.summary["error"];
}

Real dispersion_coefficient(const std::string& kernel) {
  return kernel == "cubic" ? 1.0 / 6 : 1.0 / 8;
}

class FieldError : public ::testing::TestWithParam<std::string> {};

TEST_P(FieldError, RanksPicAtLeastTenTimesWorseThanApic) {
  const std::string kernel = GetParam();
  const auto pic = run_bar("pic", kernel);
  const auto apic = run_bar("apic", kernel);
  const Real pic_field = pic["field_rel"], apic_field = apic["field_rel"];
  EXPECT_GE(pic_field, 10 * apic_field) << "PIC " << pic_field << ", APIC " << apic_field;
  // PIC's damping is what the metric sees: its error is at least most of the
  // amplitude it lost (sampled at the output times, not at the peaks).
  const Real lost = 1 - std::sqrt(1 - static_cast<Real>(pic["energy_rel"]));
  EXPECT_GT(lost, 0.5) << "PIC should lose most of the bar's amplitude in 4 periods";
  EXPECT_GT(pic_field, 0.8 * lost);
  // The period alone cannot tell them apart: both within 2x of the dispersion.
  const Real theta = std::numbers::pi / 32;  // beta h at 16 cells
  const Real period = dispersion_coefficient(kernel) * theta * theta;
  EXPECT_LT(static_cast<Real>(pic["period_rel"]), 3 * period);
  EXPECT_LT(static_cast<Real>(apic["period_rel"]), 3 * period);
}

TEST_P(FieldError, ApicIsThePhaseErrorPlusTheAmplitudeLost) {
  const std::string kernel = GetParam();
  const Real theta = std::numbers::pi / 32;
  const Real phase = 2 * std::numbers::pi * 4 * dispersion_coefficient(kernel) * theta * theta;
  const auto apic = run_bar("apic", kernel);
  const Real field = apic["field_rel"];
  const Real lost = 1 - std::sqrt(1 - static_cast<Real>(apic["energy_rel"]));
  EXPECT_GT(field, 0.8 * phase);
  EXPECT_LT(field, phase + lost + 0.1 * phase);
  // Both terms shrink under refinement (the phase term by 4).
  const Real finer = run_bar("apic", kernel, 32)["field_rel"];
  EXPECT_LT(finer, field / 2);
}

INSTANTIATE_TEST_SUITE_P(BSplines, FieldError, ::testing::Values("quadratic", "cubic"));

}  // namespace field_error_test
}  // namespace mpmtb
