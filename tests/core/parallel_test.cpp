// The split of a loop's items that follows the threads' speeds (core/detail/parallel.hpp).
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include <jelly/core/detail/parallel.hpp>

namespace jelly {
namespace {

// The ranges of every part: contiguous, in order, covering [0, n), none larger than largest().
void expect_cover(const parallel::BalancedSplit& split, long n, int parts) {
  long next = 0;
  for (int part = 0; part < parts; ++part) {
    const parallel::Range r = split.range(n, part, parts);
    EXPECT_EQ(r.begin, next) << part;
    EXPECT_LE(r.begin, r.end) << part;
    EXPECT_LE(r.end - r.begin, parallel::BalancedSplit::largest(n, parts)) << part;
    next = r.end;
  }
  EXPECT_EQ(next, n);
}

// Each part's time as if its items cost `cost[part]` seconds each; then update().
void run_once(parallel::BalancedSplit& split, long n, const std::vector<double>& cost) {
  const int parts = static_cast<int>(cost.size());
  for (int part = 0; part < parts; ++part) {
    const parallel::Range r = split.range(n, part, parts);
    split.record(part, cost[part] * static_cast<double>(r.end - r.begin));
  }
  split.update(parts);
}

TEST(BalancedSplit, StartsEqualThenGivesTheSlowerThreadFewerItems) {
  const long n = 8000;
  parallel::BalancedSplit split;
  for (int part = 0; part < 2; ++part) {  // before any update: parallel::split's ranges
    EXPECT_EQ(split.range(n, part, 2).begin, parallel::split(n, part, 2).begin);
    EXPECT_EQ(split.range(n, part, 2).end, parallel::split(n, part, 2).end);
  }
  // Thread 0 twice as slow per item: equal times when it has a third of the items.
  for (int k = 0; k < 40; ++k) {
    run_once(split, n, {2e-9, 1e-9});
    expect_cover(split, n, 2);
  }
  EXPECT_NEAR(static_cast<double>(split.range(n, 0, 2).end), n / 3.0, 2.0);
  // The speeds swap: the split follows.
  for (int k = 0; k < 40; ++k) run_once(split, n, {1e-9, 2e-9});
  EXPECT_NEAR(static_cast<double>(split.range(n, 0, 2).end), 2 * n / 3.0, 2.0);
}

TEST(BalancedSplit, NoPartBelowHalfOrAboveThreeHalvesOfAnEqualShare) {
  const long n = 9001;
  for (int parts : {2, 3, 5}) {
    parallel::BalancedSplit split;
    std::vector<double> cost(parts, 1e-9);
    cost[0] = 1e-6;  // a thousand times slower
    for (int k = 0; k < 60; ++k) {
      run_once(split, n, cost);
      expect_cover(split, n, parts);
    }
    const parallel::Range slow = split.range(n, 0, parts);
    EXPECT_NEAR(static_cast<double>(slow.end - slow.begin), 0.5 * n / parts, 2.0) << parts;
    // A team of another size starts from equal parts.
    split.update(parts + 1);
    for (int part = 0; part <= parts; ++part)
      EXPECT_EQ(split.range(n, part, parts + 1).end, parallel::split(n, part, parts + 1).end);
  }
}

// Times that say nothing (zero, not finite) leave the split as it is.
TEST(BalancedSplit, IgnoresTimesThatAreNotPositive) {
  const long n = 1000;
  parallel::BalancedSplit split;
  run_once(split, n, {1e-9, 1e-9});
  run_once(split, n, {3e-9, 1e-9});
  const long boundary = split.range(n, 0, 2).end;
  EXPECT_LT(boundary, n / 2);
  for (const double bad : {0.0, -1.0, std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::quiet_NaN()}) {
    split.record(0, bad);
    split.record(1, 1e-6);
    split.update(2);
    EXPECT_EQ(split.range(n, 0, 2).end, boundary);
  }
}

}  // namespace
}  // namespace jelly
