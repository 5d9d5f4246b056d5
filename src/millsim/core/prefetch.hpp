// Asking the processor to fetch a record before it is needed.
#pragma once

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

}  // namespace millsim
