// libFuzzer target: config files and --set overrides (fuzz/config_check.hpp says what is
// checked; fuzz/README.md how to run it). Built by the `fuzz` preset (clang).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "config_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  millsim::fuzz::check_config(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
