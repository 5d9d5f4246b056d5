#include "millsim/io/partial_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
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
    throw std::runtime_error(
        fmt::format("{}: cannot write: {}", partial_.string(), std::strerror(errno)));
  }
}

void PartialFile::write(std::string_view text) {
  errno = 0;
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size() && error_ == 0) {
    error_ = errno != 0 ? errno : EIO;
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
  // The reason of the first failure: a write, the close (which writes what is buffered), or
  // the rename.
  int error = error_ != 0 ? error_ : (std::ferror(file_) != 0 ? EIO : 0);
  errno = 0;
  if (std::fclose(file_) != 0 && error == 0) error = errno != 0 ? errno : EIO;
  file_ = nullptr;
  std::error_code rename_error;
  if (error == 0) std::filesystem::rename(partial_, path_, rename_error);
  if (error != 0 || rename_error) {
    std::error_code ignored;
    std::filesystem::remove(partial_, ignored);
    throw std::runtime_error(
        fmt::format("{}: write failed: {}", path_.string(),
                    error != 0 ? std::strerror(error) : rename_error.message()));
  }
}

void write_whole_file(const std::filesystem::path& path, std::string_view text) {
  PartialFile file(path);
  file.write(text);
  file.commit();
}

void undo_failed_append(std::FILE*& file, const std::filesystem::path& path, long whole, bool first,
                        int error, std::string_view tail) {
  std::clearerr(file);
  if (first) {
    std::fclose(file);
    file = nullptr;
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
  } else if (::ftruncate(::fileno(file), whole) == 0 && std::fseek(file, whole, SEEK_SET) == 0 &&
             !tail.empty()) {
    std::fwrite(tail.data(), 1, tail.size(), file);
    std::fflush(file);
  }
  throw std::runtime_error(fmt::format("{}: write failed: {}", path.string(),
                                       error != 0 ? std::strerror(error) : "unknown error"));
}

}  // namespace millsim
