#include "shard.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numeric>
#include <set>

#include "core/errors.hpp"
#include "memory.hpp"
#include "setup.hpp"

namespace mpmtb::suite {
namespace {

// A whole positive number, all of `text` (no sign, no spaces, no suffix).
std::optional<int> whole_number(std::string_view text) {
  int v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return v;
}

// Nodes per axis of a kernel's stencil; a kernel not listed counts as quadratic
// (the estimate only balances shards, it never decides a result).
double stencil_width(const std::string& kernel) {
  if (kernel == "linear") return 2;
  if (kernel == "cubic") return 4;
  return 3;
}

}  // namespace

Shard parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  const auto k = whole_number(std::string_view(text).substr(0, slash));
  const auto n = slash == std::string::npos
                     ? std::nullopt
                     : whole_number(std::string_view(text).substr(slash + 1));
  if (!k || !n) {
    throw InputError(fmt::format(
        "--shard '{}': expected K/N, two whole numbers with 1 <= K <= N (e.g. 2/8)", text));
  }
  if (*n < 1 || *k < 1 || *k > *n) {
    throw InputError(
        fmt::format("--shard '{}': K/N needs 1 <= K <= N (given K = {}, N = {})", text, *k, *n));
  }
  return {*k, *n};
}

std::vector<int> assign_shards(const std::vector<ShardItem>& items, int count) {
  if (count < 1) throw InputError(fmt::format("shard count {}: must be >= 1", count));
  std::vector<std::size_t> order(items.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (items[a].cost != items[b].cost) return items[a].cost > items[b].cost;
    return items[a].id < items[b].id;
  });
  for (std::size_t i = 1; i < order.size(); ++i) {
    // Equal ids would make the assignment depend on the list's order.
    if (items[order[i]].id == items[order[i - 1]].id) {
      throw std::logic_error(fmt::format("shards: run id '{}' appears twice", items[order[i]].id));
    }
  }
  // The least-loaded shard, lowest number first among equals: (load, shard).
  std::set<std::pair<double, int>> load;
  for (int s = 1; s <= count; ++s) load.insert({0.0, s});
  std::vector<int> shard(items.size(), 0);
  for (std::size_t i : order) {
    const auto [work, s] = *load.begin();
    load.erase(load.begin());
    shard[i] = s;
    load.insert({work + items[i].cost, s});
  }
  return shard;
}

CostModel::CostModel(const Scene& base)
    : dim_(base.dim),
      length_(base.length),
      t_end_(base.t_end),
      wave_speed_(std::max<double>(max_wave_speed(base), 1e-300)),
      dt_(base.dt),
      cfl_(base.cfl) {
  const double lattice = std::pow(static_cast<double>(base.cells) * base.ppc, base.dim);
  fill_ = estimate_memory(base, {}).particles / lattice;
}

double CostModel::cost(const RunSpec& spec) const {
  const double particles = fill_ * std::pow(static_cast<double>(spec.cells) * spec.ppc, dim_);
  const double dx = length_ / spec.cells;
  std::optional<double> dt = spec.dt;
  if (!dt && spec.cfl) dt = *spec.cfl * dx / wave_speed_;
  if (!dt) dt = dt_ ? *dt_ : cfl_.value_or(1) * dx / wave_speed_;
  const double steps = std::ceil(spec.t_end.value_or(t_end_) / *dt);
  // An implicit step costs about 20 explicit ones (Newton iterations of CG
  // iterations of a particle loop: the 2D bar at 32 cells, Newmark at CFL 0.2).
  const double per_step = spec.integrator.empty() ? 1 : 20;
  return per_step * particles * steps * std::pow(stencil_width(spec.kernel), dim_);
}

}  // namespace mpmtb::suite
