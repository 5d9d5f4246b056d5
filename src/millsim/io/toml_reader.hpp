// Reading a TOML table key by key with errors that name the file, line and key and say what
// is allowed; keys nobody asked for are refused as unknown.
#pragma once

#include <toml++/toml.h>

#include <functional>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace millsim {

/// "file:line" of a node, or the command-line option it came from.
std::string source_location(const toml::node& node, std::string_view fallback_file);

class TableReader {
 public:
  /// `path` is the dotted name of the table ("mill.lifters"; "" for the document root).
  TableReader(const toml::table& table, std::string path, std::string file);

  bool has(std::string_view key) const;
  const toml::node* node(std::string_view key);  ///< marks the key as known; nullptr if absent

  /// A number (integers accepted). `allowed` describes the allowed values for messages, e.g.
  /// "a number > 0 (m)"; `valid` checks the value.
  double number(std::string_view key, std::optional<double> fallback, std::string_view allowed,
                const std::function<bool(double)>& valid);
  std::optional<double> optional_number(std::string_view key, std::string_view allowed,
                                        const std::function<bool(double)>& valid);
  long integer(std::string_view key, std::optional<long> fallback, std::string_view allowed,
               const std::function<bool(long)>& valid);
  std::string string(std::string_view key, std::optional<std::string> fallback,
                     std::string_view allowed);
  /// The sub-table `key` (an empty one if absent and not required).
  TableReader table(std::string_view key, bool required);

  /// Refuses every key that no call above asked about.
  void refuse_unknown_keys(std::string_view allowed_keys) const;

  [[noreturn]] void fail_at(std::string_view key, const std::string& message) const;
  [[noreturn]] void fail_missing(std::string_view key, std::string_view allowed) const;

  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }
  std::string dotted(std::string_view key) const;

 private:
  const toml::table* table_;
  std::string path_;
  std::string file_;
  std::set<std::string, std::less<>> asked_;
};

/// Applies "--set a.b.c=value" overrides to a parsed document. The value is read as TOML
/// (0.75, "text", [1, 2]); anything that is not valid TOML is taken as a plain string.
void apply_overrides(toml::table& document, const std::vector<std::string>& overrides);

}  // namespace millsim
