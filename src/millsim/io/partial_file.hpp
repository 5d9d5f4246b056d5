// Output files that a reader never sees half written: each is written under NAME.partial and
// renamed to NAME once complete. A run stopped (or failed) while writing one leaves no file
// under the final name; a PartialFile destroyed before commit() removes its .partial.
#pragma once

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <iterator>
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

  /// Appends `text`; a failure (a full disk, say) is kept, with its reason, for commit().
  void write(std::string_view text);
  template <typename... Args>
  void print(fmt::format_string<Args...> format, Args&&... args) {
    fmt::memory_buffer text;
    fmt::format_to(std::back_inserter(text), format, std::forward<Args>(args)...);
    write({text.data(), text.size()});
  }
  /// Closes the file and renames it to its final name; throws std::runtime_error (and removes
  /// the .partial) if any write, the close or the rename failed, a full disk among them. Once.
  void commit();

 private:
  std::filesystem::path path_;
  std::filesystem::path partial_;
  std::FILE* file_ = nullptr;
  int error_ = 0;  // errno of the first write that failed
};

/// Writes `text` to `path` through a PartialFile.
void write_whole_file(const std::filesystem::path& path, std::string_view text);

/// For a file that grows as a run goes (snapshots/index.csv, a .pvd collection), after an
/// append to it failed with errno `error` (a full disk, say): puts it back as it was, its first
/// `whole` bytes and then `tail` (what it keeps after its entries), or, if the append was its
/// first write, removes it (closing `file` and setting it to null); then throws
/// std::runtime_error "PATH: write failed: REASON".
[[noreturn]] void undo_failed_append(std::FILE*& file, const std::filesystem::path& path,
                                     long whole, bool first, int error, std::string_view tail = {});

}  // namespace millsim
