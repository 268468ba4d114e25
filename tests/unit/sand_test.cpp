// Drucker-Prager sand (Klar et al. 2016; models/sand.hpp) in 1, 2 and 3
// dimensions: the return map lands on the cone (checked in stress space with
// the model's own Kirchhoff stress), is idempotent, leaves states inside the
// cone alone, sends expansion to the stress-free tip, keeps the trace of the
// Hencky strain on the cone (isochoric plastic flow), never raises psi, books
// what it removes as dissipated, and commutes with rotations on either side.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <type_traits>

#include "core/parameters.hpp"
#include "models/sand.hpp"
#include "support/random_matrices.hpp"

namespace mpmtb {
namespace sand_test {

using testing::RandomRotation;

constexpr Real kE = 3.537e5, kNu = 0.3, kRho = 2200;  // Klar et al. 2016, sec. 8
constexpr Real kMu = kE / (2 * (1 + kNu));
constexpr Real kLambda = kE * kNu / ((1 + kNu) * (1 - 2 * kNu));

std::map<std::string, Real> SandParams(std::map<std::string, Real> extra = {}) {
  std::map<std::string, Real> v = {{"E", kE}, {"nu", kNu}, {"density", kRho}};
  v.insert(extra.begin(), extra.end());
  return v;
}

// alpha of eq. 27, written here from the friction angle in degrees.
Real Alpha(Real phi_degrees) {
  const Real s = std::sin(phi_degrees * std::numbers::pi / 180);
  return std::sqrt(2.0 / 3.0) * 2 * s / (3 - s);
}

// Principal Hencky strains of F from Eigen's SVD (independent of signed_svd).
template <int Dim>
Vec<Dim> HenckyStrains(const Mat<Dim>& F) {
  return Eigen::JacobiSVD<Mat<Dim>>(F).singularValues().array().log().matrix();
}

template <class D>
class SandTest : public ::testing::Test {
 protected:
  static constexpr int Dim = D::value;
  Parameters params_{"materials.sand", SandParams()};
  Sand<Dim> sand_{params_};
  std::mt19937 gen_{31 + Dim};

  std::array<Real, 3> fresh() const {
    std::array<Real, 3> q{};
    sand_.initial_state(q.data());
    return q;
  }
  // F = U exp(eps) V^T with random rotations: a trial state with principal strains eps.
  Mat<Dim> FromStrains(const Vec<Dim>& eps) {
    return RandomRotation<Dim>(gen_) * eps.array().exp().matrix().asDiagonal() *
           RandomRotation<Dim>(gen_).transpose();
  }
  // Principal strains with trace `tr` and a deviatoric part of norm `dev` (Dim >= 2).
  Vec<Dim> Strains(Real tr, Real dev) {
    std::normal_distribution<Real> n(0, 1);
    Vec<Dim> hat;
    for (int a = 0; a < Dim; ++a) hat[a] = n(gen_);
    hat.array() -= hat.mean();
    return (tr / Dim) * Vec<Dim>::Ones() + dev * hat.normalized();
  }
  // |eps_hat| on the cone for a given trace (the yield condition delta_gamma = 0).
  Real ConeRadius(Real tr, Real phi = 30) const {
    return -(Dim * kLambda + 2 * kMu) / (2 * kMu) * tr * Alpha(phi);
  }
};
using Dims = ::testing::Types<std::integral_constant<int, 1>, std::integral_constant<int, 2>,
                              std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(SandTest, Dims);

TYPED_TEST(SandTest, DefaultsAndState) {
  const auto q = this->fresh();
  EXPECT_EQ(q[0], 1) << "J_P starts at 1";
  EXPECT_EQ(q[1], 0) << "no hardening at the start";
  EXPECT_EQ(q[2], 0) << "nothing dissipated at the start";
  EXPECT_EQ(this->sand_.friction_angle(q.data()), 30);
  EXPECT_NEAR(this->sand_.alpha(q.data()), Alpha(30), 1e-15);
  EXPECT_NEAR(this->sand_.mu(), kMu, 1e-9 * kMu);
  EXPECT_NEAR(this->sand_.lambda(), kLambda, 1e-9 * kLambda);
}

// psi = mu |eps|^2 + lambda/2 (tr eps)^2 with eps from an independent SVD.
TYPED_TEST(SandTest, EnergyIsHenckyStVK) {
  constexpr int Dim = TestFixture::Dim;
  for (int s = 0; s < 20; ++s) {
    const Mat<Dim> F = testing::RandomF<Dim>(this->gen_, 0.4);
    const Vec<Dim> eps = HenckyStrains<Dim>(F);
    const Real expected = kMu * eps.squaredNorm() + 0.5 * kLambda * eps.sum() * eps.sum();
    EXPECT_NEAR(this->sand_.psi(F, nullptr), expected, 1e-12 * (expected + kE));
  }
}

// Outside the cone with compression: after the map the Kirchhoff stress lies on
// the Drucker-Prager cone |dev tau| + alpha tr(tau) = 0 (eq. 27 in stress form:
// dev tau = 2 mu eps_hat, tr tau = (d lambda + 2 mu) tr eps), the trace of eps
// and J_P are kept, and a second map changes nothing (idempotent).
TYPED_TEST(SandTest, ConeCaseLandsOnTheYieldSurfaceAtFixedTrace) {
  constexpr int Dim = TestFixture::Dim;
  if (Dim == 1) GTEST_SKIP() << "no deviatoric strain in 1D: compression is always elastic";
  const auto& m = this->sand_;
  std::uniform_real_distribution<Real> tr_dist(-0.05, -1e-3), factor(1.2, 20);
  for (int s = 0; s < 50; ++s) {
    const Real tr = tr_dist(this->gen_);
    const Mat<Dim> trial =
        this->FromStrains(this->Strains(tr, factor(this->gen_) * this->ConeRadius(tr)));
    Mat<Dim> F = trial;
    auto q = this->fresh();
    m.project(F, q.data(), 1e-3);
    const Vec<Dim> eps = HenckyStrains<Dim>(F);
    EXPECT_NEAR(eps.sum(), tr, 1e-12) << "plastic flow on the cone is isochoric";
    EXPECT_EQ(q[0], 1) << "J_P unchanged on the cone";
    const Vec<Dim> eps_hat = eps.array() - eps.mean();
    EXPECT_NEAR(eps_hat.norm(), this->ConeRadius(tr), 1e-10);
    // Stress form, from the model's own tau.
    const Mat<Dim> tau = m.tau(F, q.data());
    const Mat<Dim> dev = tau - tau.trace() / Dim * Mat<Dim>::Identity();
    EXPECT_NEAR(dev.norm() + Alpha(30) * tau.trace(), 0, 1e-9 * tau.norm());
    // Idempotent.
    const Mat<Dim> once = F;
    const auto q_once = q;
    m.project(F, q.data(), 1e-3);
    EXPECT_LT((F - once).norm(), 1e-13);
    EXPECT_LT(std::abs(q[2] - q_once[2]), 1e-12 * q_once[2]);
  }
}

TYPED_TEST(SandTest, InsideTheConeIsLeftUnchanged) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->sand_;
  std::uniform_real_distribution<Real> tr_dist(-0.05, -1e-4), factor(0, 0.95);
  for (int s = 0; s < 50; ++s) {
    const Real tr = tr_dist(this->gen_);
    const Real dev = Dim == 1 ? 0 : factor(this->gen_) * this->ConeRadius(tr);
    const Mat<Dim> F0 =
        this->FromStrains(Dim == 1 ? Vec<Dim>::Constant(tr) : this->Strains(tr, dev));
    Mat<Dim> F = F0;
    auto q = this->fresh();
    q[0] = 0.9;  // some earlier plastic history
    q[1] = 0.3;
    m.project(F, q.data(), 1e-3);
    EXPECT_EQ(F, F0);
    EXPECT_EQ(q[0], 0.9);
    EXPECT_EQ(q[1], 0.3);
    EXPECT_EQ(q[2], 0);
  }
}

// Expansion (tr eps > 0) goes to the tip: F becomes a rotation (stress free),
// J_P takes the whole volume change, and all of psi is dissipated.
TYPED_TEST(SandTest, TensionGoesToTheStressFreeTip) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->sand_;
  std::uniform_real_distribution<Real> tr_dist(1e-4, 0.3), dev_dist(0, 0.3);
  for (int s = 0; s < 50; ++s) {
    const Vec<Dim> eps = Dim == 1 ? Vec<Dim>::Constant(tr_dist(this->gen_))
                                  : this->Strains(tr_dist(this->gen_), dev_dist(this->gen_));
    Mat<Dim> F = this->FromStrains(eps);
    const Real J_total = F.determinant(), psi_trial = m.psi(F, nullptr);
    auto q = this->fresh();
    m.project(F, q.data(), 1e-3);
    EXPECT_LT((F.transpose() * F - Mat<Dim>::Identity()).norm(), 1e-12) << "F =\n" << F;
    EXPECT_NEAR(F.determinant(), 1, 1e-12);
    EXPECT_LT(m.P(F, q.data()).norm(), 1e-9 * kE);
    EXPECT_NEAR(m.total_J(F, q.data()), J_total, 1e-12 * J_total);
    EXPECT_NEAR(q[1], eps.norm(), 1e-12) << "q grows by |eps| (Algorithm 2, case II)";
    EXPECT_NEAR(q[2], psi_trial, 1e-12 * psi_trial);
  }
}

// Random large deformations as a sequence of steps: psi never rises through a
// map, the increment of `dissipated` is exactly what psi lost, and the total
// volume ratio J = J_E J_P is what the trial step produced.
TYPED_TEST(SandTest, ReturnMapNeverRaisesEnergyAndKeepsTotalJ) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->sand_;
  for (int path = 0; path < 20; ++path) {
    auto q = this->fresh();
    Mat<Dim> F = Mat<Dim>::Identity();
    for (int step = 0; step < 10; ++step) {
      const Mat<Dim> trial = testing::RandomF<Dim>(this->gen_, 0.2) * F;
      const Real J_total = trial.determinant() * q[0];
      const Real psi_trial = m.psi(trial, q.data()), d_before = q[2];
      F = trial;
      m.project(F, q.data(), 1e-3);
      const Real psi_after = m.psi(F, q.data());
      EXPECT_LE(psi_after, psi_trial + 1e-12 * kE);
      EXPECT_GE(q[2], d_before);
      EXPECT_NEAR(q[2] - d_before, psi_trial - psi_after, 1e-14 * kE);
      EXPECT_NEAR(m.total_J(F, q.data()), J_total, 1e-12 * J_total);
      EXPECT_GT(F.determinant(), 0);
    }
  }
}

// The map commutes with rotations on both sides: project(R F Q) = R project(F) Q.
TYPED_TEST(SandTest, ProjectionIsFrameIndifferentAndIsotropic) {
  constexpr int Dim = TestFixture::Dim;
  if (Dim == 1) GTEST_SKIP() << "the only rotation in 1D is the identity";
  const auto& m = this->sand_;
  for (int s = 0; s < 30; ++s) {
    const Real tr = -0.02 + 0.04 * (s % 2);  // cone and tip cases
    const Mat<Dim> F0 = this->FromStrains(this->Strains(tr, 0.1));
    const Mat<Dim> R = RandomRotation<Dim>(this->gen_), Q = RandomRotation<Dim>(this->gen_);
    Mat<Dim> F = F0, G = R * F0 * Q;
    auto qF = this->fresh(), qG = this->fresh();
    m.project(F, qF.data(), 1e-3);
    m.project(G, qG.data(), 1e-3);
    EXPECT_LT((G - R * F * Q).norm(), 1e-12) << "case " << (tr < 0 ? "cone" : "tip");
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(qG[k], qF[k], 1e-12 * (std::abs(qF[k]) + 1));
  }
}

// Hardening (eq. 28) with the paper's parameters: phi_F rises from h0 - h3 = 25
// to h0 = 35 degrees as q accumulates delta_gamma, so the cone opens.
TYPED_TEST(SandTest, HardeningOpensTheCone) {
  constexpr int Dim = TestFixture::Dim;
  if (Dim == 1) GTEST_SKIP() << "no cone case in 1D";
  Parameters params("materials.sand", SandParams({{"friction_angle", 35}, {"h1", 9}, {"h3", 10}}));
  const Sand<Dim> m(params);
  auto q = this->fresh();
  EXPECT_NEAR(m.friction_angle(q.data()), 25, 1e-12);
  const Real tr = -0.01;
  Mat<Dim> F = this->FromStrains(this->Strains(tr, 5 * this->ConeRadius(tr, 25)));
  const Vec<Dim> eps_trial = HenckyStrains<Dim>(F);
  m.project(F, q.data(), 1e-3);
  const Real delta_gamma =
      (eps_trial.array() - eps_trial.mean()).matrix().norm() - this->ConeRadius(tr, 25);
  EXPECT_NEAR(q[1], delta_gamma, 1e-10) << "q += delta_gamma (Algorithm 2, case III)";
  EXPECT_NEAR(m.friction_angle(q.data()), 35 + (9 * q[1] - 10) * std::exp(-0.2 * q[1]), 1e-12);
  EXPECT_GT(m.alpha(q.data()), Alpha(25));
  q[1] = 1e3;
  EXPECT_NEAR(m.friction_angle(q.data()), 35, 1e-9);
}

}  // namespace sand_test
}  // namespace mpmtb
