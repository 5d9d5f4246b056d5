// From a mill config to everything derived from it (speeds, ball counts, masses, time step),
// and the charge placed in the mill.
#pragma once

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "millsim/io/config.hpp"
#include "millsim/sim/world.hpp"

namespace millsim {

/// A settled 2D bed of frictional discs holds this fraction of its area in voids (random
/// packings of discs: 0.16–0.22; docs/model.md). It sets how many discs fill J of a slice.
inline constexpr double disc_bed_porosity = 0.2;
/// Default steps per contact duration of the stiffest, lightest pair ("auto" time step).
inline constexpr double steps_per_contact = 20.0;
/// A time step given in the config with fewer steps than this per shortest contact is stable
/// but coarse (MODEL.md §4: "at least ~10–20"): the run is made, with a warning.
inline constexpr double fewest_steps_per_contact = 10.0;

/// The step "auto" takes, for mills and scenes alike: 1/steps_per_contact of the shortest
/// contact, and never above a quarter of the stability limit (with a tangential stiffness far
/// above the normal one, or heavy damping, the limit is the shorter).
inline double automatic_time_step(double shortest_contact, double critical_time_step) {
  return std::min(shortest_contact / steps_per_contact, 0.25 * critical_time_step);
}

/// The warning for a time step given in a config (at `where`, its file and line) that takes
/// fewer than fewest_steps_per_contact steps over the `shortest` contact duration, naming
/// `automatic`, the step "auto" would take; nothing for a finer step. Mills and scenes alike.
std::optional<std::string> coarse_step_warning(const std::string& where, double time_step,
                                               double shortest, double automatic);

/// One size of the simulated charge: discs in 2D, spheres in 3D.
struct DiscClass {
  double diameter = 0.0;  ///< m
  double mass = 0.0;      ///< kg: the mass of the sphere of that diameter
  int count = 0;
};

/// Derived quantities of a mill run (`millsim info` prints them).
struct MillPlan {
  MillConfig config;
  double radius = 0.0;              ///< m
  double largest_ball = 0.0;        ///< m
  double critical_speed_rpm = 0.0;  ///< 42.3 / sqrt(D − d_max) (MODEL.md §1)
  double speed_rpm = 0.0;
  double speed_fraction = 0.0;
  double angular_speed = 0.0;      ///< rad/s
  double revolution_period = 0.0;  ///< s
  std::vector<DiscClass> discs;
  int particle_count = 0;
  double slice_mass = 0.0;  ///< kg, the simulated discs or balls
  /// kg, ρ (1 − porosity) (J π R² L + 2 cone_bed_volume): the cylinder's bed, and with
  /// conical ends the bed in each cone below the same level
  double mill_charge_mass = 0.0;
  double trunnion_radius = 0.0;  ///< m, 3D with conical ends: where each cone is closed
  double cone_volume = 0.0;      ///< m³, inside one conical end (a frustum)
  /// m³, voids included: the part of one cone below the level of a bed filling J of the
  /// cylinder
  double cone_bed_volume = 0.0;
  /// Simulated power × power_scale = the mill's: mill_charge_mass / slice_mass in 2D,
  /// length / simulated_length in 3D (1 for a whole mill).
  double power_scale = 0.0;
  double simulated_length = 0.0;            ///< m, 3D: the mill length or the periodic slab
  double contact_duration_ball_ball = 0.0;  ///< s, smallest pair
  double contact_duration_ball_wall = 0.0;  ///< s, smallest ball
  double critical_time_step = 0.0;          ///< s, stability limit
  double time_step = 0.0;                   ///< s, in use
  /// s, the shell's speed ramps up linearly from 0 over it after settling: a quarter of a
  /// revolution's period, in which the shell turns an eighth of a revolution
  double spin_up_time = 0.0;
  /// s, settling + rotation: settle_time + spin_up_time / 2 + revolutions × revolution_period
  /// (the ramp turns the shell as half its time at full speed would)
  double total_time = 0.0;
  /// Snapshots the run writes: one at each multiple of output.snapshot_interval before the
  /// last step (the last may fall either side of the end by a step); 0 without snapshots.
  double snapshot_count = 0.0;
  /// Bytes those snapshots take on disk, at most about: snapshot_count times the particles'
  /// rows (snapshot_bytes_per_particle) and, as VTK, the mill's walls (snapshot_mill_bytes).
  double snapshot_bytes = 0.0;
  /// What in the config makes the results doubtful without making the run impossible (a
  /// coarse time step), or the run's output larger than a disk is likely to hold (snapshots
  /// above snapshot_bytes_warned), one sentence each, naming the file, line and key.
  std::vector<std::string> warnings;
};

/// Bytes a particle's row takes in a snapshot, at most about, by dimension and format: the
/// numbers of a turning mill's rows, 17 significant digits each at most (2D CSV 136 and VTK
/// 168, 3D 232 and 244 bytes a particle in the built-in example's mill), with room to spare.
inline constexpr double snapshot_bytes_per_particle(int dimension, bool vtk) {
  return dimension == 2 ? (vtk ? 200.0 : 170.0) : (vtk ? 300.0 : 280.0);
}
/// Bytes of a snapshot's mill_NNNNNN.vtp, at most about: the shell, and each lifter's corners
/// and cells (measured: 2D 9.5 kB and 190 bytes a lifter; 3D 22 kB, 24 kB more with cones,
/// and 500 bytes a lifter), with room to spare.
inline constexpr double snapshot_mill_bytes(int dimension, int lifters, bool cones) {
  return dimension == 2 ? 12e3 + 250.0 * lifters : 30e3 + (cones ? 30e3 : 0.0) + 650.0 * lifters;
}
/// Snapshots above this many bytes in all are warned of (MillPlan::warnings).
inline constexpr double snapshot_bytes_warned = 20e9;

/// Area of the part of a circle of `radius` below the horizontal line at `level` from its
/// centre (negative: below the centre), m².
double circle_area_below(double radius, double level);
/// Volume, voids included, of the bed in one conical end: the part of a frustum (radius R at
/// the cylinder, r_t at the trunnion, `cone_length` long) below the level of a bed that fills
/// `filling` of the cylinder's cross-section, m³.
double cone_bed_volume(double radius, double trunnion_radius, double cone_length, double filling);

/// Works out the plan; throws InputError when the config asks for the impossible (an unstable
/// time step), naming the key.
MillPlan plan_mill(const MillConfig& config);

/// The World for a plan, with the shell still and the charge placed without overlaps at random
/// (largest discs first) in the free space of the mill. Throws InputError when the discs do
/// not fit.
template <int D>
World<D> build_mill_world(const MillPlan& plan);

extern template World<2> build_mill_world<2>(const MillPlan&);
extern template World<3> build_mill_world<3>(const MillPlan&);

}  // namespace millsim
