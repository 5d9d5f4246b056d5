// Analytic answers shared by the 2D and 3D contact tests: the restitutions swept, the material,
// the steps per contact and free flight, and the exact normal impact of the linear
// spring–dashpot with and without tension.
#pragma once

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "millsim/core/constants.hpp"
#include "millsim/particles/material.hpp"
#include "millsim/sim/world.hpp"

namespace millsim::impact_answers {

inline constexpr double restitutions[] = {0.2, 0.5, 0.8, 0.95};

inline ContactMaterial material_with(double restitution) {
  return ContactMaterial{1.0e6, 2.0e6 / 3.0, restitution, 0.5};
}

// Steps per contact duration in the impact tests: Δt = t_c/200 resolves the force history to
// well below the 1 % (restitution) and 2 % (duration) tolerances.
inline constexpr double steps_per_contact = 200.0;

// Free flight before an impact, in steps of approach: the touch falls half-way between two
// samples of the positions. The dashpot force jumps from 0 to c_n v0 at the touch, so the
// leapfrog's answer depends on where in a step the touch falls: for e = 0.2 at t_c/200 the
// no-tension restitution moves by ±0.8 % as the touch moves through a step, and a touch exactly
// on a sample puts the end of a tension impact (t_c is a whole number of steps here) on a sample
// too, where the dashpot pulls for one more step: 1.6 % low. Half a step off is the midpoint
// rule: the first force sample stands for the step centred on it, which begins at the touch.
inline constexpr double free_flight_steps = 40.5;

// With tension the contact is the linear damped oscillator, which the leapfrog integrates to
// second order: over one contact its error in the phase and amplitude is of order
// (ω_d Δt)² = (π/200)² = 2.5e-4 at t_c/200, where a first-order scheme would be off by about
// π/200 = 1.6e-2. The with-tension answers are held to 1e-3 (relative) besides the issue's
// 1 % and 2 %; measured: within 1.1e-4 (e) and 6e-5 (t_c).
inline constexpr double second_order_tolerance = 1e-3;
/// Without tension the contact ends at a step, not at the exact t*: the restitution is within
/// 2.0e-4 of the no-tension answer and the force's duration within 2.1e-3 of t* in every head-on
/// case, 2D and 3D (Δt = t_c / 200). The bounds are tight enough to tell e_eff from Corkum's e at
/// e = 0.8 (1 % apart), which the 1 % used before could not.
inline constexpr double no_tension_restitution_tolerance = 1e-3;
inline constexpr double no_tension_duration_tolerance = 5e-3;

inline void record(const std::string& key, double value) {
  ::testing::Test::RecordProperty(key, fmt::format("{:.6g}", value));
}

/// The normal impact of the law without tension (allow_tension = false), solved exactly.
///
/// With ω0² = k_n/m*, 2ζω0 = c_n/m*, the overlap obeys δ'' + 2ζω0 δ' + ω0² δ = 0 from δ(0) = 0,
/// δ'(0) = v0, so δ = (v0/ω_d) e^{−ζω0 t} sin φ with φ = ω_d t, ω_d = ω0 sqrt(1 − ζ²), and
///   δ' = v0 e^{−ζω0 t} (cos φ − tan α sin φ) = v0 e^{−ζω0 t} cos(φ + α) / cos α,  ζ = sin α.
/// The contact force per unit m* is ω0² δ + 2ζω0 δ' ∝ (1 − 2ζ²) sin φ + 2ζ sqrt(1 − ζ²) cos φ
/// = cos 2α sin φ + sin 2α cos φ = sin(φ + 2α). It first falls to zero at φ* = π − 2α, so
///   t* = (π − 2 arcsin ζ) / ω_d,
/// and there δ' = v0 e^{−ζω0 t*} cos(π − α) / cos α = −v0 e^{−ζω0 t*}: the restitution is
///   e_eff = e^{−ζω0 t*} = exp(−tan α (π − 2α)).
/// (With tension the contact runs on to δ = 0 at φ = π, giving e = exp(−π tan α): Corkum.)
struct ImpactAnswer {
  double restitution = 0.0;
  double duration = 0.0;  ///< s, of the force for no tension, of the overlap with tension
};

inline ImpactAnswer no_tension_impact(const ContactMaterial& material, double effective_mass) {
  const double zeta = damping_ratio(material.restitution);
  const double alpha = std::asin(zeta);
  const double natural = std::sqrt(material.normal_stiffness / effective_mass);  // ω0
  const double damped = natural * std::sqrt(1.0 - zeta * zeta);                  // ω_d
  const double duration = (pi - 2.0 * alpha) / damped;
  return {std::exp(-zeta * natural * duration), duration};
}

inline ImpactAnswer corkum_impact(const ContactMaterial& material, double effective_mass) {
  return {material.restitution, contact_duration(material, effective_mass)};
}

/// Steps `world` until particle 0, bouncing on a floor whose normal is coordinate `axis`, has
/// made `count` whole flights after its first bounce (or `time_limit` s have passed), and
/// returns the highest centre height of each of those flights.
template <int D>
std::vector<double> bounce_apexes(World<D>& world, int axis, double radius, std::size_t count,
                                  double time_limit) {
  std::vector<double> apexes;
  bool airborne = true;
  bool bounced = false;
  double highest = 0.0;
  while (apexes.size() < count && world.time() < time_limit) {
    world.step();
    const double height = world.particles().position[0][axis];
    if (airborne && height < radius) {  // landing: the flight since the bounce is over
      if (bounced) apexes.push_back(highest);
      airborne = false;
    } else if (!airborne && height >= radius) {  // take-off
      airborne = true;
      bounced = true;
      highest = height;
    }
    if (airborne) highest = std::max(highest, height);
  }
  return apexes;
}

}  // namespace millsim::impact_answers
