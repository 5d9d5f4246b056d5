// Growing the large arrays that each neighbour-list rebuild refills.
#pragma once

#include <cstddef>
#include <vector>

#include "millsim/core/huge_pages.hpp"

namespace millsim {

/// Makes room for `count` elements with a quarter to spare when `values` has less, dropping what
/// it held (the callers refill it). The arrays a rebuild refills (pairs, their histories, the wall
/// candidates' slots) change size a little from one rebuild to the next; std::vector::assign
/// allocates exactly what it is asked for, so each new largest count took a fresh allocation,
/// whose pages the kernel then had to clear (at a million balls a fifth of the steps around the
/// first rebuilds went to that: bench/results.md). A new allocation is asked to be backed by huge
/// pages, before anything touches it: the step reads the histories here and there, and on the
/// AMD host of bench/results.md's fortieth session the 1e6-ball slab ran 1.085 times as fast on
/// one thread with the advice as without (on an Intel host huge pages made no difference). The
/// advice stays with the addresses: a block glibc serves from its heap (below its mmap threshold,
/// at most 32 MiB) passes it on to what is allocated there after it is freed, which changes how
/// much memory is resident, never what it holds.
template <class T>
void reserve_with_slack(std::vector<T>& values, std::size_t count) {
  if (values.capacity() >= count) return;
  std::vector<T>().swap(values);  // nothing copied into the new allocation's pages
  values.reserve(count + count / 4);
  static_cast<void>(advise_huge_pages(values.data(), values.capacity() * sizeof(T)));
}

}  // namespace millsim
