#include "millsim/io/toml_reader.hpp"

#include <fmt/format.h>

#include <cmath>

#include "millsim/core/error.hpp"

namespace millsim {
namespace {

constexpr std::string_view override_prefix = "--set ";

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

std::string describe(const toml::node& node) {
  if (const auto* s = node.as_string()) return fmt::format("\"{}\"", s->get());
  if (const auto* i = node.as_integer()) return fmt::format("{}", i->get());
  if (const auto* f = node.as_floating_point()) return fmt::format("{}", f->get());
  return type_name(node);
}

const toml::table& empty_table() {
  static const toml::table empty;
  return empty;
}

}  // namespace

std::string source_location(const toml::node& node, std::string_view fallback_file) {
  const auto& source = node.source();
  if (source.path && source.path->starts_with(override_prefix)) {
    return fmt::format("command line ({})", *source.path);
  }
  const std::string_view file =
      source.path && !source.path->empty() ? std::string_view(*source.path) : fallback_file;
  if (source.begin.line == 0) return std::string(file);
  return fmt::format("{}:{}", file, source.begin.line);
}

TableReader::TableReader(const toml::table& table, std::string path, std::string file)
    : table_(&table), path_(std::move(path)), file_(std::move(file)) {}

std::string TableReader::dotted(std::string_view key) const {
  return path_.empty() ? std::string(key) : fmt::format("{}.{}", path_, key);
}

bool TableReader::has(std::string_view key) const {
  return table_->contains(key);
}

const toml::node* TableReader::node(std::string_view key) {
  asked_.emplace(key);
  return table_->get(key);
}

void TableReader::fail_at(std::string_view key, const std::string& message) const {
  const toml::node* at = table_->get(key);
  const std::string where =
      source_location(at ? *at : static_cast<const toml::node&>(*table_), file_);
  throw InputError(fmt::format("{}: {}: {}", where, dotted(key), message));
}

void TableReader::fail_missing(std::string_view key, std::string_view allowed) const {
  const std::string where = source_location(*table_, file_);
  const std::string table_name = path_.empty() ? "the top level" : fmt::format("[{}]", path_);
  throw InputError(fmt::format("{}: {}: missing required key in {}; allowed: {}", where,
                               dotted(key), table_name, allowed));
}

std::optional<double> TableReader::optional_number(std::string_view key, std::string_view allowed,
                                                   const std::function<bool(double)>& valid) {
  const toml::node* n = node(key);
  if (n == nullptr) return std::nullopt;
  if (!n->is_number()) {
    fail_at(key, fmt::format("expected {}, got {}", allowed, type_name(*n)));
  }
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
  if (!n->is_integer()) fail_at(key, fmt::format("expected {}, got {}", allowed, describe(*n)));
  const long value = static_cast<long>(n->as_integer()->get());
  if (!valid(value)) fail_at(key, fmt::format("{} is not allowed; allowed: {}", value, allowed));
  return value;
}

std::string TableReader::string(std::string_view key, std::optional<std::string> fallback,
                                std::string_view allowed) {
  const toml::node* n = node(key);
  if (n == nullptr) {
    if (!fallback) fail_missing(key, allowed);
    return *fallback;
  }
  if (!n->is_string()) fail_at(key, fmt::format("expected {}, got {}", allowed, type_name(*n)));
  return n->as_string()->get();
}

TableReader TableReader::table(std::string_view key, bool required) {
  const toml::node* n = node(key);
  if (n == nullptr) {
    if (required) fail_missing(key, fmt::format("a table [{}]", dotted(key)));
    return TableReader(empty_table(), dotted(key), file_);
  }
  if (!n->is_table()) fail_at(key, fmt::format("expected a table, got {}", type_name(*n)));
  return TableReader(*n->as_table(), dotted(key), file_);
}

void TableReader::refuse_unknown_keys(std::string_view allowed_keys) const {
  for (const auto& [key, value] : *table_) {
    if (asked_.contains(key.str())) continue;
    const std::string where = source_location(value, file_);
    const std::string table_name = path_.empty() ? "the top level" : fmt::format("[{}]", path_);
    throw InputError(fmt::format("{}: {}: unknown key; allowed in {}: {}", where, dotted(key.str()),
                                 table_name, allowed_keys));
  }
}

void apply_overrides(toml::table& document, const std::vector<std::string>& overrides) {
  for (const std::string& text : overrides) {
    const auto equals = text.find('=');
    const std::string option = fmt::format("{}{}", override_prefix, text);
    if (equals == std::string::npos || equals == 0) {
      throw InputError(
          fmt::format("command line ({}): expected KEY=VALUE, e.g. mill.speed=0.75", option));
    }
    const std::string key = text.substr(0, equals);
    const std::string value_text = text.substr(equals + 1);
    toml::table parsed;
    try {
      parsed = toml::parse(fmt::format("value = {}", value_text), std::string_view(option));
    } catch (const toml::parse_error&) {
      std::string quoted;
      for (const char c : value_text) {
        if (c == '"' || c == '\\') quoted += '\\';
        quoted += c;
      }
      try {
        parsed = toml::parse(fmt::format("value = \"{}\"", quoted), std::string_view(option));
      } catch (const toml::parse_error& error) {
        throw InputError(fmt::format("command line ({}): cannot read the value: {}", option,
                                     error.description()));
      }
    }
    // Walk to the parent table, creating tables as needed.
    toml::table* table = &document;
    std::size_t start = 0;
    for (;;) {
      const auto dot = key.find('.', start);
      const std::string part = key.substr(start, dot == std::string::npos ? dot : dot - start);
      if (part.empty()) {
        throw InputError(fmt::format("command line ({}): '{}' is not a valid key", option, key));
      }
      if (dot == std::string::npos) {
        parsed.get("value")->visit(
            [&](auto&& value) { table->insert_or_assign(part, std::move(value)); });
        break;
      }
      toml::node* next = table->get(part);
      if (next == nullptr) {
        table->insert(part, toml::table{});
        next = table->get(part);
      }
      if (!next->is_table()) {
        throw InputError(
            fmt::format("command line ({}): '{}' is not a table", option, key.substr(0, dot)));
      }
      table = next->as_table();
      start = dot + 1;
    }
  }
}

}  // namespace millsim
