// The suite's derived numbers on data with a known answer: observed and fitted
// orders of e = C h^p, the choice of the asymptotic range, Pareto fronts and
// the largest stable value of a sweep.
#include <gtest/gtest.h>

#include <cmath>

#include "suite/analysis.hpp"

namespace mpmtb::suite {
namespace suite_analysis_test {

std::vector<double> halving(double h0, int n) {
  std::vector<double> h;
  for (int k = 0; k < n; ++k) h.push_back(h0 / (1 << k));
  return h;
}

TEST(SuiteOrders, PowerLawGivesItsExponent) {
  const auto h = halving(0.5, 5);
  for (double p : {1.0, 2.0, 3.5}) {
    std::vector<double> e;
    for (double x : h) e.push_back(7 * std::pow(x, p));
    const auto obs = observed_orders(h, e);
    EXPECT_TRUE(std::isnan(obs[0]));
    for (std::size_t k = 1; k < h.size(); ++k) EXPECT_NEAR(obs[k], p, 1e-12);
    const auto fit = fit_order(h, e);
    EXPECT_NEAR(fit.order, p, 1e-12);
    EXPECT_EQ(fit.first, 0);  // one power law: every level is asymptotic
    EXPECT_EQ(fit.last, 4);
  }
}

TEST(SuiteOrders, PreAsymptoticCoarseLevelsAreLeftOut) {
  // e = h^2 + 5 h^4: the h^4 term dominates the coarse levels only (observed
  // orders 3.4, 2.8, 2.3, 2.1, 2.0).
  const auto h = halving(1.0, 6);
  std::vector<double> e;
  for (double x : h) e.push_back(x * x + 5 * std::pow(x, 4));
  const auto fit = fit_order(h, e);
  EXPECT_GT(fit.first, 0);
  EXPECT_EQ(fit.last, 5);
  EXPECT_NEAR(fit.order, 2.0, 0.15);
}

TEST(SuiteOrders, PlateauShowsAsLowOrderNotAveragedAway) {
  // Second order down to a floor of 4e-3 (e.g. a model error) reached at
  // h = 1/16: the fit over the fine end must report the stall.
  const auto h = halving(1.0, 7);
  std::vector<double> e;
  for (double x : h) e.push_back(std::max(x * x, 4e-3) + 4e-3);
  const auto fit = fit_order(h, e);
  EXPECT_LT(std::abs(fit.order), 0.3);
  EXPECT_GE(fit.first, 4);
}

TEST(SuiteOrders, MissingLevelsBreakTheRun) {
  const auto h = halving(1.0, 5);
  std::vector<double> e;
  for (double x : h) e.push_back(x * x);
  e[4] = kNaN;  // the finest run was unstable
  auto fit = fit_order(h, e);
  EXPECT_EQ(fit.last, 3);
  EXPECT_NEAR(fit.order, 2.0, 1e-12);
  e[2] = kNaN;  // a gap: only the contiguous finest run (levels 3) remains
  fit = fit_order(h, e);
  EXPECT_TRUE(std::isnan(fit.order));
  const auto obs = observed_orders(h, e);
  EXPECT_TRUE(std::isnan(obs[2]) && std::isnan(obs[3]) && std::isnan(obs[4]));
}

TEST(SuitePareto, FrontIsTheNonDominatedSet) {
  // cost, error: (1, 10) (2, 5) (3, 6) (4, 1) (2, 5) duplicate, (nan, 0)
  const std::vector<double> cost = {1, 2, 3, 4, 2, kNaN};
  const std::vector<double> err = {10, 5, 6, 1, 5, 0};
  const auto f = pareto_front(cost, err);
  EXPECT_TRUE(f[0]);
  EXPECT_TRUE(f[1]);
  EXPECT_FALSE(f[2]);  // (2, 5) is cheaper and more accurate
  EXPECT_TRUE(f[3]);
  EXPECT_TRUE(f[4]);   // ties dominate nothing
  EXPECT_FALSE(f[5]);  // no cost: not a point
}

TEST(SuitePareto, ErrorsEqualToRoundOffAreOneError) {
  // The same scheme two ways (MLS-MPM = APIC with the hat): the slower of two
  // runs whose errors differ by round-off is dominated, whichever is smaller.
  const std::vector<double> cost = {1, 2, 3};
  const std::vector<double> err = {0.5, 0.5 * (1 - 1e-13), 0.5 * (1 - 1e-6)};
  const auto f = pareto_front(cost, err);
  EXPECT_TRUE(f[0]);
  EXPECT_FALSE(f[1]);
  EXPECT_TRUE(f[2]);  // a real improvement, however small, counts
}

TEST(SuiteStability, LargestStableStopsAtTheFirstFailure) {
  const std::vector<double> cfl = {0.5, 1.0, 1.5, 2.0};
  auto r = largest_stable(cfl, {true, true, false, true});
  EXPECT_EQ(r.stable, 1.0);
  EXPECT_EQ(r.first_unstable, 1.5);
  EXPECT_EQ(r.first_unstable_index, 2);
  r = largest_stable(cfl, {true, true, true, true});
  EXPECT_EQ(r.stable, 2.0);
  EXPECT_TRUE(std::isnan(r.first_unstable));
  r = largest_stable(cfl, {false, true, true, true});
  EXPECT_TRUE(std::isnan(r.stable));
}

}  // namespace suite_analysis_test
}  // namespace mpmtb::suite
