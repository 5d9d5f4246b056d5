// Reading a TOML table key by key with errors that name the file, line and key and say what
// is allowed; keys nobody declared are refused as unknown before any value is read, so that a
// misspelt key is reported as misspelt rather than as a missing required one.
//
// Every message has the form "WHERE: dotted.key: problem; allowed: ...", where WHERE is
// "file:line" for a value from the file, "command line (--set KEY=VALUE)" for a value from an
// override, and the bare file name when there is no line to point at (a missing table).
#pragma once

#include <toml++/toml.h>

#include <functional>
#include <initializer_list>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace millsim {

/// Where each key was given, by dotted name ("mill.diameter" -> "lab.toml:14").
using KeyLocations = std::map<std::string, std::string, std::less<>>;

/// "file:line" of a node, "command line (--set KEY=VALUE)" for a node from an override, or
/// `fallback_file` when the node has no line.
std::string source_location(const toml::node& node, std::string_view fallback_file);

/// The most parts a dotted key or table name may have (millsim's own keys have at most three).
inline constexpr std::size_t max_key_parts = 64;

/// The line (from 1) of the first dotted key or table name in TOML `text` with more than
/// max_key_parts parts, if any. Read before the text is parsed: toml++ takes each part of a
/// dotted key one call deeper, and a key of 35 000 parts ran millsim out of stack. Strings and
/// comments are skipped, and a number's decimal point is one dot, not a chain of them.
std::optional<std::size_t> line_of_overlong_key(std::string_view text);

/// A value as written ("0.9" with its quotes, 8.5, true), or its kind ("an array").
std::string describe_value(const toml::node& node);

/// The key of `keys` closest to `key` when it is close enough to be a likely misspelling
/// (one or two letters wrong, missing, extra or swapped; case ignored).
std::optional<std::string_view> closest_key(std::string_view key,
                                            std::span<const std::string_view> keys);

class TableReader {
 public:
  /// `path` is the dotted name of the table ("mill.lifters"; "" for the document root).
  /// `locations`, when given, collects where every key that is read was given.
  TableReader(const toml::table& table, std::string path, std::string file,
              KeyLocations* locations = nullptr);

  /// Declares the keys this table may hold and refuses any other at once, suggesting the
  /// closest allowed key. `hint`, when given, may return a remark for an unknown key that has
  /// no close match (e.g. "it belongs in [charge]"); an empty string means none.
  void allow_keys(std::span<const std::string_view> keys,
                  const std::function<std::string(std::string_view)>& hint = {});
  void allow_keys(std::initializer_list<std::string_view> keys,
                  const std::function<std::string(std::string_view)>& hint = {}) {
    allow_keys(std::span<const std::string_view>(keys.begin(), keys.size()), hint);
  }

  bool has(std::string_view key) const;
  /// The value of `key`, nullptr if absent; records where it was given in `locations`.
  const toml::node* node(std::string_view key);

  /// A number (integers accepted). `allowed` describes the allowed values for messages, e.g.
  /// "a number of metres > 0"; `valid` checks the value. A missing key takes `fallback`, or is
  /// refused when there is none.
  double number(std::string_view key, std::optional<double> fallback, std::string_view allowed,
                const std::function<bool(double)>& valid);
  std::optional<double> optional_number(std::string_view key, std::string_view allowed,
                                        const std::function<bool(double)>& valid);
  /// A whole number (a float with no fractional part, like 8.0, is accepted; 8.5 is not).
  long integer(std::string_view key, std::optional<long> fallback, std::string_view allowed,
               const std::function<bool(long)>& valid);
  /// A string. A value given with --set is taken as the text typed even when it reads as
  /// another TOML value (--set output.directory=2024 names the directory "2024").
  bool boolean(std::string_view key, bool fallback, std::string_view allowed);
  /// An array of exactly `length` finite numbers (integers accepted), e.g. a position
  /// [0.0, 0.1, 0.02]. A missing key takes `fallback`, or is refused when there is none.
  std::vector<double> numbers(std::string_view key, std::size_t length,
                              std::optional<std::vector<double>> fallback,
                              std::string_view allowed);
  std::string string(std::string_view key, std::optional<std::string> fallback,
                     std::string_view allowed);
  /// The sub-table `key`: an empty one if absent and not required. `allowed` describes the
  /// table for messages (e.g. "a table [mill] with diameter, length, speed or speed_rpm").
  TableReader table(std::string_view key, bool required, std::string_view allowed = {});

  /// Refuses `key` (which need not be present): "WHERE: path.key: message".
  [[noreturn]] void fail_at(std::string_view key, const std::string& message) const;
  /// Refuses the value `at` (an array element, say), named `label` in the message.
  [[noreturn]] void fail_at_node(const toml::node& at, std::string_view label,
                                 const std::string& message) const;
  /// Refuses a required key that is absent, pointing at the start of this table.
  [[noreturn]] void fail_missing(std::string_view key, std::string_view allowed) const;

  /// Where `key` of this table was given (as source_location), or where the table starts.
  std::string location(std::string_view key) const;
  /// Where this table starts: "file:line", the command line, or just the file name.
  const std::string& where() const { return where_; }

  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }
  std::string dotted(std::string_view key) const;

 private:
  TableReader(const toml::table& table, std::string path, std::string file, KeyLocations* locations,
              std::string where, bool present);
  std::string table_name() const;

  const toml::table* table_;
  std::string path_;
  std::string file_;
  KeyLocations* locations_;
  std::string where_;    ///< where the table starts (or its parent, for an absent table)
  bool present_ = true;  ///< the table exists in the document (from the file or --set)
};

/// Applies "--set a.b.c=value" overrides to a parsed document. The value is read as TOML
/// (0.75, "text", [1, 2]); anything that is not valid TOML is taken as a plain string. Every
/// node an override creates carries the option as its source, so that a message about it names
/// the option. Throws InputError for an override that is not KEY=VALUE.
///
/// `alternatives` are groups of dotted keys of which a config gives one (mill.speed or
/// mill.speed_rpm): an override of one removes the others where the file gives them, so that
/// `--set mill.speed_rpm=20` works on a config that gives mill.speed. Those given by another
/// override stay, for the reader to refuse as given twice.
void apply_overrides(toml::table& document, const std::vector<std::string>& overrides,
                     const std::vector<std::vector<std::string_view>>& alternatives = {});

}  // namespace millsim
