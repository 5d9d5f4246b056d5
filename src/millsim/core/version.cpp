#include "millsim/core/version.hpp"

#include "millsim/version_info.hpp"  // generated at build time (cmake/version.cmake)

namespace millsim {

std::string version_text() {
  return std::string(MILLSIM_VERSION) + " (" + MILLSIM_REVISION + ")";
}

}  // namespace millsim
