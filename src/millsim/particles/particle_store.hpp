// The particles: one array per property, owned here (STYLE.md rule 1).
#pragma once

#include <cstddef>
#include <vector>

#include "millsim/core/vec.hpp"

namespace millsim {

/// I = inertia_factor · m r²: a disc in 2D (1/2), a sphere in 3D (2/5).
template <int D>
inline constexpr double inertia_factor = D == 2 ? 0.5 : 0.4;

template <int D>
struct ParticleStore {
  std::vector<Vec<D>> position;           ///< u(n), m
  std::vector<Vec<D>> velocity;           ///< u̇(n−½) before a step, u̇(n+½) after it, m/s
  std::vector<Spin<D>> angular_velocity;  ///< ω at the same half steps, rad/s
  std::vector<Vec<D>> force;              ///< net force of the last step, N
  std::vector<Spin<D>> torque;            ///< net torque of the last step, N m
  std::vector<double> radius;             ///< m
  std::vector<double> mass;               ///< kg
  std::vector<double> inverse_mass;
  std::vector<double> inverse_inertia;

  std::size_t size() const { return position.size(); }

  /// Calls f on every per-particle array above, for code that must treat them all alike
  /// (World's reordering into cell order): an array added above belongs in this list too.
  template <typename F>
  void for_each_array(F&& f) {
    f(position);
    f(velocity);
    f(angular_velocity);
    f(force);
    f(torque);
    f(radius);
    f(mass);
    f(inverse_mass);
    f(inverse_inertia);
  }

  /// Adds a particle at rest unless told otherwise. In 2D, `mass` is whatever the caller
  /// decides a disc carries (millsim's mills give each disc the mass of its sphere).
  std::size_t add(const Vec<D>& at, double particle_radius, double particle_mass,
                  const Vec<D>& initial_velocity = {}, const Spin<D>& initial_spin = {}) {
    position.push_back(at);
    velocity.push_back(initial_velocity);
    angular_velocity.push_back(initial_spin);
    force.push_back({});
    torque.push_back({});
    radius.push_back(particle_radius);
    mass.push_back(particle_mass);
    inverse_mass.push_back(1.0 / particle_mass);
    inverse_inertia.push_back(
        1.0 / (inertia_factor<D> * particle_mass * particle_radius * particle_radius));
    return size() - 1;
  }
};

}  // namespace millsim
