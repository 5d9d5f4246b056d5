// The output directory of a run: made, checked to take files, and cleared of an earlier run's
// results, all before the run starts, so that a directory that cannot take the results is
// refused (exit 2) before any time is spent and a run stopped half-way never leaves a mixture
// of two runs' files.
#pragma once

#include <filesystem>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "millsim/core/error.hpp"

namespace millsim_app {

/// Refuses (InputError) an output directory `out` that exists as something other than a
/// directory, or whose state cannot be read; `location` names where it was given.
void refuse_a_file_as_directory(const std::filesystem::path& out, const std::string& location);

/// What becomes of an earlier run's snapshots/ subdirectory: left (scenes write none), removed,
/// or removed and made again empty.
enum class Snapshots { untouched, removed, made };

/// Refuses (InputError) an output directory whose path leaves no room for the longest path a
/// run makes in it: a result's NAME.partial, if `snapshots` is made a snapshot's, and an
/// earlier run's results moved aside into .millsim-earlier-results-XXXXXX/ (a NAME.partial,
/// and unless untouched a snapshot in snapshots/), where they are removed. Without this, a path
/// just under the system's limit passed every check and the run failed at its first snapshot,
/// after the charge had settled; and a directory a run had written could not be run into again
/// (the earlier results could not be moved aside). Checked by check_output_directory and
/// prepare_output_directory; a sweep checks each point's directory with it before any runs.
void refuse_a_path_too_long(const std::filesystem::path& out, const std::string& location,
                            std::initializer_list<const char*> results, Snapshots snapshots);

/// Creates `out`, checks that a file can be written in it, and clears the `results`, their
/// NAME.partial files (what a killed run leaves) and, unless untouched, snapshots/ that an
/// earlier run left in it (and makes snapshots/ again, empty, if `made`). A result's name taken
/// by a directory of the user's (not empty) is refused before anything moves; an empty one is
/// removed. The rest are moved aside with renames in `out` (put back if one fails, or if
/// snapshots/ cannot be made, so that a refusal loses nothing), then removed. Returns warnings
/// for the run to print (what could be moved aside but not removed). Throws InputError naming
/// `location` (config line, --set or --out) if the directory cannot be used.
/// The refusals prepare_output_directory would make, with nothing moved or removed: `out`
/// exists as something else, cannot be written, or holds a directory of the user's under a
/// result's name. Nothing to check if `out` does not exist yet. For a job that clears several
/// directories (a sweep), so that a refusal comes before any is cleared.
void check_output_directory(const std::filesystem::path& out, const std::string& location,
                            std::initializer_list<const char*> results,
                            Snapshots snapshots = Snapshots::untouched);

/// The name of the directory in which an output directory's earlier results are moved aside
/// (followed by 6 random characters) before they are removed.
inline constexpr std::string_view aside_prefix = ".millsim-earlier-results-";

/// An earlier run's results in `out`, moved aside into `aside` (move_results_aside), to be
/// removed once the new run may start, or put back if it may not.
struct EarlierResults {
  std::filesystem::path out;
  std::filesystem::path aside;  // empty: nothing made
  std::string location;
  std::vector<std::string> moved;

  /// Puts what was moved back where it was; returns the refusal to throw, saying `why`, and
  /// where anything is that could not be put back.
  millsim::InputError put_back(const std::string& why);
  /// Removes what was moved aside; warnings for what could not be removed.
  std::vector<std::string> remove();
  /// The refusal to clear `out`, saying `why`.
  millsim::InputError refusal(const std::string& why) const;
};

/// The first half of prepare_output_directory: `out` made and checked, its results (and what
/// an earlier clearing that was stopped left aside) moved into a directory of their own; a
/// refusal (InputError) puts back what it moved. For a job that clears several directories
/// and must refuse before it removes any (a sweep).
EarlierResults move_results_aside(const std::filesystem::path& out, const std::string& location,
                                  std::initializer_list<const char*> results,
                                  Snapshots snapshots = Snapshots::untouched);

std::vector<std::string> prepare_output_directory(const std::filesystem::path& out,
                                                  const std::string& location,
                                                  std::initializer_list<const char*> results,
                                                  Snapshots snapshots = Snapshots::untouched);

}  // namespace millsim_app
