// Signed SVD and polar decomposition (models/polar.hpp) in 2D and 3D:
// reconstruction to round-off, proper rotations, the sign of det F in the last
// singular value, symmetric S, and the closest-rotation property of R, for
// random, nearly singular, repeated-singular-value and reflected matrices.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "models/polar.hpp"
#include "support/random_matrices.hpp"

namespace mpmtb {
namespace polar_test {

using testing::RandomMatrix;
using testing::RandomRotation;

constexpr Real kTol = 1e-12;

template <int Dim>
Mat<Dim> Reflection() {
  Mat<Dim> M = Mat<Dim>::Identity();
  M(Dim - 1, Dim - 1) = -1;
  return M;
}

// The test matrices, each with a label.
template <int Dim>
std::vector<std::pair<std::string, Mat<Dim>>> TestMatrices(std::mt19937& gen) {
  std::vector<std::pair<std::string, Mat<Dim>>> out;
  for (int s = 0; s < 20; ++s) {
    out.push_back({"random", RandomMatrix<Dim>(gen)});
    out.push_back({"near identity", Mat<Dim>::Identity() + 0.3 * RandomMatrix<Dim>(gen)});
    Vec<Dim> sigma = Vec<Dim>::LinSpaced(Dim, 2, 1);
    sigma(Dim - 1) = 1e-10;
    const Mat<Dim> Q1 = RandomRotation<Dim>(gen), Q2 = RandomRotation<Dim>(gen);
    out.push_back({"nearly singular", Q1 * sigma.asDiagonal() * Q2});
    out.push_back({"nearly singular, reflected", Q1 * sigma.asDiagonal() * Reflection<Dim>() * Q2});
    out.push_back({"rotation times 2 I", Q1 * (2 * Mat<Dim>::Identity())});
    out.push_back({"reflected rotation times 2 I", 2 * Q1 * Reflection<Dim>()});
    Mat<Dim> A = RandomMatrix<Dim>(gen);
    if (A.determinant() > 0) A.col(0) *= -1;
    out.push_back({"reflected (det < 0)", A});
    if constexpr (Dim == 3) {
      out.push_back({"two equal singular values", Q1 * Vec<3>(3, 1, 1).asDiagonal() * Q2});
    }
  }
  out.push_back({"identity", Mat<Dim>::Identity()});
  out.push_back({"zero", Mat<Dim>::Zero()});
  out.push_back({"reflection", Reflection<Dim>()});
  return out;
}

template <int Dim>
void ExpectRotation(const Mat<Dim>& R, const std::string& what) {
  EXPECT_LT((R.transpose() * R - Mat<Dim>::Identity()).norm(), kTol) << what << " =\n" << R;
  EXPECT_NEAR(R.determinant(), 1, kTol) << what << " =\n" << R;
}

template <class D>
class PolarTest : public ::testing::Test {
 protected:
  static constexpr int Dim = D::value;
  std::mt19937 gen_{2024 + Dim};
};
using Dims = ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(PolarTest, Dims);

TYPED_TEST(PolarTest, SignedSvdReconstructsWithRotations) {
  constexpr int Dim = TestFixture::Dim;
  for (const auto& [label, F] : TestMatrices<Dim>(this->gen_)) {
    SCOPED_TRACE(label);
    const SignedSvd<Dim> svd = signed_svd<Dim>(F);
    const Mat<Dim> back = svd.U * svd.sigma.asDiagonal() * svd.V.transpose();
    EXPECT_LE((back - F).norm(), kTol * F.norm()) << "F =\n" << F;
    ExpectRotation<Dim>(svd.U, "U");
    ExpectRotation<Dim>(svd.V, "V");
    // Magnitudes are the singular values (compared with Eigen's, sorted descending).
    const Vec<Dim> reference = Eigen::JacobiSVD<Mat<Dim>>(F).singularValues();
    EXPECT_LE((svd.sigma.cwiseAbs() - reference).norm(), kTol * (F.norm() + 1));
    for (int i = 0; i + 1 < Dim; ++i) {
      EXPECT_GE(svd.sigma(i), 0);
      EXPECT_GE(svd.sigma(i), std::abs(svd.sigma(i + 1)) - kTol * F.norm());
    }
    // The sign of det F is carried by the last singular value.
    const Real det = F.determinant();
    if (std::abs(det) > 1e-6) {
      EXPECT_EQ(svd.sigma(Dim - 1) < 0, det < 0) << "det F = " << det;
    }
  }
}

// The singular values alone (the return maps' elastic test) are signed_svd's own,
// bit for bit, and their squares the eigenvalues of F^T F.
TYPED_TEST(PolarTest, SingularValuesAloneAreTheSvdsBitForBit) {
  constexpr int Dim = TestFixture::Dim;
  auto matrices = TestMatrices<Dim>(this->gen_);
  // Reflection parts of round-off size (1e-17, whose square is below 1e-30: the
  // state of most particles of a resting snow pile) and near underflow.
  for (const Real tiny : {Real(1e-17), Real(3e-160)}) {
    Mat<Dim> F = 2 * Mat<Dim>::Identity();
    F(0, 1) = tiny;
    matrices.push_back({"2 I with a tiny shear", F});
  }
  for (const auto& [label, F] : matrices) {
    SCOPED_TRACE(label);
    const Vec<Dim> sigma = signed_singular_values<Dim>(F);
    const Vec<Dim> from_svd = signed_svd<Dim>(F).sigma;
    for (int a = 0; a < Dim; ++a) EXPECT_EQ(sigma(a), from_svd(a));
    Eigen::SelfAdjointEigenSolver<Mat<Dim>> eig(F.transpose() * F);
    Vec<Dim> squares = sigma.cwiseAbs2();
    std::sort(squares.data(), squares.data() + Dim);
    EXPECT_LT((squares - eig.eigenvalues()).norm(), kTol * (1 + F.squaredNorm()));
  }
}

TYPED_TEST(PolarTest, PolarDecompositionIsRotationTimesSymmetric) {
  constexpr int Dim = TestFixture::Dim;
  for (const auto& [label, F] : TestMatrices<Dim>(this->gen_)) {
    SCOPED_TRACE(label);
    const PolarDecomposition<Dim> pd = polar<Dim>(F);
    EXPECT_LE((pd.R * pd.S - F).norm(), kTol * F.norm()) << "F =\n" << F;
    ExpectRotation<Dim>(pd.R, "R");
    EXPECT_LE((pd.S - pd.S.transpose()).norm(), kTol * F.norm());
    EXPECT_EQ(pd.R, polar_rotation<Dim>(F));
    // For det F > 0 (not near singular) S is the positive definite stretch.
    if (F.determinant() > 1e-6 * std::pow(F.norm(), Dim)) {
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat<Dim>>(pd.S).eigenvalues().minCoeff(), 0);
    }
    // Same R as from the signed SVD, R = U V^T (unique unless F is singular or
    // has two singular values of opposite sign and equal magnitude).
    const SignedSvd<Dim> svd = signed_svd<Dim>(F);
    const Vec<Dim> s = svd.sigma;
    if (std::abs(s(Dim - 1)) > 1e-6 && s(Dim - 2) + s(Dim - 1) > 1e-6) {
      EXPECT_LE((svd.U * svd.V.transpose() - pd.R).norm(), 1e-9) << "F =\n" << F;
    }
  }
}

// R is the rotation closest to F (Frobenius norm), also for det F < 0.
TYPED_TEST(PolarTest, RotationIsClosestToF) {
  constexpr int Dim = TestFixture::Dim;
  for (const auto& [label, F] : TestMatrices<Dim>(this->gen_)) {
    SCOPED_TRACE(label);
    const Mat<Dim> R = polar_rotation<Dim>(F);
    const Real best = (F - R).norm();
    for (int t = 0; t < 20; ++t) {
      const Mat<Dim> Q = R * RandomRotation<Dim>(this->gen_, 0.3);
      EXPECT_GE((F - Q).norm(), best - kTol * (F.norm() + 1)) << "F =\n" << F;
    }
  }
}

TYPED_TEST(PolarTest, ExactRotationAndScaledRotation) {
  constexpr int Dim = TestFixture::Dim;
  for (int s = 0; s < 20; ++s) {
    const Mat<Dim> Q = RandomRotation<Dim>(this->gen_);
    const PolarDecomposition<Dim> pd = polar<Dim>(Real(2) * Q);
    EXPECT_LE((pd.R - Q).norm(), kTol);
    EXPECT_LE((pd.S - 2 * Mat<Dim>::Identity()).norm(), kTol);
  }
}

// cof(F) = J F^-T and d det(F)/dF = cof(F), including singular F.
TYPED_TEST(PolarTest, CofactorIsDeterminantGradient) {
  constexpr int Dim = TestFixture::Dim;
  for (const auto& [label, F] : TestMatrices<Dim>(this->gen_)) {
    SCOPED_TRACE(label);
    const Mat<Dim> C = cofactor<Dim>(F);
    const Real h = 1e-6;
    Mat<Dim> fd;
    for (int i = 0; i < Dim; ++i) {
      for (int j = 0; j < Dim; ++j) {
        Mat<Dim> Fp = F, Fm = F;
        Fp(i, j) += h;
        Fm(i, j) -= h;
        fd(i, j) = (Fp.determinant() - Fm.determinant()) / (2 * h);
      }
    }
    EXPECT_LE((C - fd).norm(), 1e-8 * (C.norm() + 1));
    EXPECT_LE((F.transpose() * C - F.determinant() * Mat<Dim>::Identity()).norm(),
              kTol * (std::pow(F.norm(), Dim) + 1));
  }
}

TEST(Polar1D, SignGoesIntoTheSingularValue) {
  for (Real f : {2.0, 0.5, -0.7, 1e-10, -1e-10}) {
    const Mat<1> F = Mat<1>::Constant(f);
    const SignedSvd<1> svd = signed_svd<1>(F);
    EXPECT_EQ(svd.U(0, 0), 1);
    EXPECT_EQ(svd.V(0, 0), 1);
    EXPECT_EQ(svd.sigma(0), f);
    const PolarDecomposition<1> pd = polar<1>(F);
    EXPECT_EQ(pd.R(0, 0), 1);
    EXPECT_EQ(pd.S(0, 0), f);
  }
}

}  // namespace polar_test
}  // namespace mpmtb
