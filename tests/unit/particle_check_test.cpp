// G2P's failure detection (core/particle_check.hpp) against each particle's
// own values: the J range and largest squared speed of the particles, the first
// particle with a non-finite value and the first outside the domain box, the
// same whether the particles come in one piece or in chunks.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "core/particle_check.hpp"

namespace mpmtb {
namespace {

template <int Dim>
Particles<Dim> random_particles(int n, std::mt19937& rng) {
  std::uniform_real_distribution<Real> inside(0.1, 0.9), speed(-2, 2), strain(-0.2, 0.2);
  Particles<Dim> P;
  for (int p = 0; p < n; ++p) {
    Vec<Dim> x, v;
    for (int a = 0; a < Dim; ++a) x[a] = inside(rng), v[a] = speed(rng);
    P.add(x, v, 1, 1, 0);
    for (int i = 0; i < Dim; ++i)
      for (int j = 0; j < Dim; ++j) P.F[p](i, j) += strain(rng);
  }
  return P;
}

template <int Dim>
void expect_same(const ParticleCheck<Dim>& a, const ParticleCheck<Dim>& b) {
  EXPECT_EQ(a.J_min(), b.J_min());
  EXPECT_EQ(a.J_max(), b.J_max());
  EXPECT_EQ(a.v2_max(), b.v2_max());
  EXPECT_EQ(a.first_non_finite(), b.first_non_finite());
  EXPECT_EQ(a.first_outside(), b.first_outside());
}

template <int Dim>
void check_dimension() {
  std::mt19937 rng(Dim);
  constexpr int n = 300;
  Particles<Dim> P = random_particles<Dim>(n, rng);
  const Vec<Dim> lo = Vec<Dim>::Zero(), hi = Vec<Dim>::Ones();
  const Real nan = std::numeric_limits<Real>::quiet_NaN();
  const Real inf = std::numeric_limits<Real>::infinity();
  P.x[40][Dim - 1] = 1.5;     // outside
  P.x[25][0] = -0.25;         // outside, first
  P.F[90](0, Dim - 1) = nan;  // non-finite J
  P.v[70][0] = inf;           // non-finite speed, first
  P.x[200][0] = nan;          // non-finite position (also outside)
  ParticleCheck<Dim> whole(lo, hi, n);
  whole.add(P, 0, n);
  // Each particle's own values, NaN never taken into a min or max.
  Real J_min = inf, J_max = -inf, v2_max = 0;
  for (int p = 0; p < n; ++p) {
    const Real J = P.F[p].determinant(), v2 = P.v[p].squaredNorm();
    if (!std::isnan(J)) J_min = std::min(J_min, J), J_max = std::max(J_max, J);
    if (!std::isnan(v2)) v2_max = std::max(v2_max, v2);
  }
  EXPECT_EQ(whole.J_min(), J_min);
  EXPECT_EQ(whole.J_max(), J_max);
  EXPECT_EQ(whole.v2_max(), inf);  // particle 70's
  EXPECT_EQ(whole.first_non_finite(), 70);
  EXPECT_EQ(whole.first_outside(), 25);
  // In chunks of any size, in any order of the chunks: the same.
  for (int chunk : {1, 7, 128}) {
    ParticleCheck<Dim> pieces(lo, hi, n);
    for (int first = (n - 1) / chunk * chunk; first >= 0; first -= chunk)
      pieces.add(P, first, std::min(chunk, n - first));
    expect_same(whole, pieces);
  }
  // Without the flagged particles: nothing reported.
  P.x[40][Dim - 1] = P.x[25][0] = 0.5;
  P.F[90](0, Dim - 1) = 0, P.v[70][0] = 0, P.x[200][0] = 0.5;
  ParticleCheck<Dim> clean(lo, hi, n);
  clean.add(P, 0, n);
  EXPECT_EQ(clean.first_non_finite(), n);
  EXPECT_EQ(clean.first_outside(), n);
  EXPECT_LT(clean.v2_max(), inf);
  // A position on the box's faces is inside (the closed box).
  P.x[10] = hi, P.x[11] = lo;
  ParticleCheck<Dim> faces(lo, hi, n);
  faces.add(P, 0, n);
  EXPECT_EQ(faces.first_outside(), n);
}

TEST(ParticleCheck, ReportsWhatEachParticleGives1D) {
  check_dimension<1>();
}
TEST(ParticleCheck, ReportsWhatEachParticleGives2D) {
  check_dimension<2>();
}
TEST(ParticleCheck, ReportsWhatEachParticleGives3D) {
  check_dimension<3>();
}

}  // namespace
}  // namespace mpmtb
