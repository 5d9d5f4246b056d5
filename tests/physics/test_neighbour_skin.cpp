// The neighbour list's skin (WorldSettings::skin): chosen by the World at each rebuild from the
// fastest particle unless the settings fix it, and never a change to the physics: the skin
// decides which pairs that are not touching get listed, and a pair that is not touching adds
// an exact zero to every force sum.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "millsim/builtin_example.hpp"
#include "millsim/io/config.hpp"
#include "millsim/sim/charge.hpp"
#include "millsim/sim/world.hpp"
#include "support/turning_world.hpp"

namespace millsim {
namespace {

constexpr double radius = 0.01;
constexpr double time_step = 1e-5;

/// Two discs far apart, the second moving at `speed` m/s, stepped once: the first rebuild.
World<2> two_discs_after_one_step(double speed, double fixed_skin = 0.0) {
  WorldSettings<2> settings;
  settings.time_step = time_step;
  settings.skin = fixed_skin;
  World<2> world(settings, Walls<2>{});
  world.particles().add(Vec2{{0.0, 0.0}}, radius, 0.1);
  world.particles().add(Vec2{{1.0, 0.0}}, 2.0 * radius, 0.8, Vec2{{0.0, speed}});
  world.step();
  return world;
}

TEST(NeighbourSkin, ChosenToLastTheTargetStepsAtTheFastestParticlesSpeed) {
  // 2 × 45 steps × 1e-5 s × 5 m/s = 4.5 mm, between 0.05 and 3 of the smallest radius (1 cm).
  const World<2> world = two_discs_after_one_step(5.0);
  EXPECT_DOUBLE_EQ(world.neighbour_skin(), 2.0 * skin_target_steps * time_step * 5.0);
  EXPECT_DOUBLE_EQ(world.neighbour_skin(), 0.0045);
}

TEST(NeighbourSkin, StillParticlesGetTheFloorAndFastOnesTheCeiling) {
  EXPECT_DOUBLE_EQ(two_discs_after_one_step(0.0).neighbour_skin(), skin_floor * radius);
  // 2 × 45 × 1e-5 s × 100 m/s = 9 cm would exceed three times the smallest radius (1 cm):
  // capped there.
  EXPECT_DOUBLE_EQ(two_discs_after_one_step(100.0).neighbour_skin(), skin_ceiling<2> * radius);
}

TEST(NeighbourSkin, TheCeilingIsThreeRadiiIn2DAndOneIn3D) {
  // The same fast particle (9 cm of skin wanted) in 3D is capped at one smallest radius.
  WorldSettings<3> settings;
  settings.time_step = time_step;
  World<3> world(settings, Walls<3>{});
  world.particles().add(Vec3{{0.0, 0.0, 0.0}}, radius, 0.1);
  world.particles().add(Vec3{{1.0, 0.0, 0.0}}, 2.0 * radius, 0.8, Vec3{{0.0, 100.0, 0.0}});
  world.step();
  EXPECT_DOUBLE_EQ(world.neighbour_skin(), 1.0 * radius);
  EXPECT_DOUBLE_EQ(two_discs_after_one_step(100.0).neighbour_skin(), 3.0 * radius);
}

TEST(NeighbourSkin, AFixedSkinIsKept) {
  EXPECT_DOUBLE_EQ(two_discs_after_one_step(5.0, 0.004).neighbour_skin(), 0.004);
  EXPECT_DOUBLE_EQ(two_discs_after_one_step(0.0, 0.004).neighbour_skin(), 0.004);
}

/// The built-in example's charge, placed and at once turning at the mill's speed, stepped
/// `steps` times with the given skin (0: chosen). Particles are not renumbered.
World<2> turning_example(double skin, int steps) {
  const MillPlan plan = plan_mill(
      parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", {"output.snapshot_interval=0"}));
  World<2> world = testing::turning_copy(build_mill_world<2>(plan), plan.angular_speed, skin);
  for (int n = 0; n < steps; ++n) world.step();
  return world;
}

TEST(NeighbourSkin, AnySkinGivesTheSameMotionToTheLastBit) {
  // 6 000 steps (0.4 s) of a charge falling into a turning mill: collisions with each other,
  // the shell and the lifters. The skin chosen by the World, and fixed at the smallest radius
  // and at three times it, list different pairs and rebuild at different times; every
  // particle's position, velocity and spin must still be the same, compared with ==.
  const int steps = 6000;
  const World<2> chosen = turning_example(0.0, steps);
  const double smallest =
      *std::min_element(chosen.particles().radius.begin(), chosen.particles().radius.end());
  const World<2> one_radius = turning_example(smallest, steps);
  const World<2> three_radii = turning_example(3.0 * smallest, steps);
  for (const World<2>* other : {&one_radius, &three_radii}) {
    ASSERT_NE(other->neighbour_rebuilds(), chosen.neighbour_rebuilds())
        << "the skins should have rebuilt the list at different times";
    ASSERT_EQ(chosen.particles().size(), other->particles().size());
    const std::size_t differing = testing::differing_particles(chosen, *other);
    EXPECT_EQ(differing, 0u) << "skin " << other->neighbour_skin() << " m";
    EXPECT_EQ(chosen.touching_contacts(), other->touching_contacts());
  }
  // Something happened: the charge moved and touched.
  EXPECT_GT(chosen.touching_contacts(), chosen.particles().size() / 2);
  EXPECT_GT(chosen.energy_account().shell_work, 0.0);
  // The chosen skin is the rule's, for the speeds at the last rebuild: within its bounds.
  EXPECT_GE(chosen.neighbour_skin(), skin_floor * smallest);
  EXPECT_LE(chosen.neighbour_skin(), skin_ceiling<2> * smallest);
}

}  // namespace
}  // namespace millsim
