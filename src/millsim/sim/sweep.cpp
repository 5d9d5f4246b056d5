#include "millsim/sim/sweep.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <exception>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <system_error>
#include <thread>

#include "millsim/core/error.hpp"
#include "millsim/io/partial_file.hpp"

namespace millsim {
namespace {

/// A count as a whole number, or in powers of ten when it has too many digits to read.
std::string count_text(double count) {
  return count < 1e15 ? fmt::format("{:.0f}", count) : fmt::format("{:.3g}", count);
}

constexpr std::string_view vary_allowed =
    "KEY=START:STOP:STEP (numbers; STEP not 0 and leading from START towards STOP) or "
    "KEY=V1,V2,... (each a TOML value or text, as for --set; commas inside a string, array or "
    "table belong to the value), e.g. mill.speed=0.3:0.9:0.1 or "
    "charge.filling=0.2,0.3,0.4";

/// A range's values are counted as whole steps from START; STOP is included when it is within
/// this fraction of a step of the last one (it rarely lands exactly: 0.3 + 6 × 0.1 ≠ 0.9).
constexpr double stop_tolerance_steps = 1e-9;
/// Places written in fixed notation at most; a range that needs more (a step of 1e-40, say)
/// is rounded to significant digits instead (decimal_text).
constexpr int max_decimals = 30;
/// Significant digits a range's values keep when they need more than max_decimals places:
/// enough to drop the noise of START + i × STEP (0.3 + 6 × 0.1), not the values typed.
constexpr int range_significant_digits = 15;

std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

std::optional<double> read_number(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() ||
      !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

/// Where `separator` occurs in `text` outside TOML strings and outside arrays and inline
/// tables, so that a value such as "a,b" or [{diameter = 0.1, mass_fraction = 1}] stays whole.
/// At the top level a quote or bracket opens a string or array only as the first character of
/// a value, as in TOML: in plain text (it's, a[1) it is a character like any other, and the
/// comma after it still ends the value. Strings are basic ("...", with \ escapes), literal
/// ('...') or multi-line (""" or '''). An unclosed one runs to the end of the text: the value is
/// then read as --set reads it (refused if its key takes a number; text if it takes text).
/// A top-level comma starts a new value whatever the separator looked for, so that in
/// "a","b:c" the colon is inside the second value's string.
std::vector<std::size_t> top_level_positions(std::string_view text, char separator) {
  std::vector<std::size_t> positions;
  int depth = 0;
  bool value_started = false;  // a character other than a blank seen since the last separator
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    const bool opens_here = depth > 0 || !value_started;
    if (c != ' ' && c != '\t') value_started = true;
    if (opens_here && (c == '"' || c == '\'')) {
      const std::size_t quotes = text.substr(i, 3) == std::string(3, c) ? 3 : 1;
      const std::string_view closing = text.substr(i, quotes);
      std::size_t j = i + quotes;
      while (j < text.size() && text.substr(j, quotes) != closing) {
        j += c == '"' && text[j] == '\\' ? 2 : 1;  // an escape: the next character is not a quote
      }
      i = std::min(text.size(), j + quotes);
      continue;
    }
    if (opens_here && (c == '[' || c == '{')) {
      ++depth;
    } else if (depth > 0 && (c == ']' || c == '}')) {
      --depth;
    } else if (depth == 0 && (c == separator || c == ',')) {
      if (c == separator) positions.push_back(i);
      value_started = false;
    }
    ++i;
  }
  return positions;
}

std::vector<std::string> split(std::string_view text, char separator) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (const std::size_t at : top_level_positions(text, separator)) {
    parts.emplace_back(trim(text.substr(start, at - start)));
    start = at + 1;
  }
  parts.emplace_back(trim(text.substr(start)));
  return parts;
}

std::vector<std::string> range_values(const std::vector<std::string>& parts,
                                      const std::string& where) {
  const char* names[] = {"START", "STOP", "STEP"};
  double number[3] = {};
  for (int k = 0; k < 3; ++k) {
    const std::optional<double> value = read_number(parts[k]);
    if (!value) {
      throw InputError(fmt::format("{}: {} \"{}\" is not a number; allowed: {}", where, names[k],
                                   parts[k], vary_allowed));
    }
    number[k] = *value;
  }
  const auto [start, stop, step] = number;
  if (step == 0.0) {
    throw InputError(fmt::format("{}: STEP is 0; allowed: {}", where, vary_allowed));
  }
  const double steps = (stop - start) / step;
  if (steps < -stop_tolerance_steps) {
    throw InputError(fmt::format("{}: STEP {} leads away from STOP {}; allowed: {}", where,
                                 parts[2], parts[1], vary_allowed));
  }
  const double last = std::floor(steps + stop_tolerance_steps * std::max(1.0, steps));
  if (last + 1.0 > static_cast<double>(max_sweep_points)) {
    throw InputError(fmt::format("{}: {} values; allowed: at most {} values", where,
                                 count_text(last + 1.0), max_sweep_points));
  }
  const int decimals = std::max(decimal_places(parts[0]), decimal_places(parts[2]));
  std::vector<std::string> values;
  for (std::size_t i = 0; i <= static_cast<std::size_t>(last); ++i) {
    values.push_back(decimal_text(start + static_cast<double>(i) * step, decimals));
  }
  return values;
}

std::optional<double> scalar(const SweepRow& row, std::string_view name) {
  for (const auto& [key, value] : row.scalars) {
    if (key == name) return value;
  }
  return std::nullopt;
}

}  // namespace

namespace {

/// A CSV field, quoted when it holds a separator, a quote or a line break (RFC 4180).
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

/// A name's characters hashed (32-bit FNV-1a), the same on every machine and run.
std::uint32_t stable_hash(std::string_view text) {
  std::uint32_t hash = 2166136261U;
  for (const char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 16777619U;
  }
  return hash;
}

}  // namespace

bool is_config_key(std::string_view key) {
  if (key.empty() || key.front() == '.' || key.back() == '.') return false;
  if (key.find("..") != std::string_view::npos) return false;
  return std::all_of(key.begin(), key.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-' || c == '.';
  });
}

std::string csv_line(const std::vector<std::string>& cells) {
  std::string line;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    if (k > 0) line += ',';
    line += csv_field(cells[k]);
  }
  line += '\n';
  return line;
}

SweepAxis parse_vary(std::string_view argument) {
  const std::string where = fmt::format("command line (--vary {})", argument);
  const auto equals = argument.find('=');
  if (equals == std::string_view::npos) {
    throw InputError(
        fmt::format("{}: no '=' between the key and the values; allowed: {}", where, vary_allowed));
  }
  SweepAxis axis;
  axis.key = std::string(trim(argument.substr(0, equals)));
  if (!is_config_key(axis.key)) {
    throw InputError(fmt::format(
        "{}: \"{}\" is not a key; allowed: names of letters, digits, _ and - joined by dots, "
        "e.g. mill.speed",
        where, axis.key));
  }
  if (axis.key == "output.directory") {
    throw InputError(fmt::format(
        "{}: output.directory is set per point by the sweep; allowed: any other key (--out "
        "sets where the points go)",
        where));
  }
  const std::string_view spec = trim(argument.substr(equals + 1));
  if (!top_level_positions(spec, ':').empty()) {
    const std::vector<std::string> parts = split(spec, ':');
    if (parts.size() != 3) {
      throw InputError(fmt::format("{}: \"{}\" has {} parts separated by ':', not 3; allowed: {}",
                                   where, spec, parts.size(), vary_allowed));
    }
    axis.values = range_values(parts, where);
    return axis;
  }
  axis.values = split(spec, ',');
  for (std::size_t i = 0; i < axis.values.size(); ++i) {
    if (axis.values[i].empty()) {
      throw InputError(fmt::format("{}: value {} of the list is empty; allowed: {}", where, i + 1,
                                   vary_allowed));
    }
  }
  return axis;
}

int decimal_places(std::string_view number) {
  const auto exponent_at = number.find_first_of("eE");
  int exponent = 0;
  if (exponent_at != std::string_view::npos) {
    std::string_view digits = number.substr(exponent_at + 1);
    if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
    std::from_chars(digits.data(), digits.data() + digits.size(), exponent);
    number = number.substr(0, exponent_at);
  }
  const auto point = number.find('.');
  const int fraction =
      point == std::string_view::npos ? 0 : static_cast<int>(number.size() - point - 1);
  // (A number of a double's range needs at most some 1100 places: 4.9e-324 written out.)
  return std::clamp(fraction - exponent, 0, 2000);
}

std::string decimal_text(double value, int decimals) {
  // Rounded to a fixed number of places, 1e-40 + 1e-40 would be written "0": past
  // max_decimals, to significant digits.
  const std::string rounded = decimals > max_decimals
                                  ? fmt::format("{:.{}g}", value, range_significant_digits)
                                  : fmt::format("{:.{}f}", value, std::max(decimals, 0));
  double exact = 0.0;
  std::from_chars(rounded.data(), rounded.data() + rounded.size(), exact);
  if (exact == 0.0) exact = 0.0;  // no "-0"
  return fmt::format("{}", exact);
}

void check_sweep_axes(const std::vector<SweepAxis>& axes) {
  double count = 1.0;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    count *= static_cast<double>(axes[k].values.size());
    for (std::size_t j = 0; j < k; ++j) {
      if (axes[j].key == axes[k].key) {
        throw InputError(fmt::format(
            "command line (--vary {}=...): {} is varied twice; allowed: each key in one --vary",
            axes[k].key, axes[k].key));
      }
    }
  }
  if (count > static_cast<double>(max_sweep_points)) {
    throw InputError(fmt::format("command line (--vary): {} points; allowed: at most {}",
                                 count_text(count), max_sweep_points));
  }
}

std::vector<std::vector<std::string>> cartesian_product(const std::vector<SweepAxis>& axes) {
  std::vector<std::vector<std::string>> points{{}};
  for (const SweepAxis& axis : axes) {
    std::vector<std::vector<std::string>> longer;
    longer.reserve(points.size() * axis.values.size());
    for (const auto& point : points) {
      for (const std::string& value : axis.values) {
        longer.push_back(point);
        longer.back().push_back(value);
      }
    }
    points = std::move(longer);
  }
  return points;
}

std::vector<std::string> point_overrides(const std::vector<SweepAxis>& axes,
                                         const std::vector<std::string>& point) {
  std::vector<std::string> overrides;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    overrides.push_back(fmt::format("{}={}", axes[k].key, point[k]));
  }
  return overrides;
}

std::string point_directory_name(std::size_t index, std::size_t count,
                                 const std::vector<SweepAxis>& axes,
                                 const std::vector<std::string>& point) {
  const std::size_t width = std::max<std::size_t>(3, fmt::format("{}", count - 1).size());
  std::string values;
  for (const std::string& setting : point_overrides(axes, point)) {
    values += '_';
    for (const char c : setting) {
      const bool safe = std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '.' || c == '+' ||
                        c == '-' || c == '=' || c == '_';
      values += safe ? c : '_';
    }
  }
  // A long value (a list of size classes, say) is cut, and a hash of the whole keeps names
  // apart, within the 255 bytes a file name may have; sweep.csv has the whole values.
  if (values.size() > longest_point_values) {
    values =
        fmt::format("{}_{:08x}", values.substr(0, longest_point_values - 9), stable_hash(values));
  }
  return fmt::format("{:0{}d}", index, width) + values;
}

std::string sweep_csv(const std::vector<SweepAxis>& axes, const std::vector<SweepRow>& rows) {
  // Every row lists its scalars in summary_scalars order, leaving out those it does not have:
  // each new name goes in right after the name before it in its row, so that the columns keep
  // that order whichever rows have which.
  std::vector<std::string> names;
  for (const SweepRow& row : rows) {
    std::size_t at = 0;
    for (const auto& entry : row.scalars) {
      const auto found = std::find(names.begin(), names.end(), entry.first);
      if (found == names.end()) {
        names.insert(names.begin() + static_cast<std::ptrdiff_t>(at), entry.first);
        ++at;
      } else {
        at = static_cast<std::size_t>(found - names.begin()) + 1;
      }
    }
  }
  std::vector<std::string> header{"point", "directory"};
  for (const SweepAxis& axis : axes) header.push_back(axis.key);
  header.emplace_back("status");
  header.emplace_back("warnings");
  header.insert(header.end(), names.begin(), names.end());
  std::string text = csv_line(header);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const SweepRow& row = rows[i];
    std::map<std::string_view, double, std::less<>> values;
    for (const auto& [name, value] : row.scalars) values.emplace(name, value);
    std::vector<std::string> cells{fmt::format("{}", i), row.directory};
    cells.insert(cells.end(), row.values.begin(), row.values.end());
    cells.push_back(row.status);
    std::string warnings;
    for (const std::string& warning : row.warnings) {
      warnings += (warnings.empty() ? "" : "; ") + warning;
    }
    cells.push_back(warnings);
    for (const std::string& name : names) {
      const auto found = values.find(name);
      // A number the point has none of (NaN) leaves its cell empty, as a failed point does.
      const bool has = found != values.end() && !std::isnan(found->second);
      cells.push_back(has ? fmt::format("{}", found->second) : std::string());
    }
    text += csv_line(cells);
  }
  return text;
}

std::vector<std::vector<std::string>> csv_rows(std::string_view text) {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> row;
  std::string cell;
  bool quoted = false;
  bool cell_started = false;
  for (std::size_t k = 0; k < text.size(); ++k) {
    const char c = text[k];
    if (quoted) {
      if (c != '"') {
        cell += c;
      } else if (k + 1 < text.size() && text[k + 1] == '"') {
        cell += '"';
        ++k;
      } else {
        quoted = false;
      }
    } else if (c == '"' && !cell_started) {
      quoted = true;
      cell_started = true;
    } else if (c == ',') {
      row.push_back(std::move(cell));
      cell.clear();
      cell_started = false;
    } else if (c == '\n' || c == '\r') {
      if (c == '\r' && k + 1 < text.size() && text[k + 1] == '\n') ++k;
      row.push_back(std::move(cell));
      rows.push_back(std::move(row));
      row.clear();
      cell.clear();
      cell_started = false;
    } else {
      cell += c;
      cell_started = true;
    }
  }
  if (cell_started || !row.empty()) {
    row.push_back(std::move(cell));
    rows.push_back(std::move(row));
  }
  return rows;
}

void write_sweep_csv(const std::filesystem::path& path, const std::vector<SweepAxis>& axes,
                     const std::vector<SweepRow>& rows) {
  write_whole_file(path, sweep_csv(axes, rows));
}

ThreadShare share_threads(int threads, std::size_t points) {
  ThreadShare share;
  if (threads <= 1 || points <= 1) {
    share.threads_each = std::max(threads, 1);
    return share;
  }
  share.at_a_time =
      static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(threads), points));
  share.threads_each = threads / share.at_a_time;
  return share;
}

std::string describe(const ThreadShare& share) {
  if (share.at_a_time <= 1) return "one at a time";
  if (share.threads_each <= 1) return fmt::format("{} at a time", share.at_a_time);
  return fmt::format("{} at a time, {} threads each", share.at_a_time, share.threads_each);
}

void run_shared(std::size_t count, const ThreadShare& share,
                const std::function<void(std::size_t)>& job) {
  if (share.at_a_time <= 1) {
    for (std::size_t i = 0; i < count; ++i) job(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::mutex failing;
  std::exception_ptr failure;
  const auto take_jobs = [&] {
    omp_set_num_threads(share.threads_each);
    for (std::size_t i = next++; i < count; i = next++) {
      try {
        job(i);
      } catch (...) {
        const std::lock_guard lock(failing);
        if (!failure) failure = std::current_exception();
        next = count;
      }
    }
  };
  {
    std::vector<std::jthread> pool;
    pool.reserve(static_cast<std::size_t>(share.at_a_time));
    try {
      for (int t = 0; t < share.at_a_time; ++t) pool.emplace_back(take_jobs);
    } catch (const std::system_error&) {
      // No more threads to be had (a limit on the processes, say): those made take every job;
      // with none, this thread does, on its own setting once done.
      if (pool.empty()) {
        const int own = omp_get_max_threads();
        take_jobs();
        omp_set_num_threads(own);
      }
    }
  }
  if (failure) std::rethrow_exception(failure);
}

std::string sweep_table(const std::vector<SweepAxis>& axes, const std::vector<SweepRow>& rows) {
  constexpr const char* measures[] = {"power_kw", "power_dissipation_kw", "energy_balance_error"};
  std::vector<std::size_t> widths;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    std::size_t width = axes[k].key.size();
    for (const SweepRow& row : rows) width = std::max(width, row.values[k].size());
    widths.push_back(width);
  }
  std::string text;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    text += fmt::format("{:<{}}  ", axes[k].key, widths[k]);
  }
  for (const char* measure : measures) text += fmt::format("{:>{}}  ", measure, 20);
  text += "status\n";
  for (const SweepRow& row : rows) {
    for (std::size_t k = 0; k < axes.size(); ++k) {
      text += fmt::format("{:<{}}  ", row.values[k], widths[k]);
    }
    for (const char* measure : measures) {
      const std::optional<double> value = scalar(row, measure);
      text += value ? fmt::format("{:>20.4g}  ", *value) : fmt::format("{:>20}  ", "-");
    }
    text += row.status + "\n";
  }
  return text;
}

}  // namespace millsim
