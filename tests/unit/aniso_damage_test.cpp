// Anisotropic damage (methods/models/aniso_damage.hpp; AnisoMPM, Wolper et al.
// 2020) in 2 and 3D: P = dpsi/dF by finite differences with fibres and damage,
// the fibre reinforcement's exact uniaxial stress, the structural tensor's
// onset stress across and along the fibres derived here, objectivity and
// advection of the fibres, the energy budget, and alpha = 0 = `damage` bit for
// bit, per particle and through the step on the pinned block.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/registry.hpp"
#include "models/aniso_damage.hpp"
#include "models/damage.hpp"
#include "setup.hpp"
#include "support/finite_difference.hpp"
#include "support/random_matrices.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace aniso_damage_test {

using testing::FiniteDifferenceP;
using testing::RandomMatrix;
using testing::RandomRotation;

constexpr Real kE = 250, kNu = 0.3, kRho = 7, kSigmaCrit = 20, kAlpha = 3, kFiberE = 400;

std::map<std::string, Real> Values(Real alpha = kAlpha, Real fiber_E = kFiberE, Real nu = kNu) {
  return {{"E", kE},        {"nu", nu}, {"density", kRho},   {"sigma_crit", kSigmaCrit},
          {"alpha", alpha}, {"l0", 0},  {"fiber_E", fiber_E}};
}

template <int Dim>
AnisoDamage<Dim> Make(const std::map<std::string, Real>& values = Values()) {
  Parameters p("materials.test", values);
  AnisoDamage<Dim> m(p);
  p.reject_unknown();
  return m;
}

template <int Dim>
Damage<Dim> MakeIsotropic() {
  Parameters p("materials.test",
               {{"E", kE}, {"nu", kNu}, {"density", kRho}, {"sigma_crit", kSigmaCrit}, {"l0", 0}});
  return Damage<Dim>(p);
}

// A fresh state with the given fibre families.
template <int Dim>
std::vector<Real> FreshState(const AnisoDamage<Dim>& m, std::vector<Vec<Dim>> fibers) {
  std::vector<Real> q(m.state_size());
  m.initial_state(q.data());
  m.set_fibers(q.data(), fibers);
  return q;
}

template <int Dim>
Vec<Dim> RandomUnit(std::mt19937& gen) {
  std::normal_distribution<Real> n;
  Vec<Dim> v;
  for (int i = 0; i < Dim; ++i) v[i] = n(gen);
  return v.normalized();
}

// F with J and every fibre stretch away from 1, so that the differences do not
// straddle the tension/compression switches (both C^1).
template <int Dim>
Mat<Dim> AwayFromSwitches(std::mt19937& gen, const std::vector<Vec<Dim>>& fibers) {
  for (;;) {
    const Mat<Dim> F = Mat<Dim>::Identity() + 0.3 * RandomMatrix<Dim>(gen);
    bool ok = F.determinant() >= 0.2 && std::abs(F.determinant() - 1) > 1e-3;
    for (const auto& a : fibers) ok = ok && std::abs((F * a).norm() - 1) > 1e-3;
    if (ok) return F;
  }
}

template <class T>
class AnisoDamageTest : public ::testing::Test {};
using Dims = ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(AnisoDamageTest, Dims);

TYPED_TEST(AnisoDamageTest, StressIsEnergyGradientWithFibersAndDamage) {
  constexpr int Dim = TypeParam::value;
  const auto m = Make<Dim>();
  std::mt19937 gen(7);
  for (int families = 1; families <= 2; ++families) {
    for (int s = 0; s < 20; ++s) {
      std::vector<Vec<Dim>> fibers;
      for (int f = 0; f < families; ++f) fibers.push_back(RandomUnit<Dim>(gen));
      auto q = FreshState<Dim>(m, fibers);
      q[AnisoDamage<Dim>::kDamage] = (s % 4) * 0.3;  // 0, 0.3, 0.6, 0.9
      const Mat<Dim> F = AwayFromSwitches<Dim>(gen, fibers);
      const Mat<Dim> P = m.P(F, q.data()), P_fd = FiniteDifferenceP<Dim>(m, F, q.data());
      EXPECT_LT((P - P_fd).norm(), 1e-6 * P.norm() + 1e-9 * kE) << "F =\n" << F;
      EXPECT_LT((m.tau(F, q.data()) - P * F.transpose()).norm(), 1e-12 * (P.norm() + kE));
    }
  }
}

// Stretch lambda along the fibre, the other directions held: the fibre adds
// fiber_E (lambda - 1) to P_aa (psi_f = fiber_E/2 (lambda - 1)^2, d/dlambda),
// degraded by g(d); nothing for compression along it or stretch across it.
TYPED_TEST(AnisoDamageTest, FiberReinforcementIsExactInUniaxialStretch) {
  constexpr int Dim = TypeParam::value;
  const auto m = Make<Dim>();
  const auto iso = MakeIsotropic<Dim>();
  const Vec<Dim> a = Vec<Dim>::Unit(0);
  auto q = FreshState<Dim>(m, {a});
  for (Real d : {0.0, 0.5}) {
    q[0] = d;
    const Real g = (1 - d) * (1 - d) * (1 - 1e-6) + 1e-6;
    for (Real stretch : {0.8, 1.2, 1.5}) {
      Mat<Dim> F = Mat<Dim>::Identity();
      F(0, 0) = stretch;
      const Mat<Dim> extra = m.P(F, q.data()) - iso.P(F, q.data());
      const Real expected = stretch > 1 ? g * kFiberE * (stretch - 1) : 0;
      EXPECT_NEAR(extra(0, 0), expected, 1e-12 * kFiberE) << "stretch " << stretch;
      EXPECT_LT((extra - expected * a * a.transpose()).norm(), 1e-12 * kFiberE);
      F = Mat<Dim>::Identity();
      F(1, 1) = stretch;  // across the fibre: its length is unchanged
      EXPECT_LT((m.P(F, q.data()) - iso.P(F, q.data())).norm(), 1e-12 * kE);
    }
  }
}

// With nu = 0 (lambda = 0) and no fibre stiffness, a stretch s along n is a
// uniaxial stress sigma = mu (s^2 - 1) / s n n^T. With A = I + alpha (I - a a^T),
// A n = (1 + alpha) n - alpha (a.n) a, so the largest principal value of
// A sigma A is sigma_nn |A n|^2 = sigma_nn ((1 + alpha)^2 - alpha (2 + alpha)
// (a.n)^2), a the current fibre F a0 / |F a0|: damage starts where this
// reaches sigma_crit, (1 + alpha)^2 sooner across the fibres than along them.
// The onset stretch is found here by bisection on that formula.
TYPED_TEST(AnisoDamageTest, OnsetStressFollowsTheStructuralTensor) {
  constexpr int Dim = TypeParam::value;
  const auto m = Make<Dim>(Values(kAlpha, 0, 0));
  const Real mu = kE / 2;
  for (Real angle_deg : {0.0, 30.0, 60.0, 90.0}) {
    const Real t = angle_deg * std::numbers::pi / 180;
    Vec<Dim> a0 = Vec<Dim>::Zero(), n = Vec<Dim>::Zero();
    a0[0] = 1;
    n[0] = std::cos(t), n[1] = std::sin(t);
    const auto stretch = [&](Real s) {
      return Mat<Dim>(Mat<Dim>::Identity() + (s - 1) * n * n.transpose());
    };
    const auto excess = [&](Real s) {
      const Vec<Dim> a = (stretch(s) * a0).normalized();
      const Real an = a.dot(n);
      const Real weight = (1 + kAlpha) * (1 + kAlpha) - kAlpha * (2 + kAlpha) * an * an;
      return mu * (s * s - 1) / s * weight - kSigmaCrit;
    };
    Real lo = 1, hi = 3;
    for (int i = 0; i < 200; ++i) (excess((lo + hi) / 2) > 0 ? hi : lo) = (lo + hi) / 2;
    const auto damages = [&](Real s) {
      auto q = FreshState<Dim>(m, {a0});
      Mat<Dim> F = stretch(s);
      m.project(F, q.data(), 1e-3);
      return q[0] > 0;
    };
    EXPECT_FALSE(damages(lo * (1 - 1e-9))) << angle_deg << " degrees";
    EXPECT_TRUE(damages(lo * (1 + 1e-9))) << angle_deg << " degrees";
  }
}

// psi(R F) = psi(F), P(R F) = R P(F), and the damage driven by R F equals that
// by F; the fibre written by the return map is R F a0 / |F a0|, unit length.
TYPED_TEST(AnisoDamageTest, ObjectiveAndFibersFollowF) {
  constexpr int Dim = TypeParam::value;
  const auto m = Make<Dim>(Values(kAlpha, kFiberE));
  std::mt19937 gen(11);
  for (int s = 0; s < 20; ++s) {
    const std::vector<Vec<Dim>> fibers = {RandomUnit<Dim>(gen), RandomUnit<Dim>(gen)};
    auto q = FreshState<Dim>(m, fibers), q_rot = q;
    const Mat<Dim> F = Mat<Dim>::Identity() + 0.4 * RandomMatrix<Dim>(gen);
    if (F.determinant() < 0.3) continue;
    const Mat<Dim> R = RandomRotation<Dim>(gen);
    const Real psi = m.psi(F, q.data());
    EXPECT_NEAR(m.psi(R * F, q.data()), psi, 1e-12 * (std::abs(psi) + kE));
    EXPECT_LT((m.P(R * F, q.data()) - R * m.P(F, q.data())).norm(), 1e-11 * kE);
    Mat<Dim> F1 = F, F2 = R * F;
    m.project(F1, q.data(), 1e-3);
    m.project(F2, q_rot.data(), 1e-3);
    EXPECT_NEAR(q_rot[0], q[0], 1e-12) << "damage differs under rotation";
    for (int f = 0; f < 2; ++f) {
      const Vec<Dim> a = AnisoDamage<Dim>::current_fiber(q_rot.data(), f);
      EXPECT_NEAR(a.norm(), 1, 1e-14);
      EXPECT_LT((a - R * (F * fibers[f]).normalized()).norm(), 1e-13);
    }
  }
}

// Strain energy lost by the damage at fixed F reappears as dissipated energy.
TYPED_TEST(AnisoDamageTest, ReturnMapKeepsTheEnergyBudget) {
  constexpr int Dim = TypeParam::value;
  const auto m = Make<Dim>();
  std::mt19937 gen(5);
  int damaged = 0;
  for (int s = 0; s < 30; ++s) {
    auto q = FreshState<Dim>(m, {RandomUnit<Dim>(gen)});
    Mat<Dim> F = Mat<Dim>::Identity() + 0.6 * RandomMatrix<Dim>(gen);
    if (F.determinant() < 0.2) continue;
    for (int k = 0; k < 3; ++k) {
      const Real before = m.psi(F, q.data()) + q[1];
      m.project(F, q.data(), 1e-3);
      EXPECT_NEAR(m.psi(F, q.data()) + q[1], before, 1e-12 * (before + kE));
    }
    damaged += q[0] > 0;
  }
  EXPECT_GT(damaged, 5) << "the random stretches must damage some particles";
}

// alpha = 0 and fiber_E = 0: the `damage` model's energy, stress, state update
// and dissipation, bit for bit, whatever the fibre.
TYPED_TEST(AnisoDamageTest, IsotropicLimitIsDamageBitForBit) {
  constexpr int Dim = TypeParam::value;
  const auto m = Make<Dim>(Values(0, 0));
  const auto iso = MakeIsotropic<Dim>();
  std::mt19937 gen(3);
  for (int s = 0; s < 50; ++s) {
    auto q = FreshState<Dim>(m, {RandomUnit<Dim>(gen)});
    std::vector<Real> qi(iso.state_size());
    iso.initial_state(qi.data());
    Mat<Dim> F = Mat<Dim>::Identity() + 0.6 * RandomMatrix<Dim>(gen);
    if (F.determinant() < 0.2) continue;
    Mat<Dim> Fi = F;
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(m.psi(F, q.data()), iso.psi(Fi, qi.data()));
      EXPECT_EQ(m.P(F, q.data()), iso.P(Fi, qi.data()));
      EXPECT_EQ(m.tau(F, q.data()), iso.tau(Fi, qi.data()));
      m.project(F, q.data(), 1e-3);
      iso.project(Fi, qi.data(), 1e-3);
      for (int i = 0; i < iso.state_size(); ++i) EXPECT_EQ(q[i], qi[i]);
    }
  }
}

TEST(AnisoDamageParameters, InvalidValuesAreRejectedByName) {
  for (const auto& [key, value] : std::map<std::string, Real>{{"alpha", -1}, {"fiber_E", -1}}) {
    auto values = Values();
    values[key] = value;
    Parameters p("materials.test", values);
    try {
      AnisoDamage<2> m(p);
      ADD_FAILURE() << key << " = " << value << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
  const auto m = Make<3>();
  EXPECT_EQ(m.fiber_families(), 2);
  EXPECT_EQ(static_cast<int>(m.state_names().size()), m.state_size());
  EXPECT_NEAR(m.wave_speed(),
              std::sqrt((kE * kNu / ((1 + kNu) * (1 - 2 * kNu)) + kE / (1 + kNu) + kFiberE) / kRho),
              1e-12);
}

// Through the step: the pinned block (cells 16, sigma_crit lowered so that the
// top tears under its own swing within the steps run) with `damage` and with
// `aniso-damage` at alpha = 0: positions, velocities, F and damage identical.
TEST(AnisoDamageStep, AlphaZeroIsDamageOnThePinnedBlock) {
  const std::vector<std::string> common = {"materials.block.sigma_crit=3e3"};
  auto iso_set = common;
  auto aniso_set = common;
  aniso_set.push_back("materials.block.model=\"aniso-damage\"");
  aniso_set.push_back("bodies.0.fiber=[0.6,0.8,0.0]");
  State<3> a = build_state<3>(load_scene("pinned_block", {.cells = 16, .set = iso_set}));
  State<3> b = build_state<3>(load_scene("pinned_block", {.cells = 16, .set = aniso_set}));
  ASSERT_EQ(b.materials[0]->name(), "aniso-damage");
  Parameters params;
  auto sa = make_stepper<3>("mls", "quadratic", params);
  auto sb = make_stepper<3>("mls", "quadratic", params);
  const Real dt = 1e-3;
  for (int i = 0; i < 60; ++i) {
    sa->step(a, dt);
    sb->step(b, dt);
  }
  int damaged = 0;
  for (std::size_t p = 0; p < a.particles.size(); ++p) {
    ASSERT_EQ(a.particles.x[p], b.particles.x[p]) << "particle " << p;
    ASSERT_EQ(a.particles.v[p], b.particles.v[p]) << "particle " << p;
    ASSERT_EQ(a.particles.F[p], b.particles.F[p]) << "particle " << p;
    for (int k = 0; k < 4; ++k)
      ASSERT_EQ(a.particles.state_of(p)[k], b.particles.state_of(p)[k]) << "particle " << p;
    damaged += a.particles.state_of(p)[0] > 0;
  }
  EXPECT_GT(damaged, 0) << "the steps must exercise the damage update";
}

// A square spinning at omega = 1 rad/s about z (APIC keeps the spin). After
// t = 1 s every particle's fibre must be its initial one turned by the body's
// rotation, the best-fit rotation of the particle positions about their centre
// (angle atan2(sum r0 x r, sum r0 . r)), up to the small elastic strain of the
// spin, rho omega^2 r^2 / E ~ 2e-3, and stay unit length. (The spin itself is
// a little slower than omega: the initial P2G carries no affine part.)
std::string spinning_toml(const std::string& fiber) {
  return "[scene]\nname = \"spin\"\ndim = 2\n[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, "
         "1.0]\n"
         "[grid]\ncells = 32\nppc = 2\n[method]\ntransfer = \"apic\"\nkernel = \"quadratic\"\n"
         "[time]\nt_end = 1.0\ndt = 1e-3\n"
         "[materials.wood]\nmodel = \"aniso-damage\"\nE = 2e4\nnu = 0.3\ndensity = 1000.0\n"
         "sigma_crit = 1e6\nalpha = 3.0\nfiber_E = 2e4\n"
         "[[bodies]]\nshape = \"box\"\nmin = [0.35, 0.35, 0.0]\nmax = [0.65, 0.65, 0.0]\n"
         "material = \"wood\"\nangular_velocity = [0.0, 0.0, 1.0]\nfiber = " +
         fiber + "\n";
}

TEST(AnisoDamageStep, FibersRotateWithARigidlyRotatingBody) {
  State<2> s = build_state<2>(testing::scene_from_toml(spinning_toml("[0.6, 0.8, 0.0]")));
  const auto centre = [](const State<2>& st) {
    Vec<2> c = Vec<2>::Zero();
    for (const auto& x : st.particles.x) c += x;
    return Vec<2>(c / static_cast<Real>(st.particles.size()));
  };
  const std::vector<Vec<2>> x0 = s.particles.x;
  const Vec<2> c0 = centre(s);
  Parameters params;
  auto st = make_stepper<2>("apic", "quadratic", params);
  for (int i = 0; i < 1000; ++i) st->step(s, 1e-3);
  const Vec<2> c1 = centre(s);
  Real cross = 0, dot = 0;
  for (std::size_t p = 0; p < x0.size(); ++p) {
    const Vec<2> r0 = x0[p] - c0, r = s.particles.x[p] - c1;
    cross += r0[0] * r[1] - r0[1] * r[0];
    dot += r0.dot(r);
  }
  const Real turned = std::atan2(cross, dot);
  EXPECT_GT(turned, 0.9) << "the body must have turned by about omega t = 1 rad";
  const Vec<2> expected = Eigen::Rotation2D<Real>(turned) * Vec<2>(0.6, 0.8);
  Real worst = 0;
  for (std::size_t p = 0; p < s.particles.size(); ++p) {
    const Vec<2> a = AnisoDamage<2>::current_fiber(s.particles.state_of(p), 0);
    ASSERT_NEAR(a.norm(), 1, 1e-12) << "particle " << p;
    worst = std::max(worst, (a - expected).norm());
  }
  EXPECT_LT(worst, 5e-3) << "fibres must turn with the body (turned " << turned << " rad)";
}

// Bad fibre input names the field and what is allowed.
TEST(AnisoDamageScene, BadFiberInputIsRejectedByName) {
  const auto expect_error = [](const std::string& toml, const std::vector<std::string>& words) {
    try {
      testing::scene_from_toml(toml);
      ADD_FAILURE() << "accepted:\n" << toml;
    } catch (const InputError& e) {
      for (const auto& w : words)
        EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what() << " lacks " << w;
    }
  };
  expect_error(spinning_toml("[0.0, 0.0, 0.0]"), {"bodies[0].fiber", "nonzero"});
  expect_error(spinning_toml("[0.6, 0.8, 0.1]"), {"bodies[0].fiber", "must be 0 in 2D"});
  std::string no_fiber = spinning_toml("[1.0, 0.0, 0.0]");
  no_fiber = no_fiber.substr(0, no_fiber.find("fiber = "));
  expect_error(no_fiber, {"bodies[0]", "aniso-damage", "fiber = [ax, ay, az]"});
  std::string isotropic = spinning_toml("[1.0, 0.0, 0.0]");
  isotropic.replace(isotropic.find("aniso-damage"), 12, "damage");
  isotropic.replace(isotropic.find("alpha = 3.0\n"), 12, "");
  isotropic.replace(isotropic.find("fiber_E = 2e4\n"), 14, "");
  expect_error(isotropic, {"bodies[0].fiber", "'damage'", "aniso-damage"});
  std::string negative = spinning_toml("[1.0, 0.0, 0.0]");
  negative.replace(negative.find("alpha = 3.0"), 11, "alpha = -1.0");
  expect_error(negative, {"materials.wood", "alpha"});
  std::string second_only = spinning_toml("[1.0, 0.0, 0.0]");
  second_only.replace(second_only.find("fiber = "), 8, "fiber2 = ");
  expect_error(second_only, {"bodies[0].fiber2", "give `fiber` first"});
  // A valid grain is normalised; a second family is kept, and absent is zero.
  const State<2> s = build_state<2>(testing::scene_from_toml(spinning_toml("[3.0, 4.0, 0.0]")));
  const Vec<2> a = AnisoDamage<2>::reference_fiber(s.particles.state_of(0), 0);
  EXPECT_NEAR(a[0], 0.6, 1e-15);
  EXPECT_NEAR(a[1], 0.8, 1e-15);
  EXPECT_EQ(AnisoDamage<2>::reference_fiber(s.particles.state_of(0), 1), Vec<2>::Zero());
  const State<2> two = build_state<2>(
      testing::scene_from_toml(spinning_toml("[1.0, 0.0, 0.0]\nfiber2 = [0.0, -2.0, 0.0]")));
  EXPECT_EQ(AnisoDamage<2>::reference_fiber(two.particles.state_of(0), 1), Vec<2>(0, -1));
}

}  // namespace aniso_damage_test
}  // namespace mpmtb
