// The stress pass's vectorised logarithm (core/batch_log.hpp) against the C
// library's long-double logl, and the stresses that use it against V0 P F^T.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <type_traits>
#include <vector>

#include "core/batch_exp.hpp"
#include "core/batch_log.hpp"
#include "core/parameters.hpp"
#include "core/particles.hpp"
#include "models/damage.hpp"
#include "models/neo_hookean.hpp"

namespace batch_log_test {
using namespace mpmtb;

// |y - ln x| in units in the last place of ln x, against logl.
double ulps(Real x, Real y) {
  const long double exact = logl(static_cast<long double>(x));
  const Real r = static_cast<Real>(exact);
  const Real ulp = std::nextafter(std::abs(r), std::numeric_limits<Real>::infinity()) - std::abs(r);
  return static_cast<double>(std::abs(static_cast<long double>(y) - exact) / ulp);
}

std::vector<Real> batch(const std::vector<Real>& x) {
  std::vector<Real> y(x.size());
  batch_log(x.data(), y.data(), static_cast<int>(x.size()));
  return y;
}

TEST(BatchLog, WithinTwoUlpOverTheWholeRangeAndNearOne) {
  std::vector<Real> x;
  std::mt19937_64 rng(7);
  const double lo = std::log(std::numeric_limits<Real>::min()),
               hi = std::log(std::numeric_limits<Real>::max());
  std::uniform_real_distribution<double> exponent(lo, hi), near_one(-1e-3, 1e-3);
  for (int k = 0; k < 20000; ++k) x.push_back(static_cast<Real>(std::exp(exponent(rng))));
  for (int k = 0; k < 20000; ++k) x.push_back(static_cast<Real>(1 + near_one(rng)));
  // Around the reduction's switch at sqrt(2), and the neighbours of 1.
  Real s = Real(1.4142135623730950488), u = 1, d = 1;
  for (int k = 0; k < 64; ++k) {
    x.push_back(s), s = std::nextafter(s, Real(2));
    x.push_back(u = std::nextafter(u, Real(2)));
    x.push_back(d = std::nextafter(d, Real(0)));
  }
  const std::vector<Real> y = batch(x);
  double worst = 0;
  for (std::size_t k = 0; k < x.size(); ++k) worst = std::max(worst, ulps(x[k], y[k]));
  EXPECT_LE(worst, 2.5) << "measured 1.97 ulp in double and float";
  EXPECT_EQ(batch({Real(1)})[0], Real(0));
}

TEST(BatchLog, ValuesOutsideThePositiveNormalsGetTheLibraryResult) {
  const Real inf = std::numeric_limits<Real>::infinity();
  const std::vector<Real> x = {0,
                               -Real(0),
                               -1,
                               inf,
                               -inf,
                               std::numeric_limits<Real>::quiet_NaN(),
                               std::numeric_limits<Real>::denorm_min(),
                               Real(2.5)};
  const std::vector<Real> y = batch(x);
  for (std::size_t k = 0; k < x.size(); ++k) {
    const Real expected = std::log(x[k]);
    if (std::isnan(expected)) {
      EXPECT_TRUE(std::isnan(y[k])) << x[k];
    } else {
      EXPECT_EQ(y[k], expected) << x[k];
    }
  }
}

TEST(BatchLog, EveryLengthGivesTheSameValuesAsOneByOne) {
  std::vector<Real> x;
  for (int k = 0; k < 19; ++k) x.push_back(Real(0.37) + Real(0.61) * k);
  for (int n = 1; n <= 19; ++n) {
    std::vector<Real> y(n);
    batch_log(x.data(), y.data(), n);
    for (int k = 0; k < n; ++k) {
      Real one;
      batch_log(&x[k], &one, 1);
      EXPECT_EQ(y[k], one) << "n = " << n << ", k = " << k;
    }
  }
}

// The batched stress pass (ModelBase::kirchhoff_times_volume), for more
// particles than two batches of 64, in reverse order:
// - is V0 P F^T of the model's own first Piola stress;
// - takes these models a vector register of particles at a time
//   (core/lanes.hpp), and gives each particle the bits of the model's formula
//   for one particle, given the same ln J (and J^(2/3) for damage).
// Compressed and stretched particles (J from 0.5 to 1.7: damage's tension
// split) and damaged ones (d from 0 to 0.9).
template <class Model>
void expect_stress_pass_is_the_models_formula(Parameters params) {
  const Model model(params);
  Particles<3> P;
  P.state_size = model.state_size();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<Real> u(-0.25, 0.25);
  const int n = 150;
  std::vector<int> ids;
  for (int p = 0; p < n; ++p) {
    P.add(Vec<3>::Zero(), Vec<3>::Zero(), 1, Real(0.5) + Real(p) / n, 0);
    P.F[p] *= Real(0.8) + Real(0.4) * p / n;
    for (int i = 0; i < 9; ++i) P.F[p](i / 3, i % 3) += u(rng);
    if (P.state_size) model.initial_state(P.state_of(p));
    if constexpr (std::is_same_v<Model, Damage<3>>)
      P.state_of(p)[Damage<3>::kDamage] = Real(0.9) * (p % 10) / 9;
    ids.push_back(n - 1 - p);
  }
  std::vector<Mat<3>> tauV(n);
  model.kirchhoff_times_volume(P, ids, tauV);
  for (int p = 0; p < n; ++p) {
    const Mat<3> from_P = P.V0[p] * model.first_piola(P.F[p], P.state_of(p)) * P.F[p].transpose();
    EXPECT_LE((tauV[p] - from_P).norm(), 1e-12 * from_P.norm()) << "particle " << p;
    Real J = P.F[p].determinant(), logJ;
    batch_log(&J, &logJ, 1);
    Mat<3> expected;
    if constexpr (std::is_same_v<Model, Damage<3>>) {
      Real exponent = Damage<3>::kPowerOfLog * logJ, s;
      batch_exp(&exponent, &s, 1);
      model.tau_times_volume_given_log_and_power(P.F[p], logJ, s, P.state_of(p), P.V0[p], expected);
    } else {
      expected = P.V0[p] * model.tau_given_log(P.F[p], logJ, P.state_of(p));
    }
    EXPECT_TRUE(tauV[p] == expected) << "particle " << p << ", J = " << J << ":\n"
                                     << tauV[p] << "\nexpected\n"
                                     << expected;
  }
}

TEST(BatchLog, NeoHookeanStressPassIsTheModelsFormula) {
  expect_stress_pass_is_the_models_formula<NeoHookean<3>>(
      Parameters("materials.test", {{"E", 1e4}, {"nu", 0.3}, {"density", 1}}));
}

TEST(BatchLog, DamageStressPassIsTheModelsFormula) {
  expect_stress_pass_is_the_models_formula<Damage<3>>(
      Parameters("materials.test", {{"E", 1e4}, {"nu", 0.3}, {"density", 1}, {"sigma_crit", 100}}));
}

}  // namespace batch_log_test
