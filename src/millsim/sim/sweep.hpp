// A parameter sweep (`millsim sweep`): the varied keys and their values, the cartesian product
// of them, a directory name per point, and the sweep.csv table. Pure functions; running the
// points is the program's job.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace millsim {

/// One `--vary KEY=SPEC`: a config key and the values it takes, as the TOML text given to the
/// config like a `--set KEY=VALUE` override.
struct SweepAxis {
  std::string key;
  std::vector<std::string> values;
};

/// The most points one axis or a whole sweep may have (a guard against a mistyped step).
inline constexpr std::size_t max_sweep_points = 10000;

/// Reads `KEY=START:STOP:STEP` (START, START + STEP, ... up to STOP, which is included within
/// a rounding tolerance; each value is START + i STEP, not a running sum) or `KEY=V1,V2,...`
/// (each value TOML, or text, as for --set). Throws InputError naming the argument and what is
/// allowed.
SweepAxis parse_vary(std::string_view argument);

/// Decimal places a number needs as written: "0.25" 2, "3" 0, "2.5e-4" 5, "1e3" 0.
int decimal_places(std::string_view number);

/// `value` rounded to `decimals` places and written in the fewest digits that read back as
/// that rounded value: (0.3 + 4 × 0.1, 1) gives "0.7", not "0.7000000000000001". Past 30
/// places (a value of 2e-40), rounded to 15 significant digits instead.
std::string decimal_text(double value, int decimals);

/// Throws InputError when two axes vary the same key or the sweep has more than
/// max_sweep_points points.
void check_sweep_axes(const std::vector<SweepAxis>& axes);

/// Every combination of the axes' values, one value per axis in axis order; the first axis
/// varies slowest (as nested loops written in the order of the --vary options).
std::vector<std::vector<std::string>> cartesian_product(const std::vector<SweepAxis>& axes);

/// The `--set`-style overrides of one point: "KEY=VALUE" for each axis.
std::vector<std::string> point_overrides(const std::vector<SweepAxis>& axes,
                                         const std::vector<std::string>& point);

/// The longest the `_KEY=VALUE` part of a point's directory name may be (point_directory_name).
inline constexpr std::size_t longest_point_values = 120;

/// The directory of point `index` of `count`: the zero-padded index (at least 3 digits), then
/// `_KEY=VALUE` per axis, with every character other than letters, digits and `.+-=_` made
/// `_`, e.g. "007_mill.speed=0.7_charge.filling=0.3". The index makes names unique. Values
/// longer than longest_point_values in all are cut there, ending in `_` and 8 hex digits of a
/// hash of the whole.
std::string point_directory_name(std::size_t index, std::size_t count,
                                 const std::vector<SweepAxis>& axes,
                                 const std::vector<std::string>& point);

/// The outcome of one point: its values, "ok", "failed: message" or "pending" (not yet run),
/// and (when it ran) every scalar of its summary in summary_scalars order; its directory's
/// name, and what made its results doubtful (its plan's and its results' warnings).
struct SweepRow {
  std::vector<std::string> values;
  std::string status;
  std::vector<std::pair<std::string, double>> scalars;
  std::string directory;
  std::vector<std::string> warnings;
};

/// Whether `key` has the shape of a dotted config key: names of letters, digits, _ and -
/// joined by dots (mill.speed), as --vary takes them.
bool is_config_key(std::string_view key);

/// One CSV line of `cells`, ended by a line break; a cell with a comma, quote or line break is
/// quoted (RFC 4180).
std::string csv_line(const std::vector<std::string>& cells);

/// sweep.csv: a header `point, directory, <each key>, status, warnings, <each scalar name>`,
/// then one row per point. The scalar columns are the names of all rows, in the order the
/// rows list them (summary_scalars's, whichever rows have which); a row without a scalar (a
/// failed point, a toe angle a centrifuging charge lacks) leaves its cell empty. Warnings are
/// joined by "; ". Fields with a comma, quote or line break are quoted (RFC 4180).
std::string sweep_csv(const std::vector<SweepAxis>& axes, const std::vector<SweepRow>& rows);

/// The rows of CSV text, each split into its fields (RFC 4180: quoted fields may hold commas,
/// doubled quotes and line breaks).
std::vector<std::vector<std::string>> csv_rows(std::string_view text);

/// Writes sweep_csv(axes, rows) to `path` under a temporary name (`path`.partial) and renames
/// it, so that a half-written file never appears. Throws std::runtime_error if it cannot.
void write_sweep_csv(const std::filesystem::path& path, const std::vector<SweepAxis>& axes,
                     const std::vector<SweepRow>& rows);

/// How a sweep's points share the threads: so many points at a time, each on so many threads.
struct ThreadShare {
  int at_a_time = 1;
  int threads_each = 1;
};

/// `points` points on `threads` threads: as many at a time as there are threads, or points if
/// fewer, and the threads divided evenly among those (the rest left idle). So a sweep of at
/// least as many points as threads runs them all on one thread each, a single point gets every
/// thread, and three points on eight threads run together on two threads each.
ThreadShare share_threads(int threads, std::size_t points);

/// "one at a time", "4 at a time" or "3 at a time, 2 threads each".
std::string describe(const ThreadShare& share);

/// Calls `job(i)` for every i below `count`, `share.at_a_time` at a time, each call's
/// parallel regions on `share.threads_each` threads; one after another on this thread if
/// `share.at_a_time` is 1. The jobs run on a pool of plain threads, each taking the next i: to
/// OpenMP each is an initial thread, whose parallel regions (a run's World's) run on a team
/// that libgomp keeps from one region to the next. (Nested inside an OpenMP region, a job's
/// team would be made afresh at every region, i.e. at every step, since libgomp reuses idle
/// threads for outermost regions only: two points of the 996-ball slab on two threads each
/// barely advanced that way.) After a job throws, no job starts; the first exception is
/// rethrown once the running ones have finished.
void run_shared(std::size_t count, const ThreadShare& share,
                const std::function<void(std::size_t)>& job);

/// The table printed at the end of a sweep: the varied values, power_kw,
/// power_dissipation_kw, energy_balance_error and the status of each point.
std::string sweep_table(const std::vector<SweepAxis>& axes, const std::vector<SweepRow>& rows);

}  // namespace millsim
