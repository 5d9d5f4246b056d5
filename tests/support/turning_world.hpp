// A mill's charge as placed, turning at once, for tests that step the same scene twice with
// one setting changed and compare the particles bit for bit.
#pragma once

#include <cstddef>

#include "millsim/sim/world.hpp"

namespace millsim::testing {

/// A copy of `built` (a world from build_mill_world, not yet stepped) with its neighbour skin
/// set to `skin` (0: chosen by the World) and the mill turning at `angular_speed` rad/s.
template <int D>
World<D> turning_copy(const World<D>& built, double angular_speed, double skin) {
  WorldSettings<D> settings = built.settings();
  settings.skin = skin;
  World<D> world(settings, built.walls());
  world.particles() = built.particles();
  world.walls().mill->angular_speed = angular_speed;
  return world;
}

/// How many particles differ in position, velocity or spin between two worlds (compared with
/// ==, index by index); the sum of both counts if their sizes differ.
template <int D>
std::size_t differing_particles(const World<D>& a, const World<D>& b) {
  const auto& p = a.particles();
  const auto& q = b.particles();
  if (p.size() != q.size()) return p.size() + q.size();
  std::size_t differing = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const bool same = p.position[i] == q.position[i] && p.velocity[i] == q.velocity[i] &&
                      p.angular_velocity[i] == q.angular_velocity[i];
    differing += same ? 0 : 1;
  }
  return differing;
}

}  // namespace millsim::testing
