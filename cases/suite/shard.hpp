// Splitting a suite's run list into N disjoint shards, for job arrays on a
// cluster scheduler (Slurm) or GNU parallel across hosts.
//
// Every shard computes the same assignment from the same run list on its own,
// without talking to the others: the assignment depends only on the runs' ids
// (their folders under the suite root) and estimated costs, never on the order
// the list was built in, the host or the time. So `--shard K/N` on any machine
// of a cluster picks the same runs, the N shards together cover the list
// exactly once, and a shard re-run after a kill picks the same runs again.
#pragma once

#include <string>
#include <vector>

#include "runner.hpp"
#include "scene.hpp"

namespace mpmtb::suite {

// The K-th of N shards, 1-based (Slurm's array task ids start at 1).
struct Shard {
  int index = 1, count = 1;
};

// "K/N" with 1 <= K <= N; throws InputError naming --shard and what is allowed.
Shard parse_shard(const std::string& text);

struct ShardItem {
  std::string id;  // unique: the run's folder relative to the suites' root
  double cost = 1;
};

// The shard (1..count) of every item, balanced by cost: longest runs first,
// each to the shard with the least work so far (Graham's LPT rule; the largest
// shard holds at most total / count + the largest single cost). Ties are broken
// by id and by shard number, so the result is a function of the set of items.
std::vector<int> assign_shards(const std::vector<ShardItem>& items, int count);

// Estimated work of the runs of one case, for balancing only: particles x steps
// x stencil nodes. The particle count of a base scene is scaled by
// (cells ppc)^dim, the steps are t_end / dt with dt = cfl dx / c_p at rest.
class CostModel {
 public:
  explicit CostModel(const Scene& base);
  double cost(const RunSpec& spec) const;

 private:
  int dim_;
  double fill_;  // particles / (cells ppc)^dim of the base scene
  double length_, t_end_, wave_speed_;
  std::optional<double> dt_, cfl_;
};

}  // namespace mpmtb::suite
