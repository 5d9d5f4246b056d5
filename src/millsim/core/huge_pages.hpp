// Asking the kernel to back large arrays with huge pages.
#pragma once

#include <cstddef>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace millsim {

/// The size of a transparent huge page on x86-64 Linux (and arm64 with 4 KiB pages).
inline constexpr std::uintptr_t huge_page_bytes = std::uintptr_t{2} << 20U;

/// Addresses [begin, end).
struct AddressRange {
  std::uintptr_t begin = 0;
  std::uintptr_t end = 0;
  friend bool operator==(const AddressRange&, const AddressRange&) = default;
};

/// The whole huge pages inside [start, start + bytes): begin rounded up and end rounded down to
/// huge_page_bytes; empty (begin == end) where no whole page fits.
constexpr AddressRange whole_huge_pages(std::uintptr_t start, std::size_t bytes) {
  const std::uintptr_t begin = (start + huge_page_bytes - 1) & ~(huge_page_bytes - 1);
  const std::uintptr_t end = (start + bytes) & ~(huge_page_bytes - 1);
  return end > begin ? AddressRange{begin, end} : AddressRange{begin, begin};
}

/// Asks that the whole huge pages inside [data, data + bytes) be backed by transparent huge pages
/// when first touched (MADV_HUGEPAGE; pages already touched stay as they are). A hint: where the
/// kernel has no such pages or refuses, nothing changes; returns whether the kernel took it
/// (false also where no whole huge page fits), which the callers need not check. The memory
/// must be the caller's own. Where a huge page is not 2 MiB (arm64 with 64 KiB pages, say), the
/// advice covers whole 2 MiB blocks and the kernel does what it can with them.
inline bool advise_huge_pages(const void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  const AddressRange range = whole_huge_pages(reinterpret_cast<std::uintptr_t>(data), bytes);
  if (range.end > range.begin) {
    // NOLINTNEXTLINE(performance-no-int-to-ptr): an address range for the kernel
    void* const first = reinterpret_cast<void*>(range.begin);
    return madvise(first, range.end - range.begin, MADV_HUGEPAGE) == 0;
  }
  return false;
#else
  static_cast<void>(data);
  static_cast<void>(bytes);
  return false;
#endif
}

}  // namespace millsim
