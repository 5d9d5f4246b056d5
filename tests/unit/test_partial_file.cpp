// PartialFile: every output file is written under NAME.partial and appears under NAME only
// when complete.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <system_error>

#include "millsim/io/partial_file.hpp"

namespace {

namespace fs = std::filesystem;

class PartialFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = fs::temp_directory_path() /
                 ("millsim_partial_" + std::to_string(::getpid()) + "_" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(directory_);
    fs::create_directories(directory_);
  }
  void TearDown() override { fs::remove_all(directory_); }

  static std::string read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  /// The names of the files in the directory, in order.
  [[nodiscard]] std::string listing() const {
    std::string names;
    for (const auto& entry : fs::directory_iterator(directory_)) {
      names += entry.path().filename().string() + ";";
    }
    return names;
  }

  fs::path directory_;
};

TEST_F(PartialFileTest, AppearsUnderItsNameOnlyWhenCommitted) {
  const fs::path path = directory_ / "power.csv";
  {
    millsim::PartialFile file(path);
    file.write("a,b\n");
    file.print("{},{}\n", 1, 2.5);
    EXPECT_EQ(listing(), "power.csv.partial;");
    file.commit();
  }
  EXPECT_EQ(listing(), "power.csv;");
  EXPECT_EQ(read(path), "a,b\n1,2.5\n");
}

TEST_F(PartialFileTest, LeavesNothingWhenAbandoned) {
  // A run stopped by an exception while writing: neither the file nor its .partial remains.
  {
    millsim::PartialFile file(directory_ / "trajectory.csv");
    file.write("half a row");
  }
  EXPECT_EQ(listing(), "");
}

TEST_F(PartialFileTest, ReplacesAnOlderFileWholeAndWritesWholeText) {
  const fs::path path = directory_ / "summary.json";
  millsim::write_whole_file(path, "old");
  millsim::write_whole_file(path, "{\"power_kw\": 1}\n");
  EXPECT_EQ(listing(), "summary.json;");
  EXPECT_EQ(read(path), "{\"power_kw\": 1}\n");
}

TEST_F(PartialFileTest, FailsInADirectoryItCannotWriteNamingThePath) {
  const fs::path path = directory_ / "no-such-directory" / "final.csv";
  try {
    millsim::PartialFile file(path);
    FAIL() << "opened " << path;
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              path.string() + ".partial: cannot write: " +
                  std::make_error_code(std::errc::no_such_file_or_directory).message());
  }
}

TEST_F(PartialFileTest, ARenameThatFailsLeavesNothingAndSaysSo) {
  // The final name is taken by a directory that is not empty: the rename fails, and the
  // .partial goes too.
  fs::create_directories(directory_ / "impacts.csv" / "inside");
  const fs::path path = directory_ / "impacts.csv";
  millsim::PartialFile file(path);
  file.write("angle_rad,count\n");
  // The message names the file and the system's reason: rename(2) of a file onto a directory
  // fails with EISDIR.
  try {
    file.commit();
    ADD_FAILURE() << "committed onto a directory";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ": write failed: " +
                                         std::make_error_code(std::errc::is_a_directory).message());
  }
  EXPECT_EQ(listing(), "impacts.csv;");
  EXPECT_TRUE(fs::is_directory(directory_ / "impacts.csv"));
  EXPECT_THROW(file.commit(), std::logic_error);
}

}  // namespace
