// Contact materials: the physical inputs of one material pair and the constants derived from
// them (damping, contact duration, stable time step), each computed here and nowhere else.
#pragma once

namespace millsim {

/// k_s / k_n when a config gives no tangential stiffness (MODEL.md §3).
inline constexpr double default_tangential_share = 2.0 / 3.0;

/// What the user gives for one material pair (ball–ball, ball–wall). SI units.
struct ContactMaterial {
  double normal_stiffness = 4.0e5;  ///< k_n, N/m
  /// k_s, N/m; by default 2/3 of k_n (MODEL.md §3: Hertzian theory puts it between 2/3 and 1
  /// of k_n for Poisson's ratios below 0.5).
  double tangential_stiffness = default_tangential_share * 4.0e5;
  double restitution = 0.6;  ///< e, in (0, 1]
  double friction = 0.5;     ///< μ, >= 0
};

/// Damping ratio ζ of the linear spring–dashpot that gives restitution e (Corkum's relation):
/// c = 2 ζ sqrt(k m*), ζ = −ln e / sqrt(ln²e + π²). Exact for an impact whose force may turn
/// tensile at its very end; see docs/model.md for what the no-tension rule changes.
double damping_ratio(double restitution);

/// c_n = −2 ln(e) sqrt(k_n m*) / sqrt(ln²e + π²).
double normal_damping(const ContactMaterial& material, double effective_mass);

/// c_s: our choice is Corkum's relation with k_s in place of k_n (docs/model.md).
double tangential_damping(const ContactMaterial& material, double effective_mass);

/// t_c = π / sqrt(k_n/m* − (c_n / 2m*)²), the duration of a normal impact.
double contact_duration(const ContactMaterial& material, double effective_mass);

/// Largest stable leapfrog step for a two-body contact: the shorter of the normal mode's and the
/// tangential mode's 2 / (ω (sqrt(1 + 4 ζ²) + 2 ζ)), with ω = sqrt(k_n/m*) and ζ the damping
/// ratio, and ω = sqrt(k_s/m_t*) and ζ sqrt(m*/m_t*), m_t* being the mass that resists sliding
/// once rotation is counted (`tangential_mass`). Undamped (e = 1) it is 2/ω_max; the dashpots,
/// given the velocity estimated at the time of the positions, lower it (to 0.73 of that for
/// the normal mode at e = 0.6, 0.59 for a disc's tangential one: docs/model.md).
double critical_time_step(const ContactMaterial& material, double effective_mass,
                          double tangential_mass);

/// m* = m_a m_b / (m_a + m_b).
double reduced_mass(double mass_a, double mass_b);

/// Mass that resists sliding at the contact point of a pair:
/// 1/m_t = 1/m_a + 1/m_b + r_a²/I_a + r_b²/I_b, with I = inertia_factor · m r².
/// For a wall pass mass_b = 0 (infinite). inertia_factor is 1/2 for discs, 2/5 for spheres.
double tangential_mass(double mass_a, double mass_b, double inertia_factor);

}  // namespace millsim
