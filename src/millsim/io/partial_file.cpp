#include "millsim/io/partial_file.hpp"

#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

namespace millsim {

PartialFile::PartialFile(std::filesystem::path path)
    : path_(std::move(path)), partial_(path_.string() + ".partial") {
  file_ = std::fopen(partial_.c_str(), "wb");
  if (file_ == nullptr) {
    // A run failure (exit status 1), not refused input: the output directory was made and
    // checked before the run began.
    throw std::runtime_error(fmt::format("{}: cannot write", partial_.string()));
  }
}

PartialFile::~PartialFile() {
  if (file_ == nullptr) return;
  std::fclose(file_);
  std::error_code ignored;
  std::filesystem::remove(partial_, ignored);
}

void PartialFile::commit() {
  if (file_ == nullptr) throw std::logic_error(fmt::format("{}: committed twice", path_.string()));
  const bool write_failed = std::ferror(file_) != 0;
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  std::error_code error;
  if (!write_failed && !close_failed) std::filesystem::rename(partial_, path_, error);
  if (write_failed || close_failed || error) {
    std::error_code ignored;
    std::filesystem::remove(partial_, ignored);
    throw std::runtime_error(fmt::format("{}: write failed{}", path_.string(),
                                         error ? ": " + error.message() : std::string()));
  }
}

void write_whole_file(const std::filesystem::path& path, std::string_view text) {
  PartialFile file(path);
  file.write(text);
  file.commit();
}

}  // namespace millsim
