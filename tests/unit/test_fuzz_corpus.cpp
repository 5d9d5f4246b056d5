// The config fuzzer's corpus replayed (fuzz/README.md): every input in fuzz/corpus, read,
// planned and built as the fuzzer does (fuzz/config_check.hpp), must be accepted or refused with
// an InputError; no other exception may come out (and, in the debug build, no sanitizer report).
// The corpus holds the inputs that once failed that and a reduced set of what the fuzzer found
// interesting.
#include <gtest/gtest.h>

#include <algorithm>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "config_check.hpp"

namespace millsim {
namespace {

namespace fs = std::filesystem;

TEST(FuzzInput, SplitsConfigFromOverrides) {
  const fuzz::ConfigInput plain = fuzz::split_input("[mill]\ndiameter = 1\n");
  EXPECT_EQ(plain.text, "[mill]\ndiameter = 1\n");
  EXPECT_TRUE(plain.overrides.empty());
  const fuzz::ConfigInput both =
      fuzz::split_input("[mill]\ndiameter = 1\n#--set\nmill.speed=0.7\ncharge.filling=0.3");
  EXPECT_EQ(both.text, "[mill]\ndiameter = 1");
  EXPECT_EQ(both.overrides, (std::vector<std::string>{"mill.speed=0.7", "charge.filling=0.3"}));
}

TEST(FuzzCorpus, EveryInputIsAcceptedOrRefusedWithAnInputError) {
  std::vector<fs::path> inputs;
  for (const auto& entry : fs::directory_iterator(fs::path(MILLSIM_SOURCE_DIR) / "fuzz/corpus")) {
    if (entry.is_regular_file()) inputs.push_back(entry.path());
  }
  std::sort(inputs.begin(), inputs.end());
  ASSERT_GE(inputs.size(), 10U) << "fuzz/corpus is missing or nearly empty";
  int accepted = 0;
  int refused = 0;
  for (const fs::path& path : inputs) {
    std::ifstream file(path, std::ios::binary);
    const std::string data{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
    try {
      (fuzz::check_config(data) ? accepted : refused) += 1;
    } catch (const std::exception& error) {
      ADD_FAILURE() << path.filename() << ": " << error.what();
    }
  }
  // The corpus reaches both ends: configs that run and configs that are refused.
  EXPECT_GT(accepted, 0);
  EXPECT_GT(refused, 0);
}

}  // namespace
}  // namespace millsim
