// Snapshots for ParaView (README "Outputs"): VTK XML PolyData files of the particles and of the
// mill's walls at one instant, and a ParaView data collection (.pvd) that lists them by time.
// ASCII, with every number in the shortest text that reads back to the same double.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "millsim/sim/world.hpp"

namespace millsim {

/// The particles as a VTK PolyData file: a point and a vertex for each, by id (World's
/// particle_id), with the point arrays id, radius, velocity and angular_velocity (at the time
/// of the positions: motion_at_positions) and force. 2D worlds lie in the plane z = 0, their
/// spin about +z.
template <int D>
std::string particles_vtp(const World<D>& world);

/// The mill's walls at their present angle as a VTK PolyData file, for a mill world: in 2D the
/// shell as a closed line of `shell_segments` and each lifter as a rectangle; in 3D the shell
/// as a ring of `shell_segments` quadrilaterals from z = 0 to the simulated length, each
/// lifter as a box, and, for a whole mill, the end plates (or the cones and their trunnion
/// plates). The cell array `wall` says which: 0 shell, 1 lifter, 2 end plate or cone. Empty
/// (no points) for a world without a mill.
template <int D>
std::string mill_vtp(const World<D>& world);

inline constexpr int shell_segments = 180;

/// A ParaView data collection (.pvd) that grows by a time step at a time: each add() writes
/// the new entries and the closing tags over the old closing tags and flushes, so that between
/// calls the file is a whole, valid collection of the snapshots written so far.
class PvdCollection {
 public:
  explicit PvdCollection(std::filesystem::path path);
  ~PvdCollection();
  PvdCollection(const PvdCollection&) = delete;
  PvdCollection& operator=(const PvdCollection&) = delete;

  /// The files of one instant (file names relative to the collection's directory), as parts
  /// 0, 1, ... of the time step `time`. Throws std::runtime_error naming the file if it
  /// cannot write.
  void add(double time, const std::vector<std::string>& files);

 private:
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  long entries_end_ = 0;  // where the closing tags start
};

}  // namespace millsim
