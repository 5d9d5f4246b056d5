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
  const double normal_frequency = std::sqrt(material.normal_stiffness / effective_mass);
  const double tangential_frequency =
      std::sqrt(material.tangential_stiffness / tangential_mass_value);
  return 2.0 / std::max(normal_frequency, tangential_frequency);
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
