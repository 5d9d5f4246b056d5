// Growing the large arrays that each neighbour-list rebuild refills.
#pragma once

#include <cstddef>
#include <vector>

namespace millsim {

/// Makes room for `count` elements with a quarter to spare when `values` has less. The arrays a
/// rebuild refills (pairs, their histories, the wall candidates' slots) change size a little
/// from one rebuild to the next; std::vector::assign allocates exactly what it is asked for, so
/// each new largest count took a fresh allocation, whose pages the kernel then had to clear (at a
/// million balls a fifth of the steps around the first rebuilds went to that: bench/results.md).
template <class T>
void reserve_with_slack(std::vector<T>& values, std::size_t count) {
  if (values.capacity() < count) values.reserve(count + count / 4);
}

}  // namespace millsim
