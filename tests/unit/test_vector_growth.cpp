#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <numeric>
#include <string>
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

/// The VmFlags of the mapping of this process that holds `address` (/proc/self/smaps), or ""
/// if none does.
std::string mapping_flags(std::uintptr_t address) {
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    // A mapping's first line: "start-end perms offset device inode [path]", in hexadecimal.
    const std::size_t dash = line.find('-');
    const std::size_t space = line.find(' ');
    if (dash != std::string::npos && space != std::string::npos && dash < space &&
        line.find(':') > space) {
      const std::uintptr_t start = std::stoull(line.substr(0, dash), nullptr, 16);
      const std::uintptr_t end = std::stoull(line.substr(dash + 1, space - dash - 1), nullptr, 16);
      inside = start <= address && address < end;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line + " ";
    }
  }
  return "";
}

TEST(HugePages, OnlyTheWholePagesInsideTheArrayAreAdvised) {
  // 24 MiB of doubles, advised before anything is written (as reserve_with_slack does).
  std::vector<double> values;
  values.reserve(std::size_t{3} * 1024 * 1024);
  const std::size_t bytes = values.capacity() * sizeof(double);
  const auto start = reinterpret_cast<std::uintptr_t>(values.data());
  if (!advise_huge_pages(values.data(), bytes)) {
    GTEST_SKIP() << "this kernel has no transparent huge pages, or refused the advice";
  }
  const AddressRange pages = whole_huge_pages(start, bytes);
  ASSERT_GT(pages.end, pages.begin);
  // The kernel marks the advised pages "hg" (and splits the mapping there), at both ends of the
  // range, and nothing of the array before or after it.
  EXPECT_NE(mapping_flags(pages.begin).find(" hg "), std::string::npos);
  EXPECT_NE(mapping_flags(pages.end - 1).find(" hg "), std::string::npos);
  if (pages.begin > start) {
    EXPECT_EQ(mapping_flags(pages.begin - 1).find(" hg "), std::string::npos);
  }
  if (pages.end < start + bytes) {
    EXPECT_EQ(mapping_flags(pages.end).find(" hg "), std::string::npos);
  }
  // A hint about how the pages are backed, never about what they hold.
  values.resize(values.capacity());
  std::iota(values.begin(), values.end(), 0.0);
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
