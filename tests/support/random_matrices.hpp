// Random matrices for the model tests: deformation gradients and rotations.
#pragma once

#include <Eigen/Geometry>
#include <numbers>
#include <random>

#include "core/types.hpp"

namespace mpmtb::testing {

// Entries uniform in [-1, 1].
template <int Dim>
Mat<Dim> RandomMatrix(std::mt19937& gen) {
  std::uniform_real_distribution<Real> u(-1, 1);
  Mat<Dim> A;
  for (int i = 0; i < Dim; ++i)
    for (int j = 0; j < Dim; ++j) A(i, j) = u(gen);
  return A;
}

// F = I + amplitude * random with det F >= min_det (models may be undefined
// at J <= 0), and |det F - 1| > away_from_one when a test must not straddle J = 1.
template <int Dim>
Mat<Dim> RandomF(std::mt19937& gen, Real amplitude = 0.3, Real min_det = 0.2,
                 Real away_from_one = 0) {
  for (;;) {
    const Mat<Dim> F = Mat<Dim>::Identity() + amplitude * RandomMatrix<Dim>(gen);
    const Real J = F.determinant();
    if (J >= min_det && std::abs(J - 1) > away_from_one) return F;
  }
}

// A proper rotation by an angle uniform in [-max_angle, max_angle] (identity in 1D).
template <int Dim>
Mat<Dim> RandomRotation(std::mt19937& gen, Real max_angle = std::numbers::pi) {
  std::uniform_real_distribution<Real> angle(-max_angle, max_angle);
  if constexpr (Dim == 1) {
    return Mat<Dim>::Identity();
  } else if constexpr (Dim == 2) {
    return Eigen::Rotation2D<Real>(angle(gen)).toRotationMatrix();
  } else {
    const Vec<3> axis = RandomMatrix<3>(gen).col(0).normalized();
    return Eigen::AngleAxis<Real>(angle(gen), axis).toRotationMatrix();
  }
}

}  // namespace mpmtb::testing
