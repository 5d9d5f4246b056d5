// What a run writes to its output directory (README "Outputs").
#pragma once

#include <filesystem>
#include <string>

#include "millsim/sim/world.hpp"

namespace millsim {

struct MillResult;

/// snapshots/snapshot_NNNNNN.csv: time, and per particle id, position, velocity, angular
/// velocity, radius and net force.
void write_snapshot(const std::filesystem::path& directory, int index, const World<2>& world);
void write_snapshot(const std::filesystem::path& directory, int index, const World<3>& world);

/// summary.json, power.csv, power_timeseries.csv and spectrum.csv. summary.json is written
/// last, so its presence means the run finished.
void write_results(const std::filesystem::path& directory, const MillResult& result);

/// The summary as JSON text (what summary.json holds).
std::string summary_json(const MillResult& result);

/// The one-line summary printed at the end of a run.
std::string summary_line(const MillResult& result);

}  // namespace millsim
