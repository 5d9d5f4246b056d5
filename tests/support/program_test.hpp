// A test fixture that runs the built millsim program in a fresh temporary directory, as a user
// would from a shell, and captures its exit status, stdout and stderr.
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "support/temporary_directory.hpp"

namespace millsim::testing {

/// `text` as one single-quoted shell word.
inline std::string quoted(const std::string& text) {
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

inline std::string read_all(const std::filesystem::path& path) {
  std::ifstream file(path);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

struct Outcome {
  int status = -1;
  std::string out;
  std::string err;
};

class ProgramTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fresh_directory("test");
    ASSERT_FALSE(root_.empty());
    work_ = root_ / "work";
    std::filesystem::create_directory(work_);
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(root_, ignored);
  }

  /// Runs `millsim ARGS` in the working directory; ARGS is shell text.
  Outcome millsim(const std::string& args) const {
    const std::string command = "cd " + quoted(work_.string()) + " && " + quoted(MILLSIM_BINARY) +
                                " " + args + " >" + quoted((root_ / "stdout").string()) + " 2>" +
                                quoted((root_ / "stderr").string()) + " </dev/null";
    const int raw = std::system(command.c_str());
    Outcome o;
    o.status = raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    o.out = read_all(root_ / "stdout");
    o.err = read_all(root_ / "stderr");
    return o;
  }

  std::filesystem::path root_;  ///< the temporary directory, removed after the test
  std::filesystem::path work_;  ///< where the program runs
};

}  // namespace millsim::testing
