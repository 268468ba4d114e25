// Damage model (REFERENCE.md, "Damage"; methods/models/damage.hpp) in 1, 2 and 3D.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <regex>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/errors.hpp"
#include "core/parameters.hpp"
#include "core/particles.hpp"
#include "core/types.hpp"
#include "models/damage.hpp"
#include "models/neo_hookean.hpp"
#include "support/finite_difference.hpp"
#include "support/random_matrices.hpp"

namespace mpmtb {
namespace damage_test {

using testing::FiniteDifferenceP;
using testing::RandomMatrix;
using testing::RandomRotation;

constexpr Real kE = 250, kNu = 0.3, kRho = 7, kSigmaCrit = 20;
// Lame constants derived here, independently of the class under test.
constexpr Real kMu = kE / (2 * (1 + kNu));
constexpr Real kLambda = kE * kNu / ((1 + kNu) * (1 - 2 * kNu));

std::map<std::string, Real> Valid() {
  return {{"E", kE}, {"nu", kNu}, {"density", kRho}, {"sigma_crit", kSigmaCrit}};
}
std::map<std::string, Real> With(const std::string& key, Real value) {
  auto v = Valid();
  v[key] = value;
  return v;
}

// The local model (l0 = 0) unless l0 is given: these tests call project on
// single particles, with no grid to give lap d (damage_length_test.cpp has l0 > 0).
template <int Dim>
Damage<Dim> MakeDamage(const std::map<std::string, Real>& values = Valid()) {
  auto local = values;
  local.emplace("l0", 0);
  Parameters p("materials.test", local);
  Damage<Dim> m(p);
  p.reject_unknown();
  return m;
}

// F = I + 0.3 * random with J >= 0.2, and |J - 1| > 1e-3 so that the finite
// differences do not straddle the tension/compression switch at J = 1.
template <int Dim>
Mat<Dim> RandomF(std::mt19937& gen) {
  for (;;) {
    const Mat<Dim> F = Mat<Dim>::Identity() + 0.3 * RandomMatrix<Dim>(gen);
    const Real J = F.determinant();
    if (J >= 0.2 && std::abs(J - 1) > 1e-3) return F;
  }
}

// Uniaxial stretch along x, the other directions held at 1.
template <int Dim>
Mat<Dim> Uniaxial(Real stretch) {
  Mat<Dim> F = Mat<Dim>::Identity();
  F(0, 0) = stretch;
  return F;
}

// Largest principal value of the undamaged Cauchy stress, from the neo-Hookean model.
template <int Dim>
Real MaxPrincipal(const NeoHookean<Dim>& nh, const Mat<Dim>& F) {
  const Mat<Dim> sigma = nh.tau(F, nullptr) / F.determinant();
  return Eigen::SelfAdjointEigenSolver<Mat<Dim>>(sigma).eigenvalues().maxCoeff();
}

template <class D>
class DamageTest : public ::testing::Test {
 protected:
  static constexpr int Dim = D::value;
  Damage<Dim> m_ = MakeDamage<Dim>();
  Parameters nh_params_{"materials.test", Valid()};
  NeoHookean<Dim> nh_{nh_params_};  // the undamaged reference
  std::mt19937 gen_{1234 + Dim};
};
using Dims = ::testing::Types<std::integral_constant<int, 1>, std::integral_constant<int, 2>,
                              std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(DamageTest, Dims);

// Through the virtual interface, with the damage state held fixed.
TYPED_TEST(DamageTest, StressIsEnergyGradientAtFixedDamage) {
  constexpr int Dim = TestFixture::Dim;
  const ConstitutiveModel<Dim>& m = this->m_;
  for (const Real d : {0.0, 0.3, 1.0}) {
    const Real q[4] = {d, 0, 0, 0};
    for (int s = 0; s < 20; ++s) {
      const Mat<Dim> F = RandomF<Dim>(this->gen_);
      const Mat<Dim> P_fd = FiniteDifferenceP<Dim>(m, F, q);
      const Mat<Dim> P = m.first_piola(F, q);
      EXPECT_LT((P - P_fd).norm(), 1e-6 * (P.norm() + 1e-3 * kE)) << "d " << d << "\n" << F;
      const Mat<Dim> PFt = P * F.transpose();
      EXPECT_LT((this->m_.tau(F, q) - PFt).norm(), 1e-12 * (PFt.norm() + kE));
    }
  }
}

TYPED_TEST(DamageTest, RotationsAreStressFreeAndObjective) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->m_;
  for (const Real d : {0.0, 0.3, 1.0}) {
    const Real q[4] = {d, 0, 0, 0};
    for (int s = 0; s < 10; ++s) {
      const Mat<Dim> R = s == 0 ? Mat<Dim>::Identity() : RandomRotation<Dim>(this->gen_);
      SCOPED_TRACE(::testing::Message() << "R =\n" << R);
      EXPECT_LT(m.P(R, q).norm(), 1e-12 * kE);
      EXPECT_LT(m.tau(R, q).norm(), 1e-12 * kE);
      EXPECT_LT(std::abs(m.psi(R, q)), 1e-12 * kE);
      // Objectivity (trivial in 1D, where R = I).
      const Mat<Dim> F = RandomF<Dim>(this->gen_);
      const Real psi = m.psi(F, q);
      EXPECT_NEAR(m.psi(R * F, q), psi, 1e-12 * (std::abs(psi) + kE));
      EXPECT_NEAR(m.max_principal_stress(R * F), m.max_principal_stress(F), 1e-10 * kE);
    }
  }
  const Real q0[4] = {0, 0, 0, 0};
  EXPECT_GT(m.P(Mat<Dim>::Identity() * 1.1, q0).norm(), 1e-2 * kE);
}

TYPED_TEST(DamageTest, SplitIsExactAndNonNegative) {
  constexpr int Dim = TestFixture::Dim;
  const auto& nh = this->nh_;
  const auto& m = this->m_;
  const Real q0[4] = {0, 0, 0, 0};
  int tension = 0, compression = 0;
  for (int s = 0; s < 200; ++s) {
    const Mat<Dim> F = RandomF<Dim>(this->gen_);
    const auto e = m.split(F);
    const Real psi = nh.psi(F, nullptr);
    EXPECT_NEAR(e.plus + e.minus, psi, 1e-12 * (psi + kE)) << "F =\n" << F;
    EXPECT_NEAR(m.psi(F, q0), psi, 1e-12 * (psi + kE));
    EXPECT_LT((m.P(F, q0) - nh.P(F, nullptr)).norm(), 1e-12 * kE);
    EXPECT_NEAR(m.max_principal_stress(F), MaxPrincipal(nh, F), 1e-10 * kE);
    EXPECT_GE(e.plus, 0);
    EXPECT_GE(e.minus, 0);
    if (F.determinant() > 1) {
      EXPECT_EQ(e.minus, 0) << "no compressive energy under J > 1";
      ++tension;
    } else {
      EXPECT_GT(e.minus, 0) << "the volumetric energy under J < 1 is kept";
      ++compression;
    }
  }
  EXPECT_GT(tension, 20);
  EXPECT_GT(compression, 20);
}

TYPED_TEST(DamageTest, DamageIsMonotoneAndBounded) {
  constexpr int Dim = TestFixture::Dim;
  const auto m = MakeDamage<Dim>(With("eta", 1e-2));
  std::uniform_real_distribution<Real> u(0, 1);
  Real q[4] = {-1, -1, -1, -1};
  m.initial_state(q);
  ASSERT_TRUE(q[0] == 0 && q[1] == 0);
  Real d_max_seen = 0;
  for (int step = 0; step < 2000; ++step) {
    // Loading/unloading: stretch amplitude follows a noisy cycle, sometimes far past failure.
    const Real a =
        0.4 * std::sin(step * 0.01) * std::sin(step * 0.0031) + 0.05 * (u(this->gen_) - 0.5);
    Mat<Dim> F =
        Mat<Dim>::Identity() + a * Mat<Dim>::Identity() + 0.1 * RandomMatrix<Dim>(this->gen_);
    if (F.determinant() < 0.2) continue;
    const Mat<Dim> F_before = F;
    const Real d_old = q[0], w_old = q[1];
    m.project(F, q, 1e-3);
    EXPECT_EQ(F, F_before) << "damage must not change F";
    EXPECT_GE(q[0], d_old) << "step " << step;
    EXPECT_LE(q[0], 1);
    EXPECT_GE(q[1], w_old) << "dissipation decreased at step " << step;
    d_max_seen = std::max(d_max_seen, q[0]);
  }
  EXPECT_GT(d_max_seen, 0.1) << "the history should damage the particle";
  // One huge step (dt / eta = 100) far past failure: clamped to exactly 1, then absorbing.
  Real q1[4] = {0, 0, 0, 0};
  for (int i = 0; i < 2; ++i) {
    Mat<Dim> F = Uniaxial<Dim>(1.5);
    m.project(F, q1, 1);
    EXPECT_EQ(q1[0], 1);
  }
}

// 1D Cauchy stress of the undamaged neo-Hookean bar, computed here from
// sigma = tau / J, tau = mu (F^2 - 1) + lambda ln F.
Real Cauchy1D(Real F) {
  return (kMu * (F * F - 1) + kLambda * std::log(F)) / F;
}

TYPED_TEST(DamageTest, NoDamageBelowThreshold) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->m_;
  // The uniaxial stretch whose largest principal stress is `ratio` sigma_crit.
  auto stretch_at = [&](Real ratio) {
    Real lo = 1, hi = 2;
    for (int i = 0; i < 200; ++i) {
      const Real mid = 0.5 * (lo + hi);
      (MaxPrincipal(this->nh_, Uniaxial<Dim>(mid)) < ratio * kSigmaCrit ? lo : hi) = mid;
    }
    return lo;
  };
  const Real below = stretch_at(0.99);
  Real q[4] = {0, 0, 0, 0};
  for (int step = 0; step < 10000; ++step) {
    Mat<Dim> F = Uniaxial<Dim>(below);
    m.project(F, q, 1e-3);
  }
  EXPECT_EQ(q[0], 0);
  EXPECT_EQ(q[1], 0);
  // Just above the threshold the same loading damages.
  Mat<Dim> F = Uniaxial<Dim>(stretch_at(1.01));
  m.project(F, q, 1e-3);
  EXPECT_GT(q[0], 0);
  // The driver is the UNDAMAGED stress: at d = 0.2 and 1.5 sigma_crit undamaged
  // (0.96 sigma_crit degraded), (1 - d) D~ - d = 0.8 * 0.5 - 0.2 > 0: d grows.
  Real q2[4] = {0.2, 0, 0, 0};
  F = Uniaxial<Dim>(stretch_at(1.5));
  EXPECT_NEAR(m.max_principal_stress(F), 1.5 * kSigmaCrit, 1e-9 * kSigmaCrit);
  m.project(F, q2, 1e-3);
  EXPECT_NEAR(q2[0], 0.2 + 1e-3 / 1e-3 * 0.2, 1e-9);
}

// eigenvalue_excess skips the eigenvalue solve where bounds show the stress
// below the limit; the damage reads only the sign of a negative excess. So its
// sign must be the solver's, and a positive excess the solver's own value, for
// symmetric and unsymmetric stresses with their largest eigenvalue far below,
// just below, at and above the limit, with strong shear (Gershgorin's bound
// fails, Sylvester's criterion decides) and with repeated eigenvalues.
TYPED_TEST(DamageTest, StressExcessHasTheSolversSign) {
  constexpr int Dim = TestFixture::Dim;
  if constexpr (Dim >= 2) {
    std::uniform_real_distribution<Real> u(-1, 1);
    int positive = 0, negative = 0;
    for (int trial = 0; trial < 4000; ++trial) {
      const Real top = kSigmaCrit * (trial % 4 == 0   ? 1 - std::pow(10.0, -2 - trial % 13)
                                     : trial % 4 == 1 ? 1 + std::pow(10.0, -2 - trial % 13)
                                     : trial % 4 == 2 ? 1 + 0.5 * u(this->gen_)
                                                      : 1);
      Vec<Dim> lambda;
      for (int a = 0; a < Dim; ++a)
        lambda[a] = top - (a == 0 ? 0 : (trial % 3) * kSigmaCrit * (1 + u(this->gen_)));
      const Mat<Dim> R = RandomRotation<Dim>(this->gen_);
      Mat<Dim> s = R * lambda.asDiagonal() * R.transpose();
      const Mat<Dim> skew = 0.1 * kSigmaCrit * (trial % 2) * RandomMatrix<Dim>(this->gen_);
      s += skew - skew.transpose();  // the symmetric part, and so the eigenvalues, kept
      const Real solved = Damage<Dim>::max_symmetric_eigenvalue(s) - kSigmaCrit;
      const Real excess = Damage<Dim>::eigenvalue_excess(s, kSigmaCrit);
      ASSERT_EQ(excess > 0, solved > 0) << "trial " << trial << ": " << excess << " vs " << solved;
      if (solved > 0) {
        ASSERT_EQ(excess, solved) << "trial " << trial;
        ++positive;
      } else {
        ++negative;
      }
    }
    EXPECT_GT(positive, 500);
    EXPECT_GT(negative, 500);
  }
}

// The largest eigenvalue in 3D in closed form (Damage::largest_eigenvalue_3x3)
// is Eigen's iterative solver's to a few eps |A|, at every scale, with eigenvalues
// spread, the two smallest repeated or nearly so, nearly a multiple of I and
// exactly one; where the two largest nearly coincide the solver answers.
TEST(DamageEigenvalue, ClosedFormAgreesWithTheIterativeSolver) {
  std::mt19937 gen(2026);
  std::uniform_real_distribution<Real> u(-1, 1);
  constexpr Real eps = std::numeric_limits<Real>::epsilon();
  int closed = 0, solved = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Real scale = std::pow(Real(10), 6 * u(gen));
    const Real gap = std::pow(Real(10), -8 * (u(gen) + 1));  // 1 down to 1e-16
    Vec<3> lambda;
    switch (trial % 5) {
      case 0:
        lambda << u(gen), u(gen), u(gen);
        break;
      case 1:
        lambda << 1, -0.5, -0.5 - gap;
        break;  // the two smallest close
      case 2:
        lambda << 1, 1 - gap, u(gen) - 1.5;
        break;  // the two largest close
      case 3:
        lambda << 5 + gap, 5, 5 - gap;
        break;  // nearly a multiple of I
      default:
        lambda << 2, 2, 2;
        break;  // a multiple of I
    }
    const Mat<3> R = RandomRotation<3>(gen);
    const Mat<3> A = scale * R * lambda.asDiagonal() * R.transpose();
    const Mat<3> sym = Real(0.5) * (A + A.transpose());
    Eigen::SelfAdjointEigenSolver<Mat<3>> eig(sym, Eigen::EigenvaluesOnly);
    const Real reference = eig.eigenvalues().maxCoeff();
    Real largest = 0;
    if (Damage<3>::largest_eigenvalue_3x3(sym, largest)) {
      ASSERT_NEAR(largest, reference, 16 * eps * sym.norm()) << "trial " << trial;
      ++closed;
    } else {
      ++solved;
    }
    ASSERT_NEAR(Damage<3>::max_symmetric_eigenvalue(A), reference, 16 * eps * sym.norm())
        << "trial " << trial;
  }
  EXPECT_GT(closed, 15000);
  EXPECT_GT(solved, 1000) << "the two largest close: the solver's";
}

// project() skips the exact driver where an exp-free bound shows the stress
// below sigma_crit (certainly_below_limit); the damage and the dissipated
// energy must be those of the exact driver, bit for bit, for deformations
// below, near and above the onset, with and without damage already.
TYPED_TEST(DamageTest, ScreenedDriverGivesTheExactDriversDamage) {
  constexpr int Dim = TestFixture::Dim;
  const Damage<Dim>& m = this->m_;
  constexpr Real dt = 1e-4;
  int screened = 0, grown = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Real amplitude = 0.05 + 0.1 * (trial % 5);
    const Mat<Dim> F = testing::RandomF<Dim>(this->gen_, amplitude, 0.3);
    const Real logJ = std::log(F.determinant()), d_old = trial % 3 == 0 ? 0.4 : 0;
    Real q[4] = {d_old, 0.25, 0, 0}, expected[4] = {d_old, 0.25, 0, 0};
    const Real d_new = m.advanced_damage(d_old, m.stress_excess(F, logJ), expected, dt);
    if (d_new > d_old) {
      expected[1] += (m.degradation(d_old) - m.degradation(d_new)) * m.split(F).plus;
      expected[0] = d_new;
      ++grown;
    }
    screened += m.certainly_below_limit(F, logJ);
    Mat<Dim> G = F;
    m.project_given_log(G, logJ, q, dt);
    ASSERT_EQ(q[0], expected[0]) << "trial " << trial;
    ASSERT_EQ(q[1], expected[1]) << "trial " << trial;
    ASSERT_EQ(G, F) << "F is not changed";
  }
  EXPECT_GT(screened, 300) << "the bound decides for small deformations";
  EXPECT_GT(grown, 300) << "and the exact driver where damage grows";
}

// The return map's projection with J^(2/3) given (3D: the batch's exponentials,
// ModelBase::return_map) is project()'s: given std::exp's J^(2/3), bit for bit;
// through the whole return map (batch_log, batch_exp) within round-off.
TEST(Damage3D, ProjectionWithThePowerGivenIsProjects) {
  const Damage<3> m = MakeDamage<3>();
  constexpr Real dt = 1e-4;
  std::mt19937 gen(16);
  Particles<3> P, expected;
  P.state_size = expected.state_size = 4;
  int grown = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Mat<3> F = testing::RandomF<3>(gen, 0.05 + 0.1 * (trial % 5), 0.3);
    const Real logJ = std::log(F.determinant()), d_old = trial % 3 == 0 ? 0.4 : 0;
    Real q[4] = {d_old, 0.25, 0, 0}, reference[4] = {d_old, 0.25, 0, 0};
    Mat<3> G = F, H = F;
    m.project_given_log_and_power(G, logJ, std::exp(Real(2) / 3 * logJ), q, dt);
    m.project_given_log(H, logJ, reference, dt);
    ASSERT_EQ(q[0], reference[0]) << "trial " << trial;
    ASSERT_EQ(q[1], reference[1]) << "trial " << trial;
    grown += reference[0] > d_old;
    for (Particles<3>* to : {&P, &expected}) {
      to->add(Vec<3>::Zero(), Vec<3>::Zero(), 1, 1, 0);
      to->F.back() = F;
      for (const Real v : {d_old, Real(0.25), Real(0), Real(0)}) to->state.push_back(v);
    }
  }
  EXPECT_GT(grown, 300);
  std::vector<int> ids(P.size());
  for (std::size_t p = 0; p < ids.size(); ++p) ids[p] = static_cast<int>(p);
  m.return_map(P, ids, dt);
  for (std::size_t p = 0; p < P.size(); ++p) {
    m.project(expected.F[p], expected.state_of(p), dt);
    for (int k : {0, 1}) {
      ASSERT_NEAR(P.state_of(p)[k], expected.state_of(p)[k], 1e-13) << "particle " << p;
    }
  }
}

// settled() lets the return map skip a particle (and its logarithm): only
// where project() would leave it exactly as it is, including the growth that
// the nonlocal term alone drives (l0 > 0, lap d > 0 from damaged neighbours).
TYPED_TEST(DamageTest, SettledParticlesAreLeftAsTheyAre) {
  constexpr int Dim = TestFixture::Dim;
  const Damage<Dim> m = MakeDamage<Dim>(With("l0", 0.02));
  constexpr Real dt = 1e-4, diagonal = 2 * Dim * 64 * 64;  // dx = 1/64
  int settled = 0, moving = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Mat<Dim> F = testing::RandomF<Dim>(this->gen_, 0.05 + 0.1 * (trial % 4), 0.3);
    const Real d_old = trial % 3 == 0 ? 0 : trial % 3 == 1 ? 0.4 : 1;
    const Real lap = trial % 5 == 0 ? 50 : trial % 5 == 1 ? -50 : 0;
    Real q[4] = {d_old, 0.25, lap, diagonal};
    if (!m.settled(F, F.determinant(), q, dt)) {
      ++moving;
      continue;
    }
    ++settled;
    const Real before[4] = {q[0], q[1], q[2], q[3]};
    Mat<Dim> G = F;
    m.project_given_log(G, std::log(F.determinant()), q, dt);
    for (int k = 0; k < 4; ++k) ASSERT_EQ(q[k], before[k]) << "trial " << trial << " slot " << k;
    ASSERT_EQ(G, F);
  }
  EXPECT_GT(settled, 500);
  EXPECT_GT(moving, 300);
}

// The return map screens its particles a vector register at a time
// (Damage::unsettled, ModelBase::return_map): the same answer as settled()
// particle by particle, and det F bit for bit as Eigen's, which the logarithm
// then takes. Particles near the threshold, inverted (J <= 0), fully damaged,
// with lap d of either sign, with and without the nonlocal term, and a count
// that leaves a partial register.
TYPED_TEST(DamageTest, BatchScreenAgreesWithTheParticleScreen) {
  constexpr int Dim = TestFixture::Dim;
  constexpr Real dt = 1e-4, diagonal = 2 * Dim * 64 * 64;
  for (const Real l0 : {0.02, 0.0}) {
    const Damage<Dim> m = MakeDamage<Dim>(With("l0", l0));
    Particles<Dim> P;
    P.state_size = 4;
    for (int p = 0; p < 203; ++p) {
      P.add(Vec<Dim>::Zero(), Vec<Dim>::Zero(), 1, 1, 0);
      P.F[p] = testing::RandomF<Dim>(this->gen_, 0.05 + 0.1 * (p % 4), 0.3);
      if (p % 17 == 0) P.F[p].row(0) *= -1;  // inverted
      const Real d_old = p % 3 == 0 ? 0 : p % 3 == 1 ? 0.4 : 1;
      const Real lap = p % 5 == 0 ? 50 : p % 5 == 1 ? -50 : 0;
      for (const Real q : {d_old, Real(0.25), lap, diagonal}) P.state.push_back(q);
    }
    std::vector<int> ids(P.size());
    for (std::size_t p = 0; p < ids.size(); ++p) ids[p] = static_cast<int>(ids.size() - 1 - p);
    std::vector<Real> J(ids.size());
    std::vector<int> kept(ids.size());
    const int count =
        m.unsettled(P, ids.data(), static_cast<int>(ids.size()), dt, J.data(), kept.data());
    int expected = 0;
    for (const int p : ids) {
      const Real det = P.F[p].determinant();
      if (m.settled(P.F[p], det, P.state_of(p), dt)) continue;
      ASSERT_LT(expected, count) << "l0 " << l0 << ": particle " << p << " was screened out";
      EXPECT_EQ(kept[expected], p) << "l0 " << l0;
      EXPECT_EQ(std::bit_cast<std::uint64_t>(double(J[expected])),
                std::bit_cast<std::uint64_t>(double(det)))
          << "l0 " << l0 << ": det F of particle " << p;
      ++expected;
    }
    EXPECT_EQ(count, expected) << "l0 " << l0;
    EXPECT_GT(expected, 20) << "l0 " << l0;
    EXPECT_LT(expected, 183) << "l0 " << l0;
  }
}

TEST(DamageOnset, StartsExactlyAtCriticalStressIn1D) {
  const auto m = MakeDamage<1>();
  Real q[4] = {0, 0, 0, 0};
  int first_damaged = -1, first_over = -1;
  for (int step = 1; step <= 2000; ++step) {
    const Real stretch = 1 + 1e-4 * step;
    if (first_over < 0 && Cauchy1D(stretch) > kSigmaCrit) first_over = step;
    Mat<1> F = Uniaxial<1>(stretch);
    m.project(F, q, 1e-4);
    if (q[0] > 0 && first_damaged < 0) first_damaged = step;
  }
  ASSERT_GT(first_over, 1) << "the ramp must start below the critical stress";
  EXPECT_EQ(first_damaged, first_over);
  EXPECT_LT(Cauchy1D(1 + 1e-4 * (first_over - 1)), kSigmaCrit);
}

TYPED_TEST(DamageTest, FullyDamagedCarriesNoTensionButResistsCompression) {
  constexpr int Dim = TestFixture::Dim;
  const auto m = MakeDamage<Dim>(With("k", 1e-9));
  const auto& nh = this->nh_;
  const Real broken[2] = {1, 0};
  for (const Real stretch : {1.01, 1.2, 1.5}) {
    const Mat<Dim> F = Uniaxial<Dim>(stretch);
    const Real P_intact = nh.P(F, nullptr).norm();
    EXPECT_LE(m.P(F, broken).norm(), 2e-9 * P_intact) << "stretch " << stretch;
    EXPECT_LE(m.psi(F, broken), 2e-9 * nh.psi(F, nullptr));
  }
  // Compression: in 1D the whole stress, in any dimension under pure dilation.
  for (const Real s : {0.99, 0.9, 0.7}) {
    const Mat<Dim> F = s * Mat<Dim>::Identity();
    const Mat<Dim> P_intact = nh.P(F, nullptr);
    EXPECT_LT((m.P(F, broken) - P_intact).norm(), 1e-12 * P_intact.norm()) << "s " << s;
    EXPECT_LT(P_intact(0, 0), 0);
    if constexpr (Dim > 1) {
      // Uniaxial compression: keeps the volumetric stress, computed here from
      // P_vol = (mu (J^(2/dim) - 1) + lambda ln J) F^-T, and loses the shear part.
      const Mat<Dim> Fu = Uniaxial<Dim>(s);
      const Real J = Fu.determinant();
      const Mat<Dim> P_vol = (kMu * (std::pow(J, 2.0 / Dim) - 1) + kLambda * std::log(J)) *
                             Mat<Dim>(Fu.inverse().transpose());
      const Mat<Dim> P_broken = m.P(Fu, broken);
      EXPECT_LT((P_broken - P_vol).norm(), 1e-6 * P_vol.norm()) << "s " << s;
      EXPECT_LT(P_broken(0, 0), 0);
      EXPECT_GT(P_broken(0, 0), nh.P(Fu, nullptr)(0, 0)) << "the shear part is degraded";
    }
  }
}

TYPED_TEST(DamageTest, EnergyBudgetAtFixedF) {
  constexpr int Dim = TestFixture::Dim;
  const auto m = MakeDamage<Dim>(With("eta", 1e-2));
  Real q[4] = {0, 0, 0, 0};
  Real released = 0;
  for (int step = 0; step < 200; ++step) {
    Mat<Dim> F = Uniaxial<Dim>(1.3) + 0.02 * RandomMatrix<Dim>(this->gen_);
    const Real psi_old = m.psi(F, q), w_old = q[1];
    m.project(F, q, 1e-3);
    const Real psi_new = m.psi(F, q), w_new = q[1];
    EXPECT_GE(w_new, w_old);
    EXPECT_NEAR(psi_old, psi_new + (w_new - w_old), 1e-12 * (psi_old + kE)) << "step " << step;
    released += psi_old - psi_new;
  }
  EXPECT_GT(q[0], 0.5);
  EXPECT_DOUBLE_EQ(m.dissipated(q), q[1]);
  EXPECT_NEAR(m.dissipated(q), released, 1e-10 * kE);
  EXPECT_GT(released, 0);
}

void ExpectRejected(const std::map<std::string, Real>& values, const std::string& key) {
  SCOPED_TRACE("expected rejection naming '" + key + "'");
  try {
    MakeDamage<2>(values);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_TRUE(std::regex_search(e.what(), std::regex("\\b" + key + "\\b")))
        << "message: " << e.what();
  }
}

TEST(DamageParameters, ValidParametersAreAcceptedAndStateIsNamed) {
  EXPECT_NO_THROW(MakeDamage<2>());
  auto all = Valid();
  all.insert({{"zeta", 2}, {"eta", 0.1}, {"k", 0}});
  const auto m = MakeDamage<3>(all);
  EXPECT_EQ(m.name(), "damage");
  EXPECT_EQ(m.state_size(), 4);
  EXPECT_EQ(m.state_names(),
            (std::vector<std::string>{"damage", "dissipated", "lap_damage", "lap_diagonal"}));
  EXPECT_DOUBLE_EQ(m.density(), kRho);
}

TEST(DamageParameters, InvalidValuesAreRejectedByName) {
  const std::vector<std::pair<std::string, Real>> bad = {
      {"sigma_crit", 0}, {"sigma_crit", -1}, {"eta", 0},  {"eta", -1e-3},  {"zeta", 0},  {"k", 1},
      {"k", -0.1},       {"E", 0},           {"nu", 0.5}, {"density", -1}, {"l0", -0.01}};
  for (const auto& [key, value] : bad) ExpectRejected(With(key, value), key);
  auto missing = Valid();
  missing.erase("sigma_crit");
  ExpectRejected(missing, "sigma_crit");
}

}  // namespace damage_test
}  // namespace mpmtb
