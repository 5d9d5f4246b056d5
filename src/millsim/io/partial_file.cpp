#include "millsim/io/partial_file.hpp"

#include <stdexcept>
#include <system_error>
#include <utility>

#include "millsim/core/error.hpp"

namespace millsim {

PartialFile::PartialFile(std::filesystem::path path)
    : path_(std::move(path)), partial_(path_.string() + ".partial") {
  file_ = std::fopen(partial_.c_str(), "wb");
  if (file_ == nullptr) {
    throw InputError(
        fmt::format("{}: cannot write; allowed: a writable output directory", partial_.string()));
  }
}

PartialFile::~PartialFile() {
  if (file_ == nullptr) return;
  std::fclose(file_);
  std::error_code ignored;
  std::filesystem::remove(partial_, ignored);
}

void PartialFile::commit() {
  const bool write_failed = std::ferror(file_) != 0;
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  if (write_failed || close_failed) {
    std::error_code ignored;
    std::filesystem::remove(partial_, ignored);
    throw std::runtime_error(fmt::format("{}: write failed", path_.string()));
  }
  std::filesystem::rename(partial_, path_);
}

void write_whole_file(const std::filesystem::path& path, std::string_view text) {
  PartialFile file(path);
  file.write(text);
  file.commit();
}

}  // namespace millsim
