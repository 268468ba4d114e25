// Basic numeric types shared by every part of the testbed.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <array>
#include <cstddef>

namespace mpmtb {

// Precision of every field. Verification needs double (the default); a
// `float` build (cmake -DMPMTB_REAL=float) is for throughput measurements.
#ifndef MPMTB_REAL
#define MPMTB_REAL double
#endif
using Real = MPMTB_REAL;

template <int Dim>
using Vec = Eigen::Matrix<Real, Dim, 1>;
template <int Dim>
using Mat = Eigen::Matrix<Real, Dim, Dim>;

using Vec3 = Eigen::Matrix<Real, 3, 1>;

// Loops shorter than this run on one thread: forking a team costs more than
// the work, and idle spinning threads slow down concurrent test processes.
constexpr long kParallelMinimum = 4096;

// Integer power usable in constant expressions (stencil sizes).
constexpr int ipow(int base, int exp) {
  return exp == 0 ? 1 : base * ipow(base, exp - 1);
}

// First Dim components of a 3-vector (scene files always give three).
template <int Dim>
Vec<Dim> head(const Vec3& v) {
  return v.template head<Dim>();
}

// Embed a Dim-vector in 3D, padding with zeros (diagnostic columns are 3D).
template <int Dim>
Vec3 to3(const Vec<Dim>& v) {
  Vec3 r = Vec3::Zero();
  r.template head<Dim>() = v;
  return r;
}

}  // namespace mpmtb
