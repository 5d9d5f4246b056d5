// What the processor the program runs on can do, asked once.
#pragma once

namespace millsim {

/// Whether this processor has AVX2: the kernels compiled for it (the pair and wall laws in
/// lanes, the first pass over the pairs, the 3D integration, the neighbour search) are chosen
/// only then.
inline bool processor_has_avx2() {
#if defined(__x86_64__)
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return has;
#else
  return false;
#endif
}

}  // namespace millsim
