#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <numeric>
#include <vector>

#include "millsim/core/huge_pages.hpp"
#include "millsim/core/vector_growth.hpp"

namespace millsim {
namespace {

constexpr std::uintptr_t mib = std::uintptr_t{1} << 20U;

TEST(HugePages, TheWholePagesInsideARange) {
  // Aligned at both ends: all of it.
  EXPECT_EQ(whole_huge_pages(4 * mib, 6 * mib), (AddressRange{4 * mib, 10 * mib}));
  // 16 bytes past a page (glibc's header on a large block), 7 MiB long: the pages at 2 and 4 MiB
  // begin inside it, the one at 6 MiB would end past it.
  EXPECT_EQ(whole_huge_pages(mib / 2 + 16, 7 * mib), (AddressRange{2 * mib, 6 * mib}));
  EXPECT_EQ(whole_huge_pages(2 * mib + 16, 4 * mib), (AddressRange{4 * mib, 6 * mib}));
  // Less than one whole page inside: none.
  EXPECT_EQ(whole_huge_pages(mib, 2 * mib).begin, whole_huge_pages(mib, 2 * mib).end);
  EXPECT_EQ(whole_huge_pages(3 * mib, mib).begin, whole_huge_pages(3 * mib, mib).end);
  EXPECT_EQ(whole_huge_pages(4 * mib, 0).begin, whole_huge_pages(4 * mib, 0).end);
}

TEST(HugePages, AdvisedMemoryKeepsWhatIsWrittenToIt) {
  // 24 MiB of doubles, advised before anything is written (as reserve_with_slack does): the hint
  // changes how the pages are backed, never what they hold.
  std::vector<double> values;
  values.reserve(std::size_t{3} * 1024 * 1024);
  advise_huge_pages(values.data(), values.capacity() * sizeof(double));
  values.resize(values.capacity());
  std::iota(values.begin(), values.end(), 0.0);
  EXPECT_EQ(values.front(), 0.0);
  EXPECT_EQ(values[1'000'000], 1'000'000.0);
  EXPECT_EQ(values.back(), static_cast<double>(values.size() - 1));
}

TEST(VectorGrowth, GrowsWithAQuarterToSpareAndOnlyWhenShort) {
  std::vector<int> values{1, 2, 3};
  reserve_with_slack(values, 100);
  EXPECT_EQ(values.capacity(), 125U);
  EXPECT_TRUE(values.empty());  // dropped: the callers refill it
  values.assign(110, 7);
  const int* const data = values.data();
  reserve_with_slack(values, 120);  // room enough: the same allocation, the same contents
  EXPECT_EQ(values.data(), data);
  EXPECT_EQ(values.size(), 110U);
  EXPECT_EQ(values[109], 7);
}

}  // namespace
}  // namespace millsim
