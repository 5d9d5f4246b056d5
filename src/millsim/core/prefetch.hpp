// Asking the processor to fetch a record before it is needed.
#pragma once

#include <cstddef>

namespace millsim {

/// Prefetches every cache line the record `value` spans, for reading (or for writing, if
/// for_writing): its first byte's line and its last byte's. A record of up to 64 bytes spans at
/// most two lines. Half of the 40-byte pair histories (and of the 48-byte wall slots) in an
/// array span two, and a prefetch of the record's address alone left the second line to miss
/// when the record was read (the few histories that a step reads in a 1e6-ball world are
/// scattered through memory, in no cache).
template <class T>
[[gnu::always_inline]] inline void prefetch_record(const T& value, bool for_writing = false) {
  static_assert(sizeof(T) <= 64, "a record of more than two cache lines");
  const char* const first = reinterpret_cast<const char*>(&value);
  const char* const last = first + sizeof(T) - 1;
  if (for_writing) {
    __builtin_prefetch(first, 1);
    __builtin_prefetch(last, 1);
  } else {
    __builtin_prefetch(first);
    __builtin_prefetch(last);
  }
}

/// Prefetches, for reading, into the second-level cache (locality 2: `prefetcht1` on x86-64),
/// every cache line that holds a part of values [first, first + count). Steps of a line from
/// the first byte meet every line but perhaps the last, which the last byte's fetch takes. For
/// a range too large for the first-level cache that will be read soon but not at once (the
/// pair kernel's window of particles, World::prefetch_particles).
template <class T>
[[gnu::always_inline]] inline void prefetch_lines_for_l2(const T* first, std::size_t count) {
  if (count == 0) return;
  constexpr std::ptrdiff_t line = 64;
  const char* const begin = reinterpret_cast<const char*>(first);
  const auto bytes = static_cast<std::ptrdiff_t>(count * sizeof(T));
  for (std::ptrdiff_t at = 0; at < bytes; at += line) __builtin_prefetch(begin + at, 0, 2);
  __builtin_prefetch(begin + bytes - 1, 0, 2);
}

}  // namespace millsim
