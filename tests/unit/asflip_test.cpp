// AFLIP and ASFLIP (Fei et al. 2021): with alpha = 0 both are APIC bit for bit;
// ASFLIP's beta moves positions only (velocities, C_p and F_p, and so the
// momentum the grid receives next, are AFLIP's); beta follows the separation
// criterion (beta_min for a compressed particle, log J < -1e-3).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/diagnostics.hpp"
#include "core/errors.hpp"
#include "core/registry.hpp"
#include "setup.hpp"
#include "support/compiled.hpp"
#include "support/gaps.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace asflip_test {

struct Body {
  State<2> s;
  std::unique_ptr<Stepper<2>> st;
};

Body free_body(const std::string& transfer, const std::vector<std::string>& set = {}) {
  const Scene scene =
      testing::scene_from_toml(testing::free_body_toml(2, transfer, "quadratic"), {.set = set});
  Body b{build_state<2>(scene), nullptr};
  Parameters params = scene.transfer_params;
  b.st = make_stepper<2>(transfer, "quadratic", params);
  return b;
}

Body after_steps(const std::string& transfer, int steps, const std::vector<std::string>& set = {}) {
  Body b = free_body(transfer, set);
  for (int i = 0; i < steps; ++i) b.st->step(b.s, 1e-3);
  return b;
}

TEST(Asflip, AlphaZeroIsApic) {
  const Body apic = after_steps("apic", 50);
  for (const char* transfer : {"aflip", "asflip"}) {
    const Body b = after_steps(transfer, 50, {std::string(transfer) + ".alpha=0"});
    // To round-off: AFLIP keeps v_old apart, APIC folds the force (support/gaps.hpp).
    constexpr Real tol = testing::kReorderedSumsTolerance;
    EXPECT_LT(testing::relative_gap(b.s.particles.x, apic.s.particles.x), tol) << transfer;
    EXPECT_LT(testing::relative_gap(b.s.particles.v, apic.s.particles.v), tol) << transfer;
    EXPECT_LT(testing::relative_gap(b.s.particles.C, apic.s.particles.C), tol) << transfer;
    const Body d = after_steps(transfer, 50);  // default alpha = 0.99
    EXPECT_NE(d.s.particles.v, apic.s.particles.v) << transfer;
  }
}

// One step of ASFLIP with beta = 1 everywhere against AFLIP, from the same
// state (the rotating body's v_p is not S S+ v_p, so the FLIP increment is not zero).
TEST(Asflip, BetaMovesOnlyPositions) {
  const Body aflip = after_steps("aflip", 1);
  Body asflip = after_steps("asflip", 1, {"asflip.beta_min=1"});
  EXPECT_EQ(asflip.s.particles.v, aflip.s.particles.v);
  EXPECT_EQ(asflip.s.particles.C, aflip.s.particles.C);
  EXPECT_EQ(asflip.s.particles.F, aflip.s.particles.F);
  EXPECT_NE(asflip.s.particles.x, aflip.s.particles.x);
  // The momentum the grid receives next: sum m_p v_p and the affine part
  // sum w m_p C_p (x_i - x_p) vanishes (sum_i w_ip (x_i - x_p) = 0), whatever x_p.
  Body a = after_steps("aflip", 1);
  for (Body* b : {&a, &asflip}) {
    b->st->particles_to_grid(b->s, 1e-3);
    b->st->update_grid(b->s, 0);
  }
  const Vec3 pa = measure_grid(a.s.grid).momentum, pb = measure_grid(asflip.s.grid).momentum;
  EXPECT_LE((pa - pb).norm(), 1e-13 * pa.norm());
}

// beta_p = beta_min for a compressed particle (log J < -1e-3), beta_max otherwise.
TEST(Asflip, BetaFollowsTheSeparationCriterion) {
  for (const Real J_scale : {Real(0.9), Real(1.1)}) {
    Body aflip = free_body("aflip"), asflip = free_body("asflip");
    for (Body* b : {&aflip, &asflip}) {
      for (auto& F : b->s.particles.F) F = J_scale * Mat<2>::Identity();
      b->st->step(b->s, 1e-3);  // v_p - v_PIC^n != 0 from the first step on
      b->st->step(b->s, 1e-3);
    }
    if (J_scale < 1) {
      EXPECT_EQ(asflip.s.particles.x, aflip.s.particles.x) << "compressed: beta_min = 0";
    } else {
      EXPECT_NE(asflip.s.particles.x, aflip.s.particles.x) << "stretched: beta_max = 1";
    }
  }
}

// Free fall: with one beta for all particles, sum m_p x_p advances by
// dt (sum m_i v_i + beta alpha sum m_p (v_p - v_PIC^n)) and the second sum is
// zero (P2G conserves momentum), so the centre of mass follows the discrete
// parabola. The criterion's mixed beta breaks that: with the linear hat some
// particles read as compressed (log J < -1e-3) and the centre of mass drifts.
TEST(Asflip, CentreOfMassFollowsMomentumOnlyForUniformBeta) {
  MPMTB_SKIP_UNLESS_COMPILED("asflip", "linear");
  auto drift = [](const std::vector<std::string>& set) {
    const Scene scene = testing::scene_from_toml(
        testing::free_body_toml(2, "asflip", "linear", "[physics]\ngravity = [-3.0, -9.81, 0.0]\n"),
        {.set = set});
    State<2> s = build_state<2>(scene);
    Parameters params = scene.transfer_params;
    auto st = make_stepper<2>("asflip", "linear", params);
    const Diagnostics d0 = measure(s, *st);
    const int n = 40;
    const Real dt = 1e-3, t = n * dt;
    for (int i = 0; i < n; ++i) st->step(s, dt);
    const Vec3 discrete = d0.center_of_mass + t * d0.center_of_mass_velocity +
                          Real(n * (n + 1)) / 2 * dt * dt * scene.gravity;
    return (measure(s, *st).center_of_mass - discrete).norm();
  };
  EXPECT_LE(drift({"asflip.beta_min=1"}), 1e-12);
  EXPECT_GT(drift({}), 1e-10);
}

TEST(Asflip, ParametersOutOfRangeAreRejected) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"aflip", "aflip.alpha=1.5"},
      {"asflip", "asflip.beta_max=-0.1"},
      {"asflip", "asflip.beta_min=0.6"},  // with beta_max = 0.5 below
  };
  for (const auto& [transfer, set] : bad) {
    std::vector<std::string> sets = {set};
    if (set == "asflip.beta_min=0.6") sets.push_back("asflip.beta_max=0.5");
    try {
      free_body(transfer, sets);
      ADD_FAILURE() << "accepted " << set;
    } catch (const InputError& e) {
      const std::string key = set.substr(0, set.find('='));
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

}  // namespace asflip_test
}  // namespace mpmtb
