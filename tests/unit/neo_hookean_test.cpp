// Neo-Hookean model (REFERENCE.md, "Constitutive models") in 1, 2 and 3 dimensions:
// P = dpsi/dF, tau = P F^T, rest state, objectivity, small-strain limit, input checks.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <regex>
#include <string>
#include <type_traits>

#include "core/errors.hpp"
#include "core/parameters.hpp"
#include "core/types.hpp"
#include "models/neo_hookean.hpp"
#include "support/finite_difference.hpp"
#include "support/random_matrices.hpp"

namespace mpmtb {
namespace neo_hookean_test {

using testing::FiniteDifferenceP;
using testing::RandomF;
using testing::RandomMatrix;
using testing::RandomRotation;

constexpr Real kE = 250, kNu = 0.3, kRho = 7;
// Lame constants derived here, independently of the class under test.
constexpr Real kMu = kE / (2 * (1 + kNu));
constexpr Real kLambda = kE * kNu / ((1 + kNu) * (1 - 2 * kNu));

template <int Dim>
struct Fixture {
  Parameters params{"materials.test", {{"E", kE}, {"nu", kNu}, {"density", kRho}}};
  NeoHookean<Dim> model{params};
};

template <class D>
class NeoHookeanTest : public ::testing::Test {
 protected:
  static constexpr int Dim = D::value;
  Fixture<Dim> f_;
  std::mt19937 gen_{4711 + Dim};
};
using Dims = ::testing::Types<std::integral_constant<int, 1>, std::integral_constant<int, 2>,
                              std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(NeoHookeanTest, Dims);

// Through the virtual interface (energy_density / first_piola), as the solver sees it.
TYPED_TEST(NeoHookeanTest, StressIsEnergyGradient) {
  constexpr int Dim = TestFixture::Dim;
  const ConstitutiveModel<Dim>& m = this->f_.model;
  for (int s = 0; s < 20; ++s) {
    const Mat<Dim> F = RandomF<Dim>(this->gen_);
    const Mat<Dim> P_fd = FiniteDifferenceP<Dim>(m, F, nullptr);
    const Mat<Dim> P = m.first_piola(F, nullptr);
    EXPECT_LT((P - P_fd).norm(), 1e-6 * P.norm()) << "F =\n" << F << "\nP =\n" << P;
    EXPECT_EQ(P, this->f_.model.P(F, nullptr)) << "first_piola differs from P";
  }
}

TYPED_TEST(NeoHookeanTest, KirchhoffStressIsPFt) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->f_.model;
  for (int s = 0; s < 20; ++s) {
    const Mat<Dim> F = RandomF<Dim>(this->gen_);
    const Mat<Dim> tau = m.tau(F, nullptr), PFt = m.P(F, nullptr) * F.transpose();
    EXPECT_LT((tau - PFt).norm(), 1e-12 * (PFt.norm() + kE)) << "F =\n" << F;
  }
}

// Stresses and energy scale with E; "zero" means below 1e-12 E.
TYPED_TEST(NeoHookeanTest, RestStateAndRotationsAreStressFree) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->f_.model;
  const Mat<Dim> I = Mat<Dim>::Identity();
  EXPECT_LT(m.P(I, nullptr).norm(), 1e-12 * kE);
  EXPECT_LT(m.tau(I, nullptr).norm(), 1e-12 * kE);
  EXPECT_LT(std::abs(m.psi(I, nullptr)), 1e-12 * kE);
  for (int s = 0; s < 10; ++s) {
    const Mat<Dim> R = RandomRotation<Dim>(this->gen_);
    EXPECT_LT(m.P(R, nullptr).norm(), 1e-12 * kE) << "R =\n" << R;
    EXPECT_LT(m.tau(R, nullptr).norm(), 1e-12 * kE) << "R =\n" << R;
    EXPECT_LT(std::abs(m.psi(R, nullptr)), 1e-12 * kE) << "R =\n" << R;
  }
  // A stretch is not stress-free: guards against a model that returns zero everywhere.
  EXPECT_GT(m.P(1.1 * I, nullptr).norm(), 1e-2 * kE);
  EXPECT_GT(m.psi(1.1 * I, nullptr), 1e-4 * kE);
}

// Objectivity needs a rotation other than the identity: 2D and 3D only.
template <class D>
class NeoHookeanRotationTest : public NeoHookeanTest<D> {};
using RotationDims =
    ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(NeoHookeanRotationTest, RotationDims);

TYPED_TEST(NeoHookeanRotationTest, FrameIndifference) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->f_.model;
  for (int s = 0; s < 20; ++s) {
    const Mat<Dim> F = RandomF<Dim>(this->gen_), R = RandomRotation<Dim>(this->gen_);
    const Real psi = m.psi(F, nullptr);
    EXPECT_NEAR(m.psi(R * F, nullptr), psi, 1e-12 * (std::abs(psi) + kE));
    // P transforms as P(R F) = R P(F).
    const Mat<Dim> RP = R * m.P(F, nullptr);
    EXPECT_LT((m.P(R * F, nullptr) - RP).norm(), 1e-12 * (RP.norm() + kE));
  }
}

// At F = I + eps H, P = lambda tr(e) I + 2 mu e + O(eps^2) with e = eps H (H symmetric).
TYPED_TEST(NeoHookeanTest, SmallStrainLimitIsLinearElastic) {
  constexpr int Dim = TestFixture::Dim;
  const auto& m = this->f_.model;
  const Real eps = 1e-6;
  for (int s = 0; s < 10; ++s) {
    const Mat<Dim> A = RandomMatrix<Dim>(this->gen_);
    const Mat<Dim> e = eps * Real(0.5) * (A + A.transpose());
    const Mat<Dim> sigma = kLambda * e.trace() * Mat<Dim>::Identity() + 2 * kMu * e;
    const Mat<Dim> P = m.P(Mat<Dim>::Identity() + e, nullptr);
    EXPECT_LT((P - sigma).norm(), 1e-4 * sigma.norm()) << "P =\n" << P << "\nsigma =\n" << sigma;
  }
}

TYPED_TEST(NeoHookeanTest, ReportsDensityAndWaveSpeed) {
  const auto& m = this->f_.model;
  EXPECT_DOUBLE_EQ(m.density(), kRho);
  EXPECT_NEAR(m.wave_speed(), std::sqrt((kLambda + 2 * kMu) / kRho), 1e-12);
}

// Constructing the model from `values` must throw InputError naming `key` as a word.
void ExpectRejected(const std::map<std::string, Real>& values, const std::string& key) {
  SCOPED_TRACE("expected rejection naming '" + key + "'");
  Parameters p("materials.test", values);
  try {
    NeoHookean<2> model(p);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_TRUE(std::regex_search(e.what(), std::regex("\\b" + key + "\\b")))
        << "message: " << e.what();
  }
}

std::map<std::string, Real> Valid() {
  return {{"E", kE}, {"nu", kNu}, {"density", kRho}};
}

std::map<std::string, Real> With(const std::string& key, Real value) {
  auto v = Valid();
  v[key] = value;
  return v;
}

TEST(NeoHookeanParameters, ValidParametersAreAccepted) {
  Parameters p("materials.test", Valid());
  EXPECT_NO_THROW(NeoHookean<2> model(p));
  EXPECT_NO_THROW(p.reject_unknown());
  Parameters near_limits("materials.test", {{"E", 1e-3}, {"nu", 0.499}, {"density", 1e-3}});
  EXPECT_NO_THROW(NeoHookean<3> model(near_limits));
  Parameters negative_nu("materials.test", {{"E", 1}, {"nu", -0.999}, {"density", 1}});
  EXPECT_NO_THROW(NeoHookean<1> model(negative_nu));
}

TEST(NeoHookeanParameters, InvalidValuesAreRejectedByName) {
  ExpectRejected(With("E", 0), "E");
  ExpectRejected(With("E", -5), "E");
  ExpectRejected(With("nu", 0.5), "nu");
  ExpectRejected(With("nu", 0.7), "nu");
  ExpectRejected(With("nu", -1), "nu");
  ExpectRejected(With("nu", -1.5), "nu");
  ExpectRejected(With("density", 0), "density");
  ExpectRejected(With("density", -1), "density");
  ExpectRejected(With("E", std::nan("")), "E");
  auto missing = Valid();
  missing.erase("E");
  ExpectRejected(missing, "E");
}

TEST(NeoHookeanParameters, UnknownKeyIsRejected) {
  Parameters p("materials.test", With("youngs_modulus", 3));
  NeoHookean<2> model(p);  // the model itself ignores extra keys
  try {
    p.reject_unknown();
    ADD_FAILURE() << "no InputError for an unknown key";
  } catch (const InputError& e) {
    EXPECT_TRUE(std::regex_search(e.what(), std::regex("\\byoungs_modulus\\b"))) << e.what();
  }
}

}  // namespace neo_hookean_test
}  // namespace mpmtb
