#include "millsim/measure/empirical_power.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "millsim/core/constants.hpp"
#include "millsim/sim/charge.hpp"

namespace millsim {
namespace {

/// Revolutions per second from rpm.
double revolutions_per_second(double rpm) {
  return rpm / 60.0;
}

}  // namespace

EmpiricalPowerInputs empirical_power_inputs(const MillPlan& plan) {
  const MillConfig& c = plan.config;
  EmpiricalPowerInputs in;
  in.diameter = c.diameter;
  in.length = c.length;
  in.filling = c.filling;
  in.speed_rpm = plan.speed_rpm;
  // N_c = (1/2π) √(2g/D) rev/s, the 42.3/√D rpm of Bond and Morrell (no ball-size term).
  in.shell_critical_speed_rpm = 60.0 / (2.0 * pi) * std::sqrt(2.0 * standard_gravity / c.diameter);
  in.speed_fraction = in.speed_rpm / in.shell_critical_speed_rpm;
  in.ball_density = c.density;
  in.porosity = c.porosity;
  in.bed_density = c.density * (1.0 - c.porosity);
  in.ball_charge_mass = plan.mill_charge_mass;
  in.top_ball_diameter = plan.largest_ball;
  return in;
}

// Bond, F.C. (1961) "Crushing and grinding calculations", Allis-Chalmers 07R9235B; metric form
// in Rowland, C.A. & Kjos, D.M. (1980) "Rod and ball mills", in Mular & Bhappu (eds.) Mineral
// Processing Plant Design, SME, and in Napier-Munn et al. (1996) Mineral Comminution Circuits,
// JKMRC, ch. 11: S_s = 1.102 (B − 12.5 D) / 50.8 kW/t, B in mm, D in m, for D > 3.3 m.
double bond_ball_size_factor(double diameter, double top_ball_diameter) {
  if (diameter <= bond_ball_size_factor_diameter) return 0.0;
  const double ball_mm = 1000.0 * top_ball_diameter;
  return 1.102 * (ball_mm - 12.5 * diameter) / 50.8;
}

// kWb = 4.879 D^0.3 (3.2 − 3 V_p) C_s (1 − 0.1 / 2^(9 − 10 C_s)) + S_s  (same sources), kW per
// metric tonne of balls at the pinion, D in m inside the liners, V_p = J, C_s = φ.
double bond_kw_per_ball_tonne(double diameter, double filling, double speed_fraction,
                              double top_ball_diameter) {
  const double speed_term =
      speed_fraction * (1.0 - 0.1 / std::pow(2.0, 9.0 - 10.0 * speed_fraction));
  return 4.879 * std::pow(diameter, 0.3) * (3.2 - 3.0 * filling) * speed_term +
         bond_ball_size_factor(diameter, top_ball_diameter);
}

std::string bond_power_text(const BondPower& bond) {
  if (bond.applies) return fmt::format("Bond {:.4g} kW", bond.power_kw);
  return "Bond n/a (its equation gives no positive power for this mill)";
}

BondPower bond_power(const EmpiricalPowerInputs& in) {
  BondPower bond;
  bond.ball_size_factor = bond_ball_size_factor(in.diameter, in.top_ball_diameter);
  bond.kw_per_ball_tonne =
      bond_kw_per_ball_tonne(in.diameter, in.filling, in.speed_fraction, in.top_ball_diameter);
  bond.power_kw = bond.kw_per_ball_tonne * in.ball_charge_mass / 1000.0;
  bond.applies = bond.kw_per_ball_tonne > 0.0;
  return bond;
}

double segment_half_angle(double filling) {
  // π J = θ − sin θ cos θ rises monotonically from 0 (θ = 0) to π (θ = π): bisect.
  if (filling <= 0.0) return 0.0;
  if (filling >= 1.0) return pi;
  const double target = pi * filling;
  double low = 0.0;
  double high = pi;
  for (int k = 0; k < 200 && high - low > 0.0; ++k) {
    const double mid = 0.5 * (low + high);
    if (mid == low || mid == high) break;
    if (mid - std::sin(mid) * std::cos(mid) < target) {
      low = mid;
    } else {
      high = mid;
    }
  }
  return 0.5 * (low + high);
}

// Hogg, R. & Fuerstenau, D.W. (1972) "Power relationships for tumbling mills", Trans. SME-AIME
// 252, 418–423. A circular segment of half angle θ holds the area R² (θ − sin θ cos θ) = π R² J,
// and its centre of mass lies r_c = 2 R sin³θ / (3 (θ − sin θ cos θ)) from the axis, on the
// normal to the chord. With the chord at α to the horizontal, the torque is M g r_c sin α and
// P = 2π N M g r_c sin α = (4π/3) N g ρ_b L R³ sin³θ sin α, N in rev/s, ρ_b the bed density.
HoggFuerstenauPower hogg_fuerstenau_power(const EmpiricalPowerInputs& in) {
  HoggFuerstenauPower hf;
  if (in.filling <= 0.0) return hf;
  const double radius = 0.5 * in.diameter;
  hf.half_angle = segment_half_angle(in.filling);
  const double sin_theta = std::sin(hf.half_angle);
  const double sin_cubed = sin_theta * sin_theta * sin_theta;
  hf.centre_of_mass_radius =
      2.0 * radius * sin_cubed / (3.0 * (hf.half_angle - sin_theta * std::cos(hf.half_angle)));
  const double power_w = 4.0 * pi / 3.0 * revolutions_per_second(in.speed_rpm) * standard_gravity *
                         in.bed_density * in.length * radius * radius * radius * sin_cubed *
                         std::sin(in.repose_angle);
  hf.power_kw = power_w / 1000.0;
  return hf;
}

// Morrell, S. (1996) "Power draw of wet tumbling mills and its relationship to charge dynamics",
// Trans. IMM C 105, C43–C62; Napier-Munn et al. (1996) ch. 11. Angles in rad, φ the fraction of
// the shell's critical speed, J the bed filling, r_m = D/2, N_m in rev/s:
//   φ_c = max(φ, 0.35 (3.364 − J))                       (speed at which centrifuging sets in)
//   θ_T = 2.5307 (1.2796 − J) (1 − exp(−19.42 (φ_c − φ))) + π/2
//   θ_S = π/2 − (θ_T − π/2) [(0.3386 + 0.1041 φ) + (1.54 − 2.5673 φ) J]
//   r̄ = (r_m / 2) (1 + √(1 − 2π J / (2π + θ_S − θ_T)))
//   t_c = (2π − θ_T + θ_S) / (2π N), N = N_m / 2;  t_f = √(2 r̄ (sin θ_S − sin θ_T) / g)
//   β = t_c / (t_f + t_c);  r_i = r_m √(1 − 2π β J / (2π + θ_S − θ_T));  z = (1 − J)^0.4532
//   P = π g L N_m r_m / (3 (r_m − z r_i)) [2 r_m³ − 3 z r_m² r_i + r_i³ (3z − 2)]
//         ρ_c (sin θ_S − sin θ_T)
//     + L ρ_c (N_m r_m π / (r_m − z r_i))³ [(r_m − z r_i)⁴ − r_i⁴ (z − 1)⁴]
// Dry mill: no slurry pool, so the pool term ρ_p (sin θ_T − sin θ_TO) is absent; ρ_c is the bed
// density. Flat ends: no cone-end term. Net power = k P with k = morrell_calibration.
MorrellPower morrell_power(const EmpiricalPowerInputs& in) {
  MorrellPower m;
  const double J = in.filling;
  const double phi = in.speed_fraction;
  if (J <= 0.0 || in.speed_rpm <= 0.0) return m;
  m.centrifuging_speed_fraction = std::max(phi, 0.35 * (3.364 - J));
  m.toe_angle =
      2.5307 * (1.2796 - J) * (1.0 - std::exp(-19.42 * (m.centrifuging_speed_fraction - phi))) +
      pi / 2.0;
  m.shoulder_angle =
      pi / 2.0 - (m.toe_angle - pi / 2.0) * ((0.3386 + 0.1041 * phi) + (1.54 - 2.5673 * phi) * J);
  const double r_m = 0.5 * in.diameter;
  const double active_arc = 2.0 * pi + m.shoulder_angle - m.toe_angle;
  m.mean_radius = 0.5 * r_m * (1.0 + std::sqrt(std::max(0.0, 1.0 - 2.0 * pi * J / active_arc)));
  const double mill_rate = revolutions_per_second(in.speed_rpm);  // N_m
  const double charge_rate = 0.5 * mill_rate;                     // N
  const double drop = std::sin(m.shoulder_angle) - std::sin(m.toe_angle);
  const double circulation_time = active_arc / (2.0 * pi * charge_rate);  // t_c
  const double fall_time =
      std::sqrt(std::max(0.0, 2.0 * m.mean_radius * drop) / standard_gravity);  // t_f
  m.active_fraction = circulation_time / (fall_time + circulation_time);
  m.inner_radius =
      r_m * std::sqrt(std::max(0.0, 1.0 - 2.0 * pi * m.active_fraction * J / active_arc));
  m.z = std::pow(1.0 - J, 0.4532);
  const double r_i = m.inner_radius;
  const double z = m.z;
  const double gap = r_m - z * r_i;
  const double rho = in.bed_density;
  const double potential =
      pi * standard_gravity * in.length * mill_rate * r_m / (3.0 * gap) *
      (2.0 * r_m * r_m * r_m - 3.0 * z * r_m * r_m * r_i + r_i * r_i * r_i * (3.0 * z - 2.0)) *
      rho * drop;
  const double surface_speed = mill_rate * r_m * pi / gap;
  const double kinetic = in.length * rho * surface_speed * surface_speed * surface_speed *
                         (std::pow(gap, 4) - std::pow(r_i, 4) * std::pow(z - 1.0, 4));
  m.charge_motion_kw = (potential + kinetic) / 1000.0;
  m.net_kw = morrell_calibration * m.charge_motion_kw;
  return m;
}

EmpiricalPower empirical_power(const EmpiricalPowerInputs& inputs) {
  return {inputs, bond_power(inputs), hogg_fuerstenau_power(inputs), morrell_power(inputs)};
}

EmpiricalPower empirical_power(const MillPlan& plan) {
  return empirical_power(empirical_power_inputs(plan));
}

}  // namespace millsim
