// Wall-contact history (the springs of a particle's contacts with walls) is kept per wall
// candidate, the particles near a wall, and carried to the new candidate list at each
// neighbour-list rebuild (World::refresh_neighbours). A particle's wall contacts must not
// notice particles that join or leave the list around it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>

#include "millsim/measure/spectrum.hpp"
#include "millsim/sim/world.hpp"

namespace millsim {
namespace {

constexpr double radius = 0.01;
constexpr double mass = 0.0327;
constexpr double time_step = 2e-5;

/// A floor (z = 0) and a ball resting on it at x = 0, pushed sideways so that it slides and
/// then rolls: its tangential spring with the floor carries over many rebuilds. With `crowd`,
/// balls at x = 1 m are dropped in turn from heights that bring them to the floor, and back
/// up, at different times, so that they join and leave the wall candidates before and after
/// the resting ball; they never come near it. The crowd is added first, so that it comes
/// before the resting ball in the candidate list. With `side_wall`, a second plane (y = 0,
/// normal +y) that a sideways pull of gravity keeps the ball pressed against as it slides: its
/// second wall contact, held in its second slot.
World<3> ball_on_floor(bool crowd, int steps, ImpactSpectrum* spectrum = nullptr,
                       bool side_wall = false) {
  WorldSettings<3> settings;
  settings.time_step = time_step;
  settings.gravity = Vec3{{0.0, side_wall ? -2.0 : 0.0, -9.81}};
  settings.ball_wall.friction = 0.6;
  Walls<3> walls;
  walls.planes.push_back(Plane<3>{Vec3{}, Vec3{{0.0, 0.0, 1.0}}});
  if (side_wall) walls.planes.push_back(Plane<3>{Vec3{}, Vec3{{0.0, 1.0, 0.0}}});
  World<3> world(settings, walls);
  const double y = side_wall ? radius - 1e-6 : 0.0;
  if (crowd) {
    for (int k = 0; k < 6; ++k) {
      world.particles().add(Vec3{{1.0, 0.05 + 0.03 * k, radius + 0.002 + 0.004 * k}}, radius, mass,
                            Vec3{{0.0, 0.0, 0.3 - 0.1 * k}});
    }
  }
  world.particles().add(Vec3{{0.0, y, radius - 1e-6}}, radius, mass, Vec3{{0.2, 0.0, 0.0}});
  world.record_collisions_in(spectrum);
  for (int n = 0; n < steps; ++n) world.step();
  world.record_collisions_in(nullptr);
  return world;
}

TEST(WallHistory, ABallsFloorContactIgnoresBallsJoiningAndLeavingTheWallCandidates) {
  // 3000 steps (0.06 s): the resting ball slides, its friction spring loads and it starts to
  // roll; the crowd bounces on the floor far away, so the list is rebuilt and the candidates
  // renumbered many times. The resting ball must move the same to the last bit.
  const int steps = 3000;
  const World<3> alone = ball_on_floor(false, steps);
  ImpactSpectrum spectrum;
  const World<3> crowded = ball_on_floor(true, steps, &spectrum);
  const std::size_t last = crowded.particles().size() - 1;
  EXPECT_EQ(alone.particles().position[0], crowded.particles().position[last]);
  EXPECT_EQ(alone.particles().velocity[0], crowded.particles().velocity[last]);
  EXPECT_EQ(alone.particles().angular_velocity[0], crowded.particles().angular_velocity[last]);
  // The scene did what it is for: the crowd made rebuilds, the ball touches the floor with a
  // loaded tangential spring (it spins), and the crowd's balls hit the floor and leave it.
  EXPECT_GT(crowded.neighbour_rebuilds(), alone.neighbour_rebuilds() + 5);
  EXPECT_GT(std::abs(crowded.particles().angular_velocity[last][1]), 1.0);
  EXPECT_GE(crowded.touching_contacts(), 1u);
  EXPECT_GE(spectrum.total_count(ContactType::ball_plane), 3);
  EXPECT_LT(crowded.wall_candidate_count(), crowded.particles().size());
}

TEST(WallHistory, ABallsTwoWallContactsIgnoreBallsJoiningAndLeavingTheWallCandidates) {
  // The same with the ball in the corner of the floor and a side wall: each candidate's second
  // slot is carried to its new place at every rebuild as its first is (the histories are kept
  // slot by slot, each slot an array over the candidates, whose number the crowd changes).
  const int steps = 3000;
  const World<3> alone = ball_on_floor(false, steps, nullptr, true);
  ImpactSpectrum spectrum;
  const World<3> crowded = ball_on_floor(true, steps, &spectrum, true);
  const std::size_t last = crowded.particles().size() - 1;
  EXPECT_EQ(alone.particles().position[0], crowded.particles().position[last]);
  EXPECT_EQ(alone.particles().velocity[0], crowded.particles().velocity[last]);
  EXPECT_EQ(alone.particles().angular_velocity[0], crowded.particles().angular_velocity[last]);
  // Both of the ball's contacts held to the end, its side contact's spring loaded (it spins
  // about z as well as y), and the crowd changed the candidates at the rebuilds.
  EXPECT_EQ(alone.touching_contacts(), 2u);
  EXPECT_GT(std::abs(crowded.particles().angular_velocity[last][1]), 1.0);
  EXPECT_GT(std::abs(crowded.particles().angular_velocity[last][2]), 1.0);
  EXPECT_GT(crowded.neighbour_rebuilds(), alone.neighbour_rebuilds() + 5);
  EXPECT_GE(spectrum.total_count(ContactType::ball_plane), 3);
  EXPECT_LT(crowded.wall_candidate_count(), crowded.particles().size());
}

}  // namespace
}  // namespace millsim
