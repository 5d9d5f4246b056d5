// balanced_run_shares (sim/world.hpp): how the runs of a step split among threads follow their
// measured times. Each value is worked by hand in the comment above its check.
#include <gtest/gtest.h>

#include <vector>

#include "millsim/sim/world.hpp"

namespace millsim {
namespace {

void expect_shares(const std::vector<double>& actual, const std::vector<double>& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  double total = 0.0;
  for (std::size_t r = 0; r < actual.size(); ++r) {
    EXPECT_NEAR(actual[r], expected[r], 1e-12) << "run " << r;
    total += actual[r];
  }
  EXPECT_NEAR(total, 1.0, 1e-12);
}

TEST(RunShares, ASlowerRunGetsLessAQuarterOfTheWay) {
  // Equal weights, the second run three times slower: speeds 100 and 33.3, measured shares
  // 0.75 and 0.25; a quarter of the way (run_share_gain) from 0.5 each: 0.5625 and 0.4375.
  ASSERT_EQ(run_share_gain, 0.25);
  expect_shares(balanced_run_shares({0.5, 0.5}, {100.0, 100.0}, {1.0, 3.0}), {0.5625, 0.4375});
}

TEST(RunShares, BalancedRunsKeepTheirShares) {
  // Weights 300 and 100 done in the same time each: speeds 3 : 1, measured 0.75 and 0.25 as
  // now.
  expect_shares(balanced_run_shares({0.75, 0.25}, {300.0, 100.0}, {2.0, 2.0}), {0.75, 0.25});
}

TEST(RunShares, ThreeRuns) {
  // Speeds 10, 20 and 10 (weights 10, 40, 30 in 1, 2, 3 s): measured 0.25, 0.5, 0.25; a
  // quarter of the way from even thirds: 0.3125, 0.375, 0.3125 (within [1/6, 2/3]).
  const double third = 1.0 / 3.0;
  expect_shares(balanced_run_shares({third, third, third}, {10.0, 40.0, 30.0}, {1.0, 2.0, 3.0}),
                {0.3125, 0.375, 0.3125});
}

TEST(RunShares, KeptWithinAFactorOfTwoOfEven) {
  // Measured 0.01 and 0.99 (speeds 1 and 99) from 0.26 and 0.74: a quarter of the way 0.1975
  // and 0.8025; the first raised to a half of even, 0.25, then both scaled by 1 / 1.0525.
  expect_shares(balanced_run_shares({0.26, 0.74}, {1.0, 99.0}, {1.0, 1.0}),
                {0.25 / 1.0525, 0.8025 / 1.0525});
}

TEST(RunShares, UntimedOnlyBroughtWithinBounds) {
  // A run not timed (no weight, or no time): shares within [0.25, 1] for two runs stay; an
  // empty run's 0 is raised to 0.25, and with the other's 1 scaled by 1 / 1.25: 0.2 and 0.8.
  const std::vector<double> shares{0.3, 0.7};
  expect_shares(balanced_run_shares(shares, {100.0, 100.0}, {1.0, 0.0}), shares);
  expect_shares(balanced_run_shares(shares, {0.0, 100.0}, {1.0, 1.0}), shares);
  expect_shares(balanced_run_shares({0.0, 1.0}, {0.0, 100.0}, {0.0, 1.0}), {0.2, 0.8});
  expect_shares(balanced_run_shares(shares, {}, {}), shares);
}

}  // namespace
}  // namespace millsim
