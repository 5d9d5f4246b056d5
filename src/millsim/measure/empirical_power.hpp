// Empirical and semi-empirical mill-power models, evaluated for the run's mill so that the DEM
// power can be read beside what a plant engineer would have estimated (docs/empirical_power.md).
// Pure functions of the mill's geometry, speed and charge; no simulation state.
#pragma once

#include <string>

#include "millsim/core/constants.hpp"

namespace millsim {

struct MillPlan;

/// Hogg–Fuerstenau's dynamic angle of repose of the charge surface: 35°, the middle of the
/// 30–40° usually quoted for a cascading ball charge. A documented default, not fitted to any
/// millsim case (docs/empirical_power.md).
inline constexpr double default_dynamic_repose_angle = 35.0 * pi / 180.0;
/// Morrell's lumped calibration constant between charge-motion power and the net (gross minus
/// no-load) power of industrial mills, k = 1.26 (Morrell 1996; Napier-Munn et al. 1996, ch. 11).
inline constexpr double morrell_calibration = 1.26;
/// Bond's ball-size factor applies only to mills wider than this inside the liners (Bond 1961;
/// Rowland & Kjos 1980).
inline constexpr double bond_ball_size_factor_diameter = 3.3;  // m

/// What the formulas are given. SI units; the formulas convert at their own edges.
struct EmpiricalPowerInputs {
  double diameter = 0.0;  ///< m, inside the shell
  double length = 0.0;    ///< m
  double filling = 0.0;   ///< J: fraction of the mill volume the bed takes at rest, voids included
  double speed_rpm = 0.0;
  /// rpm, (60/2π) √(2g/D): the shell's critical speed without the ball-size correction of
  /// MODEL.md §1, which is the one Bond's and Morrell's correlations were fitted with.
  double shell_critical_speed_rpm = 0.0;
  double speed_fraction = 0.0;     ///< speed_rpm / shell_critical_speed_rpm
  double ball_density = 0.0;       ///< kg/m³, of the steel
  double porosity = 0.0;           ///< voids of the ball bed
  double bed_density = 0.0;        ///< kg/m³, ball_density (1 − porosity)
  double ball_charge_mass = 0.0;   ///< kg, bed_density J π D²/4 L
  double top_ball_diameter = 0.0;  ///< m, the largest ball (Bond's make-up ball size B)
  double repose_angle = default_dynamic_repose_angle;  ///< rad, Hogg–Fuerstenau
};

/// The inputs for the mill of `plan`: its config's diameter, length, filling, porosity and
/// density, its speed in rpm, its whole-mill charge mass and its largest ball.
EmpiricalPowerInputs empirical_power_inputs(const MillPlan& plan);

/// Bond (1961) in the metric form of Rowland & Kjos (1980): power at the pinion of a wet
/// overflow ball mill, kW = kWb × (ball-charge mass in t).
struct BondPower {
  double power_kw = 0.0;
  double kw_per_ball_tonne = 0.0;  ///< kWb, including the ball-size factor
  double ball_size_factor = 0.0;   ///< S_s, kW/t (0 for D <= 3.3 m)
  /// Whether the equation gives a positive power (kWb > 0). Far outside the mills it was fitted
  /// to it does not: its speed term turns negative above 1.23 of critical speed, and S_s makes
  /// kWb negative in mills of about a hundred metres. There power_kw means nothing, and the
  /// outputs say "n/a" instead of it.
  bool applies = true;
};

/// "Bond 123.4 kW", or, where the equation does not apply, why not.
std::string bond_power_text(const BondPower& bond);

/// Hogg & Fuerstenau (1972): the charge as a rigid circular segment whose chord is tilted at the
/// dynamic angle of repose α; the drive holds its centre of mass off the vertical:
/// P = 2π N M g r_c sin α.
struct HoggFuerstenauPower {
  double power_kw = 0.0;
  double half_angle = 0.0;             ///< rad, θ: half the angle the chord subtends at the axis
  double centre_of_mass_radius = 0.0;  ///< m, r_c
};

/// Morrell's C-model (1996) for the cylindrical part of a dry ball mill (no slurry pool).
struct MorrellPower {
  double net_kw = 0.0;                       ///< k × charge_motion_kw
  double charge_motion_kw = 0.0;             ///< potential + kinetic energy given to the charge
  double centrifuging_speed_fraction = 0.0;  ///< φ_c = max(φ, 0.35 (3.364 − J))
  double toe_angle = 0.0;                    ///< rad, θ_T
  double shoulder_angle = 0.0;               ///< rad, θ_S
  double mean_radius = 0.0;                  ///< m, r̄ of the active charge
  double active_fraction = 0.0;              ///< β = t_c / (t_f + t_c)
  double inner_radius = 0.0;                 ///< m, r_i of the active charge's inner surface
  double z = 0.0;                            ///< (1 − J)^0.4532
};

/// Bond's kW per tonne of balls: 4.879 D^0.3 (3.2 − 3 J) φ (1 − 0.1 / 2^(9 − 10 φ)) + S_s.
double bond_kw_per_ball_tonne(double diameter, double filling, double speed_fraction,
                              double top_ball_diameter);
/// Bond's ball-size factor S_s = 1.102 (B − 12.5 D) / 50.8 kW/t (B in mm, D in m) for
/// D > 3.3 m, else 0.
double bond_ball_size_factor(double diameter, double top_ball_diameter);
BondPower bond_power(const EmpiricalPowerInputs& inputs);

/// θ in [0, π] with J = (θ − sin θ cos θ) / π: the half angle of the circular segment that takes
/// the fraction J of the circle.
double segment_half_angle(double filling);
HoggFuerstenauPower hogg_fuerstenau_power(const EmpiricalPowerInputs& inputs);

MorrellPower morrell_power(const EmpiricalPowerInputs& inputs);

struct EmpiricalPower {
  EmpiricalPowerInputs inputs;
  BondPower bond;
  HoggFuerstenauPower hogg_fuerstenau;
  MorrellPower morrell;
};

EmpiricalPower empirical_power(const EmpiricalPowerInputs& inputs);
EmpiricalPower empirical_power(const MillPlan& plan);

}  // namespace millsim
