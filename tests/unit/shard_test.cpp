// Shards of a suite's run list (cases/suite/shard.hpp): every run in exactly
// one shard, the same assignment whatever order the list was built in, the
// work balanced within Graham's bound for the longest-first rule, and bad
// --shard values refused with the field and what is allowed.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <random>
#include <set>

#include "core/errors.hpp"
#include "suite/plan.hpp"
#include "suite/shard.hpp"

namespace mpmtb::suite {
namespace shard_test {

std::vector<ShardItem> random_items(int n, unsigned seed) {
  std::mt19937 rng(seed);
  // Costs spread over four decades, like a suite's coarse and fine levels.
  std::uniform_real_distribution<double> decades(0, 4);
  std::vector<ShardItem> items;
  for (int i = 0; i < n; ++i) {
    items.push_back({"runs/case/method/L" + std::to_string(i), std::pow(10.0, decades(rng))});
  }
  return items;
}

// What shard K of N runs, computed as that shard computes it on its own.
std::vector<std::string> members(const std::vector<ShardItem>& items, int k, int n) {
  const auto owner = assign_shards(items, n);
  std::vector<std::string> ids;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (owner[i] == k) ids.push_back(items[i].id);
  }
  return ids;
}

void expect_partition(const std::vector<ShardItem>& items, int n) {
  std::map<std::string, int> seen;
  for (int k = 1; k <= n; ++k) {
    for (const auto& id : members(items, k, n)) ++seen[id];
  }
  EXPECT_EQ(seen.size(), items.size()) << n << " shards";
  for (const auto& item : items) EXPECT_EQ(seen[item.id], 1) << item.id << " in " << n << " shards";
}

// Graham (1969): the longest-processing-time-first rule leaves no shard above
// the mean by more than one job, since the job that made it the largest went
// to the least loaded shard, which held at most the mean.
void expect_balanced(const std::vector<ShardItem>& items, int n) {
  const auto owner = assign_shards(items, n);
  std::vector<double> load(n + 1, 0.0);
  double total = 0, largest = 0;
  for (std::size_t i = 0; i < items.size(); ++i) {
    ASSERT_GE(owner[i], 1);
    ASSERT_LE(owner[i], n);
    load[owner[i]] += items[i].cost;
    total += items[i].cost;
    largest = std::max(largest, items[i].cost);
  }
  const double most = *std::max_element(load.begin() + 1, load.end());
  EXPECT_LE(most, total / n + largest * (1 + 1e-12)) << n << " shards";
}

TEST(Shards, CoverEveryRunExactlyOnce) {
  const auto items = random_items(500, 1);
  for (int n : {1, 2, 3, 7, 64, 600}) expect_partition(items, n);
}

TEST(Shards, DependOnlyOnTheRunsNotOnTheirOrder) {
  auto items = random_items(300, 2);
  std::map<std::string, int> first;
  const auto owner = assign_shards(items, 5);
  for (std::size_t i = 0; i < items.size(); ++i) first[items[i].id] = owner[i];
  std::mt19937 rng(3);
  for (int round = 0; round < 5; ++round) {
    std::shuffle(items.begin(), items.end(), rng);
    const auto again = assign_shards(items, 5);
    for (std::size_t i = 0; i < items.size(); ++i) {
      EXPECT_EQ(again[i], first[items[i].id]) << items[i].id;
    }
  }
}

TEST(Shards, TiesOfEqualCostAreBrokenByIdNotByPosition) {
  std::vector<ShardItem> items;
  for (int i = 0; i < 10; ++i) items.push_back({"run" + std::to_string(i), 1.0});
  auto reversed = items;
  std::reverse(reversed.begin(), reversed.end());
  EXPECT_EQ(members(items, 2, 3), [&] {
    auto m = members(reversed, 2, 3);
    std::reverse(m.begin(), m.end());
    return m;
  }());
}

TEST(Shards, BalanceTheEstimatedWork) {
  for (unsigned seed : {4u, 5u, 6u}) {
    const auto items = random_items(400, seed);
    for (int n : {2, 3, 8, 32}) expect_balanced(items, n);
  }
  // Equal costs: the shard sizes differ by at most one.
  std::vector<ShardItem> equal;
  for (int i = 0; i < 100; ++i) equal.push_back({"run" + std::to_string(i), 1.0});
  for (int n : {3, 7}) {
    std::size_t lo = equal.size(), hi = 0;
    for (int k = 1; k <= n; ++k) {
      lo = std::min(lo, members(equal, k, n).size());
      hi = std::max(hi, members(equal, k, n).size());
    }
    EXPECT_LE(hi - lo, 1u) << n << " shards";
  }
}

TEST(Shards, MoreShardsThanRunsLeaveSomeEmpty) {
  const auto items = random_items(3, 7);
  expect_partition(items, 10);
  int empty = 0;
  for (int k = 1; k <= 10; ++k) empty += members(items, k, 10).empty();
  EXPECT_EQ(empty, 7);
}

TEST(Shards, ADuplicateIdIsAnError) {
  EXPECT_THROW(assign_shards({{"a", 1}, {"a", 2}}, 2), std::logic_error);
}

TEST(Shards, ParseKOfN) {
  const Shard s = parse_shard("2/8");
  EXPECT_EQ(s.index, 2);
  EXPECT_EQ(s.count, 8);
  EXPECT_EQ(parse_shard("1/1").count, 1);
  for (const char* bad : {"4/3", "0/3", "x", "1/0", "3", "1/3x", "-1/3", " 1/3", "1/", "/3",
                          "1.5/3", "", "99999999999/3"}) {
    try {
      parse_shard(bad);
      ADD_FAILURE() << "accepted --shard '" << bad << "'";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("--shard '" + std::string(bad) + "'"), std::string::npos) << m;
      EXPECT_NE(m.find("1 <= K <= N"), std::string::npos) << m;
    }
  }
}

// The real run list: the quick convergence suite split in three.
TEST(Shards, TheConvergenceSuiteSplitsIntoDisjointBalancedShards) {
  SuiteRequest r;
  r.name = "convergence";
  r.quiet = true;
  r.out = "unused";
  const auto plans = plan_suites(r);
  ASSERT_EQ(plans.size(), 1u);
  std::vector<ShardItem> items;
  std::set<std::string> ids;
  for (const auto& s : plans[0].specs) {
    items.push_back({s.dir.generic_string(), s.cost});
    ids.insert(items.back().id);
    EXPECT_GT(s.cost, 0) << items.back().id;
  }
  ASSERT_GT(items.size(), 10u);
  EXPECT_EQ(ids.size(), items.size()) << "run folders must be unique";
  expect_partition(items, 3);
  expect_balanced(items, 3);
  // The estimate follows the run's work: in 1D at a fixed CFL, halving h
  // doubles both the particles and the steps.
  std::map<std::string, double> cost;
  for (const auto& item : items) cost[item.id] = item.cost;
  const double l0 = cost.at("runs/bar/apic-quadratic/L0"),
               l1 = cost.at("runs/bar/apic-quadratic/L1");
  EXPECT_NEAR(l1 / l0, 4.0, 0.5);
}

}  // namespace shard_test
}  // namespace mpmtb::suite
