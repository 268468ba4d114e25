// Snow plasticity (Stomakhin et al. 2013; models/snow.hpp) in 1, 2 and 3
// dimensions: the return map clamps the elastic singular values, keeps the
// total J = J_E J_P, hardens in compression and softens in stretch, leaves
// elastic states alone, and books the energy it removes as dissipated.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <type_traits>

#include "core/parameters.hpp"
#include "models/fixed_corotated.hpp"
#include "models/registry.hpp"
#include "models/snow.hpp"
#include "support/random_matrices.hpp"

namespace mpmtb {
namespace snow_test {

using testing::RandomMatrix;

constexpr Real kE = 250, kNu = 0.3, kRho = 7;
constexpr Real kThetaC = 2.5e-2, kThetaS = 7.5e-3, kXi = 10;  // the paper's reference snow

std::map<std::string, Real> Elastic(Real E = kE) {
  return {{"E", E}, {"nu", kNu}, {"density", kRho}};
}

// A large deformation: F = I + 0.5 * random with det F >= 0.1.
template <int Dim>
Mat<Dim> LargeF(std::mt19937& gen) {
  for (;;) {
    const Mat<Dim> F = Mat<Dim>::Identity() + 0.5 * RandomMatrix<Dim>(gen);
    if (F.determinant() >= 0.1) return F;
  }
}

template <class D>
class SnowTest : public ::testing::Test {
 protected:
  static constexpr int Dim = D::value;
  Parameters params_{"materials.snow", Elastic()};
  Snow<Dim> snow_{params_};
  std::mt19937 gen_{77 + Dim};
  std::array<Real, 2> fresh() const {
    std::array<Real, 2> q{};
    snow_.initial_state(q.data());
    return q;
  }
};
using Dims = ::testing::Types<std::integral_constant<int, 1>, std::integral_constant<int, 2>,
                              std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(SnowTest, Dims);

TYPED_TEST(SnowTest, DefaultsAndState) {
  EXPECT_EQ(this->snow_.theta_c(), kThetaC);
  EXPECT_EQ(this->snow_.theta_s(), kThetaS);
  const auto q = this->fresh();
  EXPECT_EQ(q[0], 1) << "J_P starts at 1";
  EXPECT_EQ(q[1], 0) << "nothing dissipated at the start";
  EXPECT_EQ(this->snow_.state_names(), (std::vector<std::string>{"J_P", "dissipated"}));
}

// Repeated large deformations of the elastic part, as a sequence of steps.
TYPED_TEST(SnowTest, ReturnMapClampsAndKeepsTotalDeterminant) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->snow_;
  for (int path = 0; path < 20; ++path) {
    auto q = this->fresh();
    Mat<Dim> F = Mat<Dim>::Identity();
    for (int step = 0; step < 10; ++step) {
      const Mat<Dim> trial = LargeF<Dim>(this->gen_) * F;
      const Real J_total = trial.determinant() * q[0];
      F = trial;
      m.project(F, q.data(), 1e-3);
      // Singular values from Eigen (unsigned) and the sign from det: not inverted.
      const Vec<Dim> sigma = Eigen::JacobiSVD<Mat<Dim>>(F).singularValues();
      EXPECT_GT(F.determinant(), 0);
      EXPECT_GE(sigma.minCoeff(), 1 - kThetaC - 1e-12) << "F_E =\n" << F;
      EXPECT_LE(sigma.maxCoeff(), 1 + kThetaS + 1e-12) << "F_E =\n" << F;
      // The total deformation is kept: J = J_E J_P is what the trial step produced.
      EXPECT_NEAR(F.determinant() * q[0], J_total, 1e-12 * std::abs(J_total));
    }
  }
}

TYPED_TEST(SnowTest, ElasticTrialIsLeftUnchanged) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->snow_;
  for (int s = 0; s < 20; ++s) {
    // F = I + small random: singular values within 0.5 theta_s of 1.
    const Mat<Dim> F0 = Mat<Dim>::Identity() + 0.5 * kThetaS / Dim * RandomMatrix<Dim>(this->gen_);
    Mat<Dim> F = F0;
    auto q = this->fresh();
    q[0] = 0.9;  // some earlier plastic history
    m.project(F, q.data(), 1e-3);
    EXPECT_EQ(F, F0);
    EXPECT_EQ(q[0], 0.9);
    EXPECT_EQ(q[1], 0);
  }
}

// Lame parameters grow by exp(xi (1 - J_P)): compression (J_P < 1) hardens,
// stretching (J_P > 1) softens. The stress equals fixed-corotated with the
// scaled Young's modulus.
TYPED_TEST(SnowTest, HardeningInCompressionSofteningInStretch) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->snow_;
  const Mat<Dim> I = Mat<Dim>::Identity();
  auto compressed = this->fresh(), stretched = this->fresh();
  Mat<Dim> Fc = Real(0.8) * I, Fs = Real(1.2) * I;
  m.project(Fc, compressed.data(), 1e-3);
  m.project(Fs, stretched.data(), 1e-3);
  ASSERT_LT(compressed[0], 1);
  ASSERT_GT(stretched[0], 1);
  const auto q0 = this->fresh();
  EXPECT_GT(m.mu(compressed.data()), m.mu(q0.data()));
  EXPECT_GT(m.lambda(compressed.data()), m.lambda(q0.data()));
  EXPECT_LT(m.mu(stretched.data()), m.mu(q0.data()));
  for (const auto& q : {compressed, stretched}) {
    const Real h = std::exp(kXi * (1 - q[0]));
    Parameters scaled("materials.scaled", Elastic(h * kE));
    const FixedCorotated<Dim> reference(scaled);
    for (int s = 0; s < 5; ++s) {
      const Mat<Dim> F = I + 0.2 * RandomMatrix<Dim>(this->gen_);
      const Mat<Dim> P = m.P(F, q.data()), P_ref = reference.P(F, nullptr);
      EXPECT_LT((P - P_ref).norm(), 1e-12 * P_ref.norm()) << "J_P = " << q[0];
      EXPECT_NEAR(m.psi(F, q.data()), reference.psi(F, nullptr), 1e-12 * reference.psi(F, nullptr));
      EXPECT_LT((m.tau(F, q.data()) - P * F.transpose()).norm(), 1e-12 * (P.norm() + kE));
    }
  }
}

// The documented choice: each return map adds psi(trial; J_P old) - psi(F_E; J_P new)
// to the dissipated energy, so strain + dissipated is unchanged by it.
TYPED_TEST(SnowTest, DissipatedEnergyClosesTheBudget) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->snow_;
  for (int path = 0; path < 20; ++path) {
    auto q = this->fresh();
    Mat<Dim> F = Mat<Dim>::Identity();
    for (int step = 0; step < 10; ++step) {
      F = LargeF<Dim>(this->gen_) * F;
      const Real before = m.psi(F, q.data()) + m.dissipated(q.data());
      m.project(F, q.data(), 1e-3);
      const Real after = m.psi(F, q.data()) + m.dissipated(q.data());
      EXPECT_NEAR(after, before, 1e-12 * (std::abs(before) + kE));
    }
  }
}

// Under monotone loading every clamp moves each singular value towards 1 from
// one side, lowering |F_E - R_E| and |J_E - 1|. In stretch J_P grows (softer);
// in compression, for small steps, the energy released (first order in the
// step) outweighs the hardening (xi J_P psi / sigma times the step, smaller
// since psi is second order in theta_c). So the dissipated energy is >= 0 and
// never decreases: uniaxial and isotropic stretch and compression, strain
// increment 1e-3 per step, to 40 %.
TYPED_TEST(SnowTest, DissipationIsNonNegativeAndMonotoneUnderMonotoneLoading) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->snow_;
  const Mat<Dim> I = Mat<Dim>::Identity();
  Mat<Dim> uniaxial = Mat<Dim>::Zero();
  uniaxial(0, 0) = 1;
  for (const Mat<Dim>& direction : {uniaxial, I}) {
    for (Real sign : {1.0, -1.0}) {
      auto q = this->fresh();
      Mat<Dim> F = I;
      Real last = 0;
      bool yielded = false;
      for (int step = 0; step < 400; ++step) {
        F = (I + sign * 1e-3 * direction) * F;
        m.project(F, q.data(), 1e-3);
        EXPECT_GE(q[1], last) << "sign " << sign << ", step " << step;
        last = q[1];
        yielded = yielded || q[0] != 1;
      }
      EXPECT_TRUE(yielded);
      EXPECT_GT(q[1], 0) << "sign " << sign << ": yielding must dissipate";
    }
  }
}

// What the choice makes visible: the clamp is not derived from a dissipation
// potential and the hardening grows with compaction, so the return map can
// raise the stored energy. Then `dissipated` drops by exactly that rise
// instead of the total drifting. 1D: a sudden compression to 0.3 (J_P drops to
// 0.31, stiffness x e^6.9). 3D: stretch yield in one direction while the volume
// stays compressed (J_E drops further, the volumetric term grows).
TEST(SnowModel, ClampCanRaiseStoredEnergyAndTheBudgetStillCloses) {
  Parameters p1("materials.snow", Elastic()), p3("materials.snow", Elastic());
  const Snow<1> snow1(p1);
  const Snow<3> snow3(p3);
  auto check = [](const auto& m, auto F) {
    std::array<Real, 2> q{};
    m.initial_state(q.data());
    const Real psi_trial = m.psi(F, q.data());
    m.project(F, q.data(), 1e-3);
    const Real psi_new = m.psi(F, q.data());
    EXPECT_GT(psi_new, psi_trial);
    EXPECT_LT(q[1], 0);
    EXPECT_NEAR(q[1], psi_trial - psi_new, 1e-12 * psi_new);
  };
  check(snow1, Mat<1>(Mat<1>::Constant(0.3)));
  check(snow3, Mat<3>(Vec<3>(1.0175, 0.976, 0.976).asDiagonal()));
}

}  // namespace snow_test
}  // namespace mpmtb

namespace mpmtb {
namespace snow_test {

// The reported volume ratio is the total J = J_E J_P, not the elastic part.
TEST(SnowVolume, TotalJIncludesThePlasticPart) {
  Parameters p("materials.snow", {{"E", 250}, {"nu", 0.3}, {"density", 7}});
  const auto m = make_model<3>("snow", p);
  std::vector<Real> q(m->state_size());
  m->initial_state(q.data());
  Mat<3> F = 0.8 * Mat<3>::Identity();  // far outside the clamp: plastic compression
  const Real J_trial = F.determinant();
  Particles<3> P;
  P.state_size = m->state_size();
  P.add(Vec<3>::Zero(), Vec<3>::Zero(), 1, 1, 0);
  P.F[0] = F;
  std::copy(q.begin(), q.end(), P.state.begin());
  const std::vector<int> ids = {0};
  m->return_map(P, ids, 1e-3);
  EXPECT_LT(std::abs(P.F[0].determinant() - J_trial), 1) << "the clamp must act";
  EXPECT_GT(std::abs(P.F[0].determinant() - J_trial), 1e-3) << "the clamp must act";
  EXPECT_NEAR(m->total_J(P.F[0], P.state_of(0)), J_trial, 1e-12);
}

}  // namespace snow_test
}  // namespace mpmtb
