#include "output_directory.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <limits.h>
#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <system_error>

#include "millsim/core/error.hpp"

namespace millsim_app {

namespace fs = std::filesystem;

void refuse_a_file_as_directory(const fs::path& out, const std::string& location) {
  // The non-throwing status: a path the system cannot look up (a name too long) is refused here
  // with the key, not reported as a failed run. (One below a file reads as not found, and
  // creating it fails below.)
  std::error_code error;
  const fs::file_status state = fs::status(out, error);
  if (error && state.type() != fs::file_type::not_found) {
    throw millsim::InputError(
        fmt::format("{}: output.directory: cannot use \"{}\" ({}); allowed: a directory that "
                    "can be created and written",
                    location, out.string(), error.message()));
  }
  if (fs::exists(state) && !fs::is_directory(state)) {
    throw millsim::InputError(
        fmt::format("{}: output.directory: \"{}\" exists and is not a directory; allowed: a "
                    "directory path",
                    location, out.string()));
  }
}

/// The longest file a run writes in snapshots/: a snapshot's .partial with ten digits, since a
/// run takes at most 1e10 steps and so writes fewer than 1e10 snapshots.
constexpr std::string_view longest_snapshot_file = "snapshots/snapshot_0000000000.csv.partial";

void refuse_a_path_too_long(const fs::path& out, const std::string& location,
                            std::initializer_list<const char*> results, Snapshots snapshots) {
  // What the run writes in `out`, and what it moves aside there, into the directory made for an
  // earlier run's results (its .partial files and snapshots/ too), where they are removed: the
  // longest of these must fit, so that a directory a run could write can be run into again.
  const std::string aside = std::string(aside_prefix) + "XXXXXX";
  std::string longest = aside;
  const auto consider = [&longest](std::string name) {
    if (name.size() > longest.size()) longest = std::move(name);
  };
  for (const char* name : results) {
    consider(std::string(name) + ".partial");
    consider(aside + "/" + name + ".partial");
  }
  if (snapshots == Snapshots::made) consider(std::string(longest_snapshot_file));
  if (snapshots != Snapshots::untouched) consider(aside + "/" + std::string(longest_snapshot_file));
  constexpr std::size_t most = PATH_MAX - 1;  // the system's limit, the terminating zero aside
  const std::size_t written = (out / longest).string().size();
  if (written <= most) return;
  throw millsim::InputError(fmt::format(
      "{}: output.directory: a path of {} characters leaves no room for the files the run "
      "writes in it, or moves aside there from an earlier run (the longest, {}, would be a path "
      "of {}); allowed: a directory path of at most {} characters (the system takes paths of at "
      "most {})",
      location, out.string().size(), longest, written, most - (written - out.string().size()),
      most));
}

namespace {

/// Makes `out` (and its missing parents) and writes and removes a file of its own in it, so
/// that a directory that exists but takes no files (read-only, full, immutable) is found now,
/// not when the results are written at the end. What it made is removed again if it fails.
void make_and_check_writable(const fs::path& out, const std::string& location) {
  const auto refuse = [&](const std::string& what, const std::string& why) {
    return millsim::InputError(
        fmt::format("{}: output.directory: cannot {} \"{}\" ({}); allowed: a directory that "
                    "can be created and written",
                    location, what, out.string(), why));
  };
  // The first of its parents that does not exist yet: what this call makes, and removes again
  // if the directory turns out to take no files. Anything whose state cannot be read (or a
  // link, even a dangling one) counts as existing: only what is surely absent is ever removed.
  fs::path made;
  for (fs::path p = out; !p.empty(); p = p.parent_path()) {
    std::error_code error;
    const fs::file_status state = fs::symlink_status(p, error);
    // (A missing path sets `error` too, with the type not_found; any other error leaves the
    // type none.)
    if (state.type() != fs::file_type::not_found) break;
    made = p;
    if (p == p.parent_path()) break;
  }
  try {
    fs::create_directories(out);
  } catch (const fs::filesystem_error& error) {
    throw refuse("make", error.code().message());
  }
  // mkstemp: no file of the user's is touched.
  std::string probe = (out / ".millsim-write-check-XXXXXX").string();
  const int descriptor = ::mkstemp(probe.data());
  bool writes = false;
  std::string why;
  if (descriptor < 0) {
    why = std::strerror(errno);
  } else {
    std::FILE* file = ::fdopen(descriptor, "w");
    writes = file != nullptr && std::fputs("millsim\n", file) >= 0;
    writes = (file != nullptr ? std::fclose(file) == 0 : ::close(descriptor) == 0) && writes;
    std::error_code ignored;
    fs::remove(probe, ignored);
    if (!writes) why = "a test file could not be written";
  }
  if (!writes) {
    std::error_code ignored;
    if (!made.empty()) fs::remove_all(made, ignored);
    throw refuse("write in", why);
  }
}

/// The names an earlier run's results may have in `out`: each result, its .partial, and
/// snapshots/ unless untouched.
std::vector<std::string> result_names(std::initializer_list<const char*> results,
                                      Snapshots snapshots) {
  std::vector<std::string> names;
  for (const char* name : results) {
    names.emplace_back(name);
    names.push_back(std::string(name) + ".partial");
  }
  if (snapshots != Snapshots::untouched) names.emplace_back("snapshots");
  return names;
}

/// Refuses a directory of the user's (not empty, or unreadable) under a result's name, other
/// than snapshots/ (ours): the run would fail to write the result there at its end.
void refuse_a_taken_name(const fs::path& out, const std::string& location,
                         const std::string& name) {
  std::error_code error;
  if (name == "snapshots" ||
      fs::symlink_status(out / name, error).type() != fs::file_type::directory) {
    return;
  }
  const bool empty = fs::is_empty(out / name, error);
  if (!error && empty) return;
  throw millsim::InputError(fmt::format(
      "{}: output.directory: \"{}\" holds a directory {} where the run writes a result ({}); "
      "allowed: an output directory where no result's name is taken (remove or rename {}, or "
      "choose another directory)",
      location, out.string(), name, error ? error.message() : "not empty", (out / name).string()));
}

}  // namespace

void check_output_directory(const fs::path& out, const std::string& location,
                            std::initializer_list<const char*> results, Snapshots snapshots) {
  refuse_a_path_too_long(out, location, results, snapshots);
  refuse_a_file_as_directory(out, location);
  std::error_code error;
  if (fs::symlink_status(out, error).type() == fs::file_type::not_found) return;
  make_and_check_writable(out, location);
  for (const std::string& name : result_names(results, snapshots)) {
    refuse_a_taken_name(out, location, name);
  }
}

EarlierResults move_results_aside(const fs::path& out, const std::string& location,
                                  std::initializer_list<const char*> results, Snapshots snapshots) {
  refuse_a_path_too_long(out, location, results, snapshots);
  refuse_a_file_as_directory(out, location);
  make_and_check_writable(out, location);
  std::vector<std::string> names = result_names(results, snapshots);
  EarlierResults earlier;
  earlier.out = out;
  earlier.location = location;
  // A directory under a result's name (not snapshots/, which is ours) that is not empty is the
  // user's: the run would fail to write the result there at its end. Refused before anything
  // moves. An empty one holds nothing to lose and is removed now (it may be one that cannot be
  // moved: renaming a directory needs write access to it, removing it does not).
  for (const std::string& name : names) refuse_a_taken_name(out, location, name);
  for (const std::string& name : names) {
    std::error_code error;
    if (fs::symlink_status(out / name, error).type() != fs::file_type::directory) continue;
    const bool empty = fs::is_empty(out / name, error);
    if (!error && empty && !fs::remove(out / name, error) && error) {
      throw earlier.refusal(fmt::format("{}: {}", name, error.message()));
    }
  }
  // What an earlier clearing that was stopped left moved aside goes too.
  std::error_code listing;
  for (const auto& entry : fs::directory_iterator(out, listing)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with(aside_prefix)) names.push_back(name);
  }
  // The earlier results are renamed into a directory of their own in `out`, so that if one
  // cannot be, those moved are put back and the refusal loses nothing.
  std::string aside = (out / (std::string(aside_prefix) + "XXXXXX")).string();
  if (::mkdtemp(aside.data()) == nullptr) throw earlier.refusal(std::strerror(errno));
  earlier.aside = aside;
  for (const std::string& name : names) {
    std::error_code error;
    if (fs::symlink_status(out / name, error).type() == fs::file_type::not_found) continue;
    fs::rename(out / name, earlier.aside / name, error);
    if (error) throw earlier.put_back(fmt::format("{}: {}", name, error.message()));
    earlier.moved.push_back(name);
  }
  return earlier;
}

millsim::InputError EarlierResults::refusal(const std::string& why) const {
  return millsim::InputError(
      fmt::format("{}: output.directory: cannot clear earlier results from \"{}\" ({}); "
                  "allowed: a directory whose earlier results can be removed",
                  location, out.string(), why));
}

millsim::InputError EarlierResults::put_back(const std::string& why) {
  std::vector<std::string> stuck;
  for (auto back = moved.rbegin(); back != moved.rend(); ++back) {
    std::error_code error;
    fs::rename(aside / *back, out / *back, error);
    if (error) stuck.push_back(*back);
  }
  moved.clear();
  std::error_code ignored;
  if (!aside.empty()) fs::remove(aside, ignored);  // only if it is empty again
  if (stuck.empty()) return refusal(why);
  return refusal(fmt::format("{}; and {} could not be put back: they are in {}/", why,
                             fmt::join(stuck, ", "), aside.string()));
}

std::vector<std::string> EarlierResults::remove() {
  std::vector<std::string> warnings;
  if (aside.empty()) return warnings;
  std::error_code error;
  fs::remove_all(aside, error);
  if (error) {
    warnings.push_back(fmt::format(
        "an earlier run's results were moved aside to {}/ but could not all be removed ({}): "
        "remove that directory yourself",
        aside.string(), error.message()));
  }
  moved.clear();
  return warnings;
}

std::vector<std::string> prepare_output_directory(const fs::path& out, const std::string& location,
                                                  std::initializer_list<const char*> results,
                                                  Snapshots snapshots) {
  EarlierResults earlier = move_results_aside(out, location, results, snapshots);
  if (snapshots == Snapshots::made) {
    std::error_code error;
    fs::create_directory(out / "snapshots", error);
    if (error) {
      throw earlier.put_back(fmt::format("snapshots: cannot make it: {}", error.message()));
    }
  }
  return earlier.remove();
}

}  // namespace millsim_app
