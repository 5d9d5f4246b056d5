// What a run writes to its output directory (README "Outputs").
#pragma once

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "millsim/io/vtk_output.hpp"
#include "millsim/sim/world.hpp"

namespace millsim {

struct MillResult;

/// The snapshots of a run (README "Outputs"), in the directory given. As CSV: snapshot_NNNNNN.csv,
/// one a call of write, with a row for each particle in the order of their ids (World's
/// particle_id): id, position, velocity and angular velocity at the time of the positions,
/// radius and net force. For ParaView (vtk_output.hpp): snapshot_NNNNNN.vtp (the particles),
/// mill_NNNNNN.vtp (the walls), and particles.pvd and mill.pvd listing each by time. Either way
/// index.csv, a row for each snapshot written: its number, its particles' file, its time and the
/// shell's angle. Errors throw std::runtime_error naming the file.
class SnapshotWriter {
 public:
  SnapshotWriter(std::filesystem::path directory, bool csv = true, bool vtk = false);
  ~SnapshotWriter();
  SnapshotWriter(const SnapshotWriter&) = delete;
  SnapshotWriter& operator=(const SnapshotWriter&) = delete;

  template <int D>
  void write(const World<D>& world);

 private:
  std::filesystem::path directory_;
  bool csv_ = true;
  bool vtk_ = false;
  int count_ = 0;
  std::FILE* index_ = nullptr;  // index.csv, open from the first snapshot on
  long index_end_ = 0;          // its size after its last whole row
  // particles.pvd and mill.pvd, from the first snapshot on, if vtk_
  std::unique_ptr<PvdCollection> particle_collection_;
  std::unique_ptr<PvdCollection> mill_collection_;
};

extern template void SnapshotWriter::write(const World<2>&);
extern template void SnapshotWriter::write(const World<3>&);

/// summary.json, power.csv, power_timeseries.csv, spectrum.csv, charge_profile.csv and
/// impacts.csv.
/// summary.json is written last, so its presence means the run finished.
void write_results(const std::filesystem::path& directory, const MillResult& result);

/// The summary as JSON text (what summary.json holds).
std::string summary_json(const MillResult& result);

/// JSON text (as toml++'s writer makes it) with every non-integer number in the shortest form
/// that reads back to the same double: 0.0508, not 0.050799999999999998 (toml++ built with GCC
/// writes 17 significant digits). A number that was written with a point keeps one (3.0).
/// Strings are left as they are.
std::string shortest_json_numbers(std::string_view json);

/// Every number of summary.json as (name, value), in a fixed order; a number inside a nested
/// object is named with a dot ("reference.measured_power_kw"). Arrays (`discs`/`balls`,
/// `charge_centre_of_mass_m`) are not in the list. summary.json's numbers are written from
/// this list, so the two always agree.
std::vector<std::pair<std::string, double>> summary_scalars(const MillResult& result);

/// summary_scalars with the numbers this run has none of too (NaN), so that runs of the same
/// kind of mill list the same names in the same order: sweep.csv's columns.
std::vector<std::pair<std::string, double>> summary_columns(const MillResult& result);

/// The one-line summary printed at the end of a run: the DEM power, with the empirical models'
/// (measure/empirical_power.hpp) beside it.
std::string summary_line(const MillResult& result);

/// A run whose energy balance error exceeds this is reported as doubtful (result_warnings).
inline constexpr double doubtful_energy_balance_error = 0.05;
/// Power by torque and by dissipation further apart than this, relative to the larger, is
/// reported as doubtful: the measured window was not steady.
inline constexpr double doubtful_power_disagreement = 0.10;
/// A contact that overlapped more than this fraction of the smaller radius is reported as
/// doubtful: the linear spring assumes small overlaps, and from 1 on a ball may pass through
/// another or through a wall. (MODEL.md's springs give 0.02-0.32 in the validation cases.)
inline constexpr double doubtful_overlap_fraction = 0.5;

/// What in the results says they are doubtful, one sentence each (none for a sound run): an
/// energy balance that does not close, power by torque and by dissipation that disagree,
/// contacts that overlapped deeply.
std::vector<std::string> result_warnings(const MillResult& result);

}  // namespace millsim
