// A mill job: settle the charge, turn the shell, measure power and collisions.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "millsim/measure/charge_profile.hpp"
#include "millsim/measure/shell_impacts.hpp"
#include "millsim/measure/spectrum.hpp"
#include "millsim/particles/particle_store.hpp"
#include "millsim/sim/charge.hpp"

namespace millsim {

/// Energy accounts of the slice at one instant, J.
struct EnergySample {
  double time = 0.0;
  double shell_work = 0.0;
  double dissipated = 0.0;
  double kinetic = 0.0;
  double potential = 0.0;
  double stored = 0.0;
};

/// One revolution of the shell (or one interval of the finer time series). Powers are for
/// the whole mill (the slice scaled by MillPlan::power_scale), in W and N m.
struct PowerInterval {
  double start_time = 0.0;
  double end_time = 0.0;
  double torque = 0.0;             ///< mean drive torque, N m
  double power = 0.0;              ///< shell work / duration, W
  double dissipation_power = 0.0;  ///< energy dissipated / duration, W
  double kinetic_energy = 0.0;     ///< slice, at the end, J
};

struct MillResult {
  MillPlan plan;
  std::vector<PowerInterval> revolutions;  ///< every whole revolution after settling
  std::vector<PowerInterval> series;       ///< 50 intervals a revolution, from the start
  EnergySample window_start;
  EnergySample window_end;
  ImpactSpectrum spectrum{};  ///< collisions ending in the measured window (slice)
  double power_kw = 0.0;
  double power_dissipation_kw = 0.0;
  double power_std_kw = 0.0;
  double torque_nm = 0.0;
  double energy_balance_error = 0.0;
  long steps = 0;
  double simulated_seconds = 0.0;
  double wall_seconds = 0.0;
  double settle_wall_seconds = 0.0;  ///< s of wall_seconds spent settling, before the shell turns
  double particle_steps_per_second = 0.0;
  double settled_kinetic_energy = 0.0;  ///< J, slice, at the end of settling
  /// Centre of mass of the charge in the cross-section (x, y) averaged over the measured
  /// window, m from the mill axis. Its
  /// horizontal offset times the charge weight is the torque that holds the charge up.
  Vec2 charge_centre{};
  /// The charge's angular speed about the mill axis (charge_motion) over the shell's, averaged
  /// over the window: 1 when the charge rides with the shell (centrifuged).
  double orbital_speed_ratio = 0.0;
  /// The deepest overlap of any contact as a fraction of the smaller radius
  /// (World::largest_overlap_fraction), the most at the end of settling and at each of the 50
  /// samples a revolution while the shell turns.
  double largest_overlap_fraction = 0.0;
  /// World::dropped_wall_contacts at the end (none is expected in a mill; result_warnings
  /// would say so).
  long dropped_wall_contacts = 0;
  /// The liner layer's balls by angle over the measured window, and from them the charge's toe
  /// and shoulder (ChargeProfile; sampled 50 times a revolution, with the charge's centre).
  std::optional<ChargeProfile> charge_profile;
  /// Where the wall collisions ending in the measured window began, with their energy (slice).
  std::optional<ShellImpacts> shell_impacts;
};

/// Called now and then with (simulated time, total time, revolutions so far).
using ProgressCallback = std::function<void(double, double, double)>;

/// Runs the job on `world` (from build_mill_world(plan)). Snapshots go to
/// `snapshot_directory` if the plan asks for them (it must exist). Everything else is returned.
template <int D>
MillResult run_mill(const MillPlan& plan, World<D> world,
                    const std::filesystem::path& snapshot_directory,
                    const ProgressCallback& progress = {});

extern template MillResult run_mill<2>(const MillPlan&, World<2>, const std::filesystem::path&,
                                       const ProgressCallback&);
extern template MillResult run_mill<3>(const MillPlan&, World<3>, const std::filesystem::path&,
                                       const ProgressCallback&);

/// Time for the shell to come up to speed (MillPlan::spin_up_time): a quarter of a revolution's
/// period.
double spin_up_time(const MillPlan& plan);

/// W, whole mill: a thousandth of M g R ω, M the mill's charge — of the power of a drive holding
/// the whole charge out at the shell, of which a tumbling charge draws a fifth to a third. A
/// drive's power below it is next to none (a smooth, frictionless shell draws only its sums'
/// rounding), and the run's relative checks take it as their least scale: the energy balance
/// is relative to the shell's work or to this over the window, whichever is larger, and two
/// powers below it are not compared.
double least_drive_power(const MillPlan& plan);

/// The centre of mass of the particles in the cross-section (x, y), and their angular speed
/// about the mill axis as a rigid body would have it: their angular momentum about the axis
/// over their moment of inertia about it, Σ m (x × v) / Σ m |x|² (in the cross-section; the
/// particles' own spins left out; 0 if all lie on the axis). That is the mean of each
/// particle's angular speed (x × v) / |x|² weighted by m |x|², so that a ball passing near the
/// axis, whose own angular speed can be anything, weighs next to nothing.
template <int D>
std::pair<Vec2, double> charge_motion(const ParticleStore<D>& particles);
extern template std::pair<Vec2, double> charge_motion<2>(const ParticleStore<2>&);
extern template std::pair<Vec2, double> charge_motion<3>(const ParticleStore<3>&);

}  // namespace millsim
