#include "millsim/io/toml_reader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>
#include <utility>

#include "millsim/core/error.hpp"

namespace millsim {
namespace {

constexpr std::string_view override_prefix = "--set ";
constexpr std::string_view override_allowed =
    "KEY=VALUE with a dotted config key, e.g. --set mill.speed=0.75";

bool from_override(const toml::node& node) {
  const auto& path = node.source().path;
  return path && path->starts_with(override_prefix);
}

std::string_view trim(std::string_view text) {
  constexpr std::string_view blank = " \t\r\n";
  const auto first = text.find_first_not_of(blank);
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(blank);
  return text.substr(first, last - first + 1);
}

/// `text` with control characters escaped, so that a message stays on one line.
std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      out += fmt::format("\\x{:02x}", static_cast<unsigned>(static_cast<unsigned char>(c)));
    } else {
      out += c;
    }
  }
  return out;
}

bool bare_key_character(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-';
}

std::string type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::table:
      return "a table";
    default:
      return "a date or time";
  }
}

/// The value as the user wrote it, for scalars; its kind otherwise.
std::string describe(const toml::node& node) {
  if (const auto* s = node.as_string()) return fmt::format("\"{}\"", printable(s->get()));
  if (const auto* i = node.as_integer()) return fmt::format("{}", i->get());
  if (const auto* f = node.as_floating_point()) return fmt::format("{}", f->get());
  if (const auto* b = node.as_boolean()) return b->get() ? "true" : "false";
  return type_name(node);
}

/// "\"0.9\" is a string", "a table is not allowed here": the first half of a type error.
std::string wrong_type(const toml::node& node) {
  if (const auto* text = node.as_string(); text != nullptr && from_override(node)) {
    // A --set value TOML could not read is kept as text, all of it: say why, where it looks
    // like a number (not where a string was typed as one: --set KEY="0.9", or one inside an
    // array or table that TOML read).
    const std::string_view option = *node.source().path;
    const std::string_view value =
        trim(option.substr(std::min(option.size(), option.find('=') + 1)));
    const std::string_view typed = text->get() == value ? value : std::string_view();
    const bool digits = !typed.empty() && std::all_of(typed.begin(), typed.end(), [](char c) {
      return std::isdigit(static_cast<unsigned char>(c)) != 0 || c == '+' || c == '-' || c == '.' ||
             c == 'e' || c == 'E' || c == '_';
    });
    if (digits && std::isdigit(static_cast<unsigned char>(typed.back())) != 0) {
      return fmt::format(
          "{} is a string (TOML did not read it as a number: its numbers have a digit on "
          "each side of a point, no leading zero, and lie within ±9223372036854775807 if "
          "whole, ±1.8e308 if not)",
          describe(node));
    }
  }
  if (node.is_string() || node.is_number() || node.is_boolean()) {
    return fmt::format("{} is {}", describe(node), type_name(node));
  }
  return fmt::format("{} is not allowed here", type_name(node));
}

const toml::table& empty_table() {
  static const toml::table empty;
  return empty;
}

/// Optimal string alignment distance (edits, counting a swap of neighbours as one).
std::size_t edit_distance(std::string_view a, std::string_view b) {
  const std::size_t n = a.size();
  const std::size_t m = b.size();
  std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1));
  for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= n; ++i) {
    for (std::size_t j = 1; j <= m; ++j) {
      const auto lower = [](char c) { return std::tolower(static_cast<unsigned char>(c)); };
      const std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) &&
          lower(a[i - 2]) == lower(b[j - 1])) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[n][m];
}

/// The allowed key closest to `key`, if it is close enough to be a likely misspelling.
}  // namespace

std::optional<std::string_view> closest_key(std::string_view key,
                                            std::span<const std::string_view> keys) {
  std::optional<std::string_view> best;
  // Two edits of a short key make another word: "young" is two from "count" (a suggestion an
  // adversarial review found in [materials.ball_ball]). Two only from nine letters on.
  std::size_t best_distance = key.size() < 9 ? 1 : 2;
  for (const std::string_view candidate : keys) {
    const std::size_t distance = edit_distance(key, candidate);
    if (distance <= best_distance && (!best || distance < edit_distance(key, *best))) {
      best = candidate;
      best_distance = distance;
    }
  }
  return best;
}

namespace {

bool valid_key_part(std::string_view part) {
  return !part.empty() && std::all_of(part.begin(), part.end(), bare_key_character);
}

/// A TOML document `value = <text>` whose nodes name `option` as their source.
toml::table parse_override_value(std::string_view text, const std::string& option) {
  if (line_of_overlong_key(text)) {
    throw InputError(fmt::format(
        "command line ({}): the value holds a dotted key of more than {} parts; allowed: {}",
        option, max_key_parts, override_allowed));
  }
  try {
    toml::table parsed = toml::parse(fmt::format("value = {}", text), std::string_view(option));
    if (parsed.size() != 1) {
      // More TOML after the value's end (on a line of its own): it would be dropped unread.
      throw InputError(fmt::format(
          "command line ({}): more than one value (the text after the first line's value is "
          "more TOML); allowed: one value, e.g. --set mill.speed=0.75",
          option));
    }
    return parsed;
  } catch (const toml::parse_error&) {
    // Not a TOML value: take the text as a plain string.
  }
  std::string quoted;
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      quoted += '\\';
      quoted += c;
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      quoted += fmt::format("\\u{:04x}", static_cast<unsigned>(static_cast<unsigned char>(c)));
    } else {
      quoted += c;
    }
  }
  try {
    return toml::parse(fmt::format("value = \"{}\"", quoted), std::string_view(option));
  } catch (const toml::parse_error& error) {
    throw InputError(fmt::format("command line ({}): cannot read the value ({}); allowed: {}",
                                 option, error.description(), override_allowed));
  }
}

}  // namespace

std::optional<std::size_t> line_of_overlong_key(std::string_view text) {
  // A chain is a run of key parts (bare words or quoted strings) joined by dots, blanks allowed
  // around the dots; anything else ends it. `dots` counts the current chain's dots.
  std::size_t line = 1;
  std::size_t dots = 0;
  bool after_part = false;  // the last thing read was a key part (or a word of a value)
  std::size_t i = 0;
  const std::size_t n = text.size();
  // Skips the string that starts at i (its opening quote), counting its lines.
  const auto skip_string = [&] {
    const char quote = text[i];
    const std::string_view three = quote == '"' ? std::string_view("\"\"\"") : "'''";
    const bool multi_line = text.substr(i, 3) == three;
    const bool escapes = quote == '"';
    i += multi_line ? 3 : 1;
    while (i < n) {
      const char c = text[i];
      if (escapes && c == '\\') {
        if (i + 1 < n && text[i + 1] == '\n') ++line;
        i += 2;
        continue;
      }
      if (c == '\n') {
        if (!multi_line) return;  // an unclosed string: the parser will say so
        ++line;
      }
      if (c == quote && (!multi_line || text.substr(i, 3) == three)) {
        i += multi_line ? 3 : 1;
        // A multi-line string may end in one or two quotes of its own before its three.
        while (multi_line && i < n && text[i] == quote) ++i;
        return;
      }
      ++i;
    }
  };
  while (i < n) {
    const char c = text[i];
    if (c == '"' || c == '\'') {
      skip_string();
      after_part = true;
      continue;
    }
    if (c == '#') {
      while (i < n && text[i] != '\n') ++i;
      continue;
    }
    if (c == '.' && after_part) {
      if (++dots >= max_key_parts) return line;
      after_part = false;
    } else if (bare_key_character(c)) {
      after_part = true;
    } else if (c != ' ' && c != '\t') {
      dots = 0;
      after_part = false;
      if (c == '\n') ++line;
    }
    ++i;
  }
  return std::nullopt;
}

std::string describe_value(const toml::node& node) {
  return describe(node);
}

std::string source_location(const toml::node& node, std::string_view fallback_file) {
  const auto& source = node.source();
  if (from_override(node)) return fmt::format("command line ({})", *source.path);
  const std::string_view file =
      source.path && !source.path->empty() ? std::string_view(*source.path) : fallback_file;
  if (source.begin.line == 0) return std::string(file);
  return fmt::format("{}:{}", file, source.begin.line);
}

TableReader::TableReader(const toml::table& table, std::string path, std::string file,
                         KeyLocations* locations)
    : TableReader(table, std::move(path), std::move(file), locations, {}, true) {
  // The document root starts on line 1 whatever it holds; name only the file for it.
  where_ = path_.empty() ? file_ : source_location(table, file_);
}

TableReader::TableReader(const toml::table& table, std::string path, std::string file,
                         KeyLocations* locations, std::string where, bool present)
    : table_(&table),
      path_(std::move(path)),
      file_(std::move(file)),
      locations_(locations),
      where_(std::move(where)),
      present_(present) {}

std::string TableReader::dotted(std::string_view key) const {
  return path_.empty() ? std::string(key) : fmt::format("{}.{}", path_, key);
}

std::string TableReader::table_name() const {
  if (path_.empty()) return "the top level";
  if (path_.find('[') != std::string::npos) return path_;  // an element of an array
  return fmt::format("[{}]", path_);
}

void TableReader::allow_keys(std::span<const std::string_view> keys,
                             const std::function<std::string(std::string_view)>& hint) {
  std::string list;
  for (const std::string_view k : keys)
    list += list.empty() ? std::string(k) : fmt::format(", {}", k);
  for (const auto& [key, value] : *table_) {
    const std::string_view name = key.str();
    if (std::find(keys.begin(), keys.end(), name) != keys.end()) continue;
    std::string remark;
    if (const auto near = closest_key(name, keys)) {
      remark = fmt::format(" (did you mean {}?)", *near);
    } else if (hint) {
      const std::string h = hint(name);
      if (!h.empty()) remark = fmt::format(" ({})", h);
    }
    const std::string where = source_location(value, file_);
    // The name as written, control characters escaped (a NUL would end the message there).
    const std::string shown = printable(name);
    if (path_.empty()) {
      throw InputError(fmt::format("{}: {}: unknown {}{}; allowed at the top level: the tables {}",
                                   where, shown, value.is_table() ? "table" : "key", remark, list));
    }
    throw InputError(fmt::format("{}: {}: unknown key{}; allowed in {}: {}", where, dotted(shown),
                                 remark, table_name(), list));
  }
}

bool TableReader::has(std::string_view key) const {
  return table_->contains(key);
}

const toml::node* TableReader::node(std::string_view key) {
  const toml::node* n = table_->get(key);
  if (n != nullptr && locations_ != nullptr) {
    (*locations_)[dotted(key)] = source_location(*n, file_);
  }
  return n;
}

std::string TableReader::location(std::string_view key) const {
  const toml::node* at = table_->get(key);
  return at != nullptr ? source_location(*at, file_) : where_;
}

void TableReader::fail_at(std::string_view key, const std::string& message) const {
  throw InputError(fmt::format("{}: {}: {}", location(key), dotted(key), message));
}

void TableReader::fail_at_node(const toml::node& at, std::string_view label,
                               const std::string& message) const {
  throw InputError(fmt::format("{}: {}: {}", source_location(at, file_), label, message));
}

void TableReader::fail_missing(std::string_view key, std::string_view allowed) const {
  if (path_.empty()) {
    throw InputError(
        fmt::format("{}: {}: missing required table [{}]; allowed: {}", file_, key, key, allowed));
  }
  if (!present_) {
    throw InputError(
        fmt::format("{}: {}: missing required key, and there is no {} table; "
                    "allowed: {}",
                    file_, dotted(key), table_name(), allowed));
  }
  if (from_override(*table_)) {
    // The table exists only because an override put a key in it.
    throw InputError(
        fmt::format("{}: {}: missing required key; {} is not in the file, only in "
                    "{}; allowed: {}",
                    file_, dotted(key), table_name(), where_, allowed));
  }
  throw InputError(
      fmt::format("{}: {}: missing required key in {}, which starts on this line; "
                  "allowed: {}",
                  where_, dotted(key), table_name(), allowed));
}

std::optional<double> TableReader::optional_number(std::string_view key, std::string_view allowed,
                                                   const std::function<bool(double)>& valid) {
  const toml::node* n = node(key);
  if (n == nullptr) return std::nullopt;
  if (!n->is_number()) fail_at(key, fmt::format("{}; allowed: {}", wrong_type(*n), allowed));
  const double value = n->value<double>().value_or(0.0);
  if (!std::isfinite(value) || !valid(value)) {
    fail_at(key, fmt::format("{} is not allowed; allowed: {}", describe(*n), allowed));
  }
  return value;
}

double TableReader::number(std::string_view key, std::optional<double> fallback,
                           std::string_view allowed, const std::function<bool(double)>& valid) {
  const std::optional<double> value = optional_number(key, allowed, valid);
  if (value) return *value;
  if (!fallback) fail_missing(key, allowed);
  return *fallback;
}

long TableReader::integer(std::string_view key, std::optional<long> fallback,
                          std::string_view allowed, const std::function<bool(long)>& valid) {
  const toml::node* n = node(key);
  if (n == nullptr) {
    if (!fallback) fail_missing(key, allowed);
    return *fallback;
  }
  long value = 0;
  if (const auto* i = n->as_integer()) {
    value = static_cast<long>(i->get());
  } else if (const auto* f = n->as_floating_point()) {
    // 8.0 is a whole number written as a float; 8.5 and nan are not. Beyond 2^53 a float
    // stands for several whole numbers (1e16 for 1e16 ± 1): such a one must be an integer.
    constexpr double exact = 9007199254740992.0;  // 2^53
    const double x = f->get();
    if (!std::isfinite(x) || std::floor(x) != x) {
      fail_at(key, fmt::format("{} is not a whole number; allowed: {}", describe(*n), allowed));
    }
    if (std::abs(x) > exact) {
      fail_at(key, fmt::format("{} is a float beyond 2^53, which cannot say which whole number it "
                               "is; allowed: {}, written as an integer (no point or exponent)",
                               describe(*n), allowed));
    }
    value = static_cast<long>(x);
  } else {
    fail_at(key, fmt::format("{}; allowed: {}", wrong_type(*n), allowed));
  }
  if (!valid(value)) fail_at(key, fmt::format("{} is not allowed; allowed: {}", value, allowed));
  return value;
}

std::vector<double> TableReader::numbers(std::string_view key, std::size_t length,
                                         std::optional<std::vector<double>> fallback,
                                         std::string_view allowed) {
  const toml::node* n = node(key);
  if (n == nullptr) {
    if (!fallback) fail_missing(key, allowed);
    return *fallback;
  }
  const toml::array* array = n->as_array();
  if (array == nullptr) fail_at(key, fmt::format("{}; allowed: {}", wrong_type(*n), allowed));
  if (array->size() != length) {
    fail_at(key, fmt::format("an array of {} values is not allowed; allowed: {}", array->size(),
                             allowed));
  }
  std::vector<double> values;
  for (const toml::node& element : *array) {
    const std::optional<double> x = element.is_number() ? element.value<double>() : std::nullopt;
    if (!x || !std::isfinite(*x)) {
      fail_at(key, fmt::format("element {} is not a finite number; allowed: {}", describe(element),
                               allowed));
    }
    values.push_back(*x);
  }
  return values;
}

bool TableReader::boolean(std::string_view key, bool fallback, std::string_view allowed) {
  const toml::node* n = node(key);
  if (n == nullptr) return fallback;
  if (const auto* b = n->as_boolean()) return b->get();
  fail_at(key, fmt::format("{}; allowed: {}", wrong_type(*n), allowed));
}

std::string TableReader::string(std::string_view key, std::optional<std::string> fallback,
                                std::string_view allowed) {
  const toml::node* n = node(key);
  if (n == nullptr) {
    if (!fallback) fail_missing(key, allowed);
    return *fallback;
  }
  if (const auto* s = n->as_string()) return s->get();
  if (from_override(*n) && !n->is_table()) {
    // "--set output.directory=2024": the text after '=' as typed.
    const std::string& option = *n->source().path;
    return std::string(trim(std::string_view(option).substr(option.find('=') + 1)));
  }
  fail_at(key, fmt::format("{}; allowed: {}", wrong_type(*n), allowed));
}

TableReader TableReader::table(std::string_view key, bool required, std::string_view allowed) {
  const std::string description =
      allowed.empty() ? fmt::format("a table [{}]", dotted(key)) : std::string(allowed);
  const toml::node* n = node(key);
  if (n == nullptr) {
    if (required) fail_missing(key, description);
    return TableReader(empty_table(), dotted(key), file_, locations_, where_, false);
  }
  if (!n->is_table()) {
    const std::string what = n->is_array() || n->is_date() || n->is_time() || n->is_date_time()
                                 ? type_name(*n)
                                 : fmt::format("{} is {}", describe(*n), type_name(*n));
    fail_at(key, fmt::format("{}, not a table; allowed: {}", what, description));
  }
  return TableReader(*n->as_table(), dotted(key), file_, locations_, source_location(*n, file_),
                     true);
}

namespace {

/// Removes the dotted `key` from `document` if it is there.
void erase_key(toml::table& document, std::string_view key) {
  toml::table* table = &document;
  for (std::size_t start = 0;;) {
    const auto dot = key.find('.', start);
    const std::string part(key.substr(start, dot == std::string_view::npos ? dot : dot - start));
    if (dot == std::string_view::npos) {
      table->erase(part);
      return;
    }
    toml::node* next = table->get(part);
    if (next == nullptr || !next->is_table()) return;
    table = next->as_table();
    start = dot + 1;
  }
}

}  // namespace

void apply_overrides(toml::table& document, const std::vector<std::string>& overrides,
                     const std::vector<std::vector<std::string_view>>& alternatives) {
  std::vector<std::pair<std::string, std::string>> given;  // key, option: each key once
  for (const std::string& text : overrides) {
    const std::string option = fmt::format("{}{}", override_prefix, printable(text));
    const std::string where = fmt::format("command line ({})", option);
    const auto equals = text.find('=');
    if (equals == std::string::npos) {
      throw InputError(fmt::format("{}: no '=' between the key and the value; allowed: {}", where,
                                   override_allowed));
    }
    const std::string_view key = trim(std::string_view(text).substr(0, equals));
    if (key.empty()) {
      throw InputError(fmt::format("{}: no key before '='; allowed: {}", where, override_allowed));
    }
    std::vector<std::string_view> parts;
    for (std::size_t start = 0;;) {
      const auto dot = key.find('.', start);
      parts.push_back(key.substr(start, dot == std::string_view::npos ? dot : dot - start));
      if (!valid_key_part(parts.back())) {
        throw InputError(fmt::format(
            "{}: {}: '{}' is not a valid key name; allowed: names of letters, digits, _ and - "
            "joined by dots, e.g. mill.lifters.count",
            where, printable(key), printable(parts.back())));
      }
      if (dot == std::string_view::npos) break;
      start = dot + 1;
    }
    toml::table parsed =
        parse_override_value(trim(std::string_view(text).substr(equals + 1)), option);
    if (parsed.get("value")->is_table()) {
      // It would replace the whole table, dropping every key of it the file gives.
      throw InputError(fmt::format(
          "{}: {}: a table would replace all of [{}] in the config; allowed: its keys one by one, "
          "e.g. --set {}.KEY=VALUE",
          where, printable(key), printable(key), printable(key)));
    }
    for (const auto& [earlier_key, earlier_option] : given) {
      if (earlier_key == key) {
        throw InputError(fmt::format("{}: {}: given twice, also as {}; allowed: each key once",
                                     where, printable(key), earlier_option));
      }
    }
    given.emplace_back(std::string(key), option);

    // Walk to the parent table, creating the missing tables with the option as their source.
    toml::table* table = &document;
    for (std::size_t k = 0; k + 1 < parts.size(); ++k) {
      const std::string part(parts[k]);
      toml::node* next = table->get(part);
      if (next == nullptr) {
        toml::table created = parse_override_value("{}", option);
        toml::node& fresh = *created.get("value");
        fresh.as_table()->is_inline(false);
        table->insert(part, std::move(*fresh.as_table()));
        next = table->get(part);
      }
      if (!next->is_table()) {
        const auto parent_end =
            static_cast<std::size_t>(parts[k].data() - key.data()) + part.size();
        const std::string_view parent = key.substr(0, parent_end);
        throw InputError(
            fmt::format("{}: {}: cannot set a key inside {}, which is {}, not a table; allowed: {}",
                        where, key, parent, type_name(*next), override_allowed));
      }
      table = next->as_table();
    }
    parsed.get("value")->visit(
        [&](auto& value) { table->insert_or_assign(std::string(parts.back()), std::move(value)); });
  }
  const auto overridden = [&](std::string_view key) {
    return std::any_of(given.begin(), given.end(), [&](const auto& g) { return g.first == key; });
  };
  for (const std::vector<std::string_view>& group : alternatives) {
    if (std::none_of(group.begin(), group.end(), overridden)) continue;
    for (const std::string_view key : group) {
      if (!overridden(key)) erase_key(document, key);
    }
  }
}

}  // namespace millsim
