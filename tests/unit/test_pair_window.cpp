// The pair kernel's window of prefetched particles (world_detail::pair_window_for): how far
// beyond a pair's first particle the kernel has the particle arrays fetched.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "millsim/sim/world_detail.hpp"

namespace millsim {
namespace {

using world_detail::pair_window_bytes;
using world_detail::pair_window_for;
using world_detail::pair_window_lead;

TEST(PairWindow, ReachesTheFurthestSecondParticleAndALeadBeyond) {
  // Pairs list the lower index first; the furthest second particle is 40 beyond its first.
  const std::vector<std::uint32_t> first{0, 0, 3, 10, 12};
  const std::vector<std::uint32_t> second{1, 7, 43, 11, 30};
  EXPECT_EQ(pair_window_for(first, second, 184), 40 + pair_window_lead);
}

TEST(PairWindow, LeavesOutPairsBeyondTheLargestWindow) {
  // 184 bytes a particle: at most pair_window_bytes / 184 particles (1424).
  const std::size_t largest = pair_window_bytes / 184;
  ASSERT_GT(largest, pair_window_lead + 100);
  // A pair across a periodic slab's ends (first 5, second at the far end of the list) is left
  // to the pair-by-pair prefetch; the window covers the others.
  const std::vector<std::uint32_t> first{5, 6, 20};
  const std::vector<std::uint32_t> second{900000, 106, 50};
  EXPECT_EQ(pair_window_for(first, second, 184), 100 + pair_window_lead);
  // A pair exactly at the largest window is kept, one beyond it is not.
  const auto at = static_cast<std::uint32_t>(largest - pair_window_lead);
  EXPECT_EQ(pair_window_for({0}, {at}, 184), largest);
  EXPECT_EQ(pair_window_for({0, 0}, {at + 1, 2}, 184), 2 + pair_window_lead);
}

TEST(PairWindow, IsTheLeadAloneWithNoPairs) {
  EXPECT_EQ(pair_window_for({}, {}, 184), pair_window_lead);
}

}  // namespace
}  // namespace millsim
