// Editing a config's text line by line, for tests that change one key of a small config and
// check the message that names its line.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <string_view>

namespace millsim::testing {

/// The 1-based number of the first line that starts with `start` (0 if none).
inline int line_of(std::string_view text, std::string_view start) {
  int line = 1;
  std::size_t at = 0;
  while (at <= text.size()) {
    if (text.substr(at).starts_with(start)) return line;
    const auto end = text.find('\n', at);
    if (end == std::string_view::npos) break;
    at = end + 1;
    ++line;
  }
  return 0;
}

/// `text` with its first line starting with `start` replaced by `replacement` (which may hold
/// several lines, or be empty to remove the line); a test failure if no line starts so.
inline std::string with(std::string_view text, std::string_view start,
                        std::string_view replacement) {
  const int line = line_of(text, start);
  EXPECT_GT(line, 0) << "no line starts with " << start;
  std::string out;
  int n = 1;
  std::size_t at = 0;
  while (at < text.size()) {
    auto end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    if (n == line) {
      if (!replacement.empty()) out += std::string(replacement) + "\n";
    } else {
      out += std::string(text.substr(at, end - at)) + "\n";
    }
    at = end + 1;
    ++n;
  }
  return out;
}

/// "FILE:LINE" for the line of `text` that starts with `start`, as an error message names it.
inline std::string at_line(std::string_view file, std::string_view text, std::string_view start) {
  return std::string(file) + ":" + std::to_string(line_of(text, start));
}

}  // namespace millsim::testing
