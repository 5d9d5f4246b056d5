// Output files that a reader never sees half written: each is written under NAME.partial and
// renamed to NAME once complete. A run stopped (or failed) while writing one leaves no file
// under the final name; a PartialFile destroyed before commit() removes its .partial.
#pragma once

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace millsim {

class PartialFile {
 public:
  /// Opens path.partial for writing; throws std::runtime_error if it cannot be made.
  explicit PartialFile(std::filesystem::path path);
  ~PartialFile();
  PartialFile(const PartialFile&) = delete;
  PartialFile& operator=(const PartialFile&) = delete;

  /// The open file, for writers that print into it themselves.
  std::FILE* get() { return file_; }
  void write(std::string_view text) { std::fwrite(text.data(), 1, text.size(), file_); }
  template <typename... Args>
  void print(fmt::format_string<Args...> format, Args&&... args) {
    fmt::print(file_, format, std::forward<Args>(args)...);
  }
  /// Closes the file and renames it to its final name; throws std::runtime_error (and removes
  /// the .partial) if any write, the close or the rename failed, a full disk among them. Once.
  void commit();

 private:
  std::filesystem::path path_;
  std::filesystem::path partial_;
  std::FILE* file_ = nullptr;
};

/// Writes `text` to `path` through a PartialFile.
void write_whole_file(const std::filesystem::path& path, std::string_view text);

}  // namespace millsim
