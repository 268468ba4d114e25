#include "analysis.hpp"

#include <algorithm>
#include <cmath>

namespace mpmtb::suite {
namespace {

bool usable(double e) {
  return std::isfinite(e) && e > 0;
}

}  // namespace

std::vector<double> observed_orders(const std::vector<double>& h, const std::vector<double>& e) {
  std::vector<double> p(e.size(), kNaN);
  for (std::size_t k = 1; k < e.size(); ++k) {
    if (usable(e[k - 1]) && usable(e[k]) && h[k - 1] > 0 && h[k] > 0 && h[k - 1] != h[k]) {
      p[k] = std::log(e[k - 1] / e[k]) / std::log(h[k - 1] / h[k]);
    }
  }
  return p;
}

double log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = x.size();
  if (n < 2 || y.size() != n) return kNaN;
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) {
    mx += std::log(x[i]) / n;
    my += std::log(y[i]) / n;
  }
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = std::log(x[i]) - mx;
    sxy += dx * (std::log(y[i]) - my);
    sxx += dx * dx;
  }
  return sxx > 0 ? sxy / sxx : kNaN;
}

OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& e) {
  // The contiguous run of levels with an error that ends at the finest such level.
  int last = static_cast<int>(e.size()) - 1;
  while (last >= 0 && !usable(e[last])) --last;
  int first_usable = last;
  while (first_usable > 0 && usable(e[first_usable - 1])) --first_usable;
  if (last < 1 || last - first_usable < 1) return {};
  const auto slope = [&](int a, int b) {
    return log_slope({h.begin() + a, h.begin() + b + 1}, {e.begin() + a, e.begin() + b + 1});
  };
  int first = std::max(first_usable, last - 2);
  double p = slope(first, last);
  const auto orders = observed_orders(h, e);
  while (first > first_usable) {
    const double next = orders[first];  // the pair (first - 1, first)
    if (!(std::abs(next - p) <= std::max(0.3, 0.15 * std::abs(p)))) break;
    --first;
    p = slope(first, last);
  }
  return {p, first, last};
}

std::vector<bool> pareto_front(const std::vector<double>& cost, const std::vector<double>& error) {
  const std::size_t n = cost.size();
  std::vector<bool> front(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(cost[i]) || !std::isfinite(error[i])) continue;
    bool dominated = false;
    for (std::size_t j = 0; j < n && !dominated; ++j) {
      if (j == i || !std::isfinite(cost[j]) || !std::isfinite(error[j])) continue;
      // Errors within kErrorTie of each other are one error: the same scheme
      // reached by two routes (MLS-MPM and APIC with the hat, PolyPIC's linear
      // modes) differs by round-off, and the slower of the two is not on the front.
      const double tie = kErrorTie * std::max(std::abs(error[i]), std::abs(error[j]));
      const bool no_worse = error[j] <= error[i] + tie;
      const bool better = error[j] < error[i] - tie;
      dominated = cost[j] <= cost[i] && no_worse && (cost[j] < cost[i] || better);
    }
    front[i] = !dominated;
  }
  return front;
}

StableRange largest_stable(const std::vector<double>& values, const std::vector<bool>& ok) {
  StableRange r;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!ok[i]) {
      r.first_unstable = values[i];
      r.first_unstable_index = static_cast<int>(i);
      return r;
    }
    r.stable = values[i];
  }
  return r;
}

}  // namespace mpmtb::suite
