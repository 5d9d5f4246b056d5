// Directories of a test's own under the system's temporary directory: ctest runs test programs
// at the same time, and CI may run two builds' suites at once, so no two share a fixed name.
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <string>
#include <string_view>

namespace millsim::testing {

/// A new, empty directory named millsim-NAME-XXXXXX under the temporary directory (mkdtemp);
/// a test failure, and an empty path, if it cannot be made.
inline std::filesystem::path fresh_directory(std::string_view name) {
  std::string pattern =
      (std::filesystem::temp_directory_path() / ("millsim-" + std::string(name) + "-XXXXXX"))
          .string();
  if (mkdtemp(pattern.data()) == nullptr) {
    ADD_FAILURE() << "cannot make a directory like " << pattern;
    return {};
  }
  return pattern;
}

}  // namespace millsim::testing
