#include "millsim/particles/material.hpp"

#include <algorithm>
#include <cmath>

#include "millsim/core/constants.hpp"

namespace millsim {

double damping_ratio(double restitution) {
  const double log_e = std::log(restitution);
  return -log_e / std::sqrt(log_e * log_e + pi * pi);
}

double normal_damping(const ContactMaterial& material, double effective_mass) {
  return 2.0 * damping_ratio(material.restitution) *
         std::sqrt(material.normal_stiffness * effective_mass);
}

double tangential_damping(const ContactMaterial& material, double effective_mass) {
  return 2.0 * damping_ratio(material.restitution) *
         std::sqrt(material.tangential_stiffness * effective_mass);
}

double contact_duration(const ContactMaterial& material, double effective_mass) {
  const double c = normal_damping(material, effective_mass);
  const double half_rate = c / (2.0 * effective_mass);
  return pi / std::sqrt(material.normal_stiffness / effective_mass - half_rate * half_rate);
}

double critical_time_step(const ContactMaterial& material, double effective_mass,
                          double tangential_mass_value) {
  // Each mode is a damped oscillator ü = −ω² u − 2 ζ ω u̇ whose dashpot sees the step's
  // estimate u̇(n−½) + ½ ü(n−1) Δt (World's velocity at the time of the positions). Its
  // leapfrog step is stable for ω Δt < 2 (sqrt(1 + 4 ζ²) − 2 ζ), written here without the
  // difference: 2 / (sqrt(1 + 4 ζ²) + 2 ζ). The tangential dashpot c_s = 2 ζ sqrt(k_s m*) acts
  // on the lighter m_t, so that its ratio is ζ sqrt(m* / m_t) (√3 ζ for discs).
  const auto stable_below = [](double stiffness, double mass, double ratio) {
    const double frequency = std::sqrt(stiffness / mass);
    return 2.0 / (frequency * (std::sqrt(1.0 + 4.0 * ratio * ratio) + 2.0 * ratio));
  };
  const double zeta = damping_ratio(material.restitution);
  return std::min(stable_below(material.normal_stiffness, effective_mass, zeta),
                  stable_below(material.tangential_stiffness, tangential_mass_value,
                               zeta * std::sqrt(effective_mass / tangential_mass_value)));
}

double reduced_mass(double mass_a, double mass_b) {
  return mass_a * mass_b / (mass_a + mass_b);
}

double tangential_mass(double mass_a, double mass_b, double inertia_factor) {
  // r²/I = 1/(inertia_factor m): each body adds 1/m + 1/(inertia_factor m).
  const double per_body = 1.0 + 1.0 / inertia_factor;
  double inverse = per_body / mass_a;
  if (mass_b > 0.0) inverse += per_body / mass_b;
  return 1.0 / inverse;
}

}  // namespace millsim
