// The numbers a suite derives from its runs: observed and fitted convergence
// orders, the Pareto front of cost against error, the largest stable value of
// a swept parameter. Pure functions, so that they are tested on their own.
#pragma once

#include <limits>
#include <vector>

namespace mpmtb::suite {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Observed order between consecutive levels (deal.II step-7 style):
// p_k = log(e_{k-1}/e_k) / log(h_{k-1}/h_k), which is log2(e_{k-1}/e_k) when h
// halves. p_0 and any p_k next to a missing error (NaN or <= 0) are NaN.
std::vector<double> observed_orders(const std::vector<double>& h, const std::vector<double>& e);

// Least-squares order over the asymptotic range. The range is chosen from the
// finest level down: it starts with the finest three levels that have an
// error (two if only two exist) and grows towards coarser levels, one at a
// time, while the next pair's observed order stays within
// max(0.3, 0.15 |p|) of the slope fitted so far (p). Pre-asymptotic coarse
// levels are left out; a plateau or a blow-up at the fine end shows as a low
// or negative order instead of being averaged away.
struct OrderFit {
  double order = kNaN;
  int first = -1, last = -1;  // level indices of the range, inclusive
};
OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& e);

// Least-squares slope of log y against log x.
double log_slope(const std::vector<double>& x, const std::vector<double>& y);

// true for the points no other point beats in both cost and error (lower is
// better in each; NaN points are never on the front). Errors within a relative
// kErrorTie of each other count as equal (round-off of one scheme reached two ways).
inline constexpr double kErrorTie = 1e-9;
std::vector<bool> pareto_front(const std::vector<double>& cost, const std::vector<double>& error);

// For values sorted ascending with a stable flag each: the largest value below
// which every tried value was stable, and the first value that was not.
struct StableRange {
  double stable = kNaN;          // NaN when even the smallest failed
  double first_unstable = kNaN;  // NaN when none failed
  int first_unstable_index = -1;
};
StableRange largest_stable(const std::vector<double>& values, const std::vector<bool>& ok);

}  // namespace mpmtb::suite
