// The lists of nearby lifters (World::set_nearby_lifter_lists, nearby_lifters()): each wall
// candidate keeps the lifters it may touch, made at each neighbour-list rebuild and again when
// the mill has turned the lifters by the smallest radius, and each step tests those alone. It
// is a shortcut, never a change to the physics: the same contacts must be found in the same
// order, so the motion is the same to the last bit. (So is the wall stage's other shortcut,
// which the lists make possible: a candidate with no lifter near, clear of the shell and the
// end plates, is passed over without a search; evaluate_wall_block.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <string>

#include "millsim/builtin_example.hpp"
#include "millsim/core/constants.hpp"
#include "millsim/io/config.hpp"
#include "millsim/sim/charge.hpp"
#include "millsim/sim/world.hpp"
#include "support/lifter_distance.hpp"
#include "support/turning_world.hpp"

namespace millsim {
namespace {

using testing::distance_to_lifter;

Mill2D mill_with(int lifters, double height, double width, double angle) {
  Mill2D mill;
  mill.radius = 0.45;
  mill.lifter_count = lifters;
  mill.lifter_height = height;
  mill.lifter_width = width;
  mill.turn_to(angle);
  return mill;
}

TEST(NearbyLifters, ListsEveryLifterWithinReachAndNoOther) {
  // Random centres over the mill and random reaches, on mills of 5 to 40 lifters: a known list
  // holds exactly the lifters whose bar is within the reach (checked against every lifter),
  // each once.
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int known = 0;
  int with_lifters = 0;
  for (const int lifters : {5, 8, 18, 40}) {
    for (int trial = 0; trial < 4000; ++trial) {
      const Mill2D mill = mill_with(lifters, 0.04, 0.04, 2.0 * pi * unit(random));
      const double rho = mill.radius * std::sqrt(unit(random));
      const double phi = 2.0 * pi * unit(random);
      const Vec2 centre{{rho * std::cos(phi), rho * std::sin(phi)}};
      const double reach = 0.005 + 0.05 * unit(random);
      const NearbyLifters nearby = nearby_lifters(mill, centre, reach);
      if (nearby.count == NearbyLifters::unknown) continue;
      ++known;
      int expected = 0;
      for (int k = 0; k < lifters; ++k) {
        const bool within = distance_to_lifter(mill, k, centre) < reach;
        expected += within ? 1 : 0;
        const int listed = static_cast<int>(
            std::count(nearby.index.begin(), nearby.index.begin() + nearby.count, k));
        EXPECT_EQ(listed, within ? 1 : 0) << lifters << " lifters, lifter " << k << ", centre ("
                                          << centre[0] << ", " << centre[1] << "), reach " << reach;
      }
      EXPECT_EQ(nearby.count, expected);
      with_lifters += expected > 0 ? 1 : 0;
    }
  }
  // Most lists are known, and enough of them hold lifters for the check to mean something.
  EXPECT_GT(known, 15000);
  EXPECT_GT(with_lifters, 1000);
}

TEST(NearbyLifters, UnknownWhenTheFullSearchMustDecide) {
  // Fewer than five lifters, or a reach that takes in most of the mill.
  const Vec2 near_shell{{0.43, 0.0}};
  EXPECT_EQ(nearby_lifters(mill_with(4, 0.04, 0.04, 0.0), near_shell, 0.01).count,
            NearbyLifters::unknown);
  EXPECT_EQ(nearby_lifters(mill_with(8, 0.04, 0.04, 0.0), near_shell, 0.5).count,
            NearbyLifters::unknown);
  // A centre far from the ring of the lifters has none.
  EXPECT_EQ(nearby_lifters(mill_with(8, 0.04, 0.04, 0.0), Vec2{{0.1, 0.0}}, 0.02).count, 0);
}

/// The built-in example's charge, placed and at once turning at `speed_factor` times the
/// mill's speed, stepped `steps` times with the lists of nearby lifters on or off. `skin`
/// fixes the neighbour skin (0: chosen); a wide one makes rebuilds rare, so that the lists are
/// also made again because the mill turned.
World<2> turning_example_2d(bool lists, double speed_factor, double skin, int steps) {
  const MillPlan plan = plan_mill(
      parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", {"output.snapshot_interval=0"}));
  World<2> world =
      testing::turning_copy(build_mill_world<2>(plan), speed_factor * plan.angular_speed, skin);
  world.set_nearby_lifter_lists(lists);
  for (int n = 0; n < steps; ++n) world.step();
  return world;
}

TEST(NearbyLifters, TheSameMotionToTheLastBitIn2D) {
  // 5 000 steps of the example's charge falling into its mill turning at 1 and at 3 times its
  // speed (the lifters sweep through the falling charge), with the chosen skin and with a
  // skin of three smallest radii, with which the lists are mostly remade because the mill
  // turned.
  const double smallest = 0.0254;
  for (const double speed_factor : {1.0, 3.0}) {
    for (const double skin : {0.0, 3.0 * smallest}) {
      const std::string what =
          "speed x" + std::to_string(speed_factor) + ", skin " + std::to_string(skin);
      const World<2> listed = turning_example_2d(true, speed_factor, skin, 5000);
      const World<2> searched = turning_example_2d(false, speed_factor, skin, 5000);
      EXPECT_EQ(testing::differing_particles(listed, searched), 0u) << what;
      EXPECT_EQ(listed.energy_account().shell_work, searched.energy_account().shell_work) << what;
      EXPECT_EQ(listed.touching_contacts(), searched.touching_contacts()) << what;
      // The lists were in use, and with the wide skin also remade between rebuilds.
      EXPECT_EQ(searched.nearby_lifter_refreshes(), 0) << what;
      EXPECT_GE(listed.nearby_lifter_refreshes(), listed.neighbour_rebuilds()) << what;
      if (skin > 0.0) {
        EXPECT_GT(listed.nearby_lifter_refreshes(), listed.neighbour_rebuilds() + 10) << what;
      }
      EXPECT_GT(listed.energy_account().shell_work, 0.0) << what;
    }
  }
}

/// Case 3D-g (the 0.9 m × 0.15 m mill, eight lifters, end plates) placed and at once turning
/// at `speed_factor` times its speed, `steps` steps, lists on or off.
World<3> turning_3d(bool lists, double speed_factor, double skin, int steps) {
  const MillPlan plan =
      plan_mill(load_mill_config(std::string(MILLSIM_SOURCE_DIR) + "/examples/validation/3D-g.toml",
                                 {"output.snapshot_interval=0"}));
  World<3> world =
      testing::turning_copy(build_mill_world<3>(plan), speed_factor * plan.angular_speed, skin);
  world.set_nearby_lifter_lists(lists);
  for (int n = 0; n < steps; ++n) world.step();
  return world;
}

TEST(NearbyLifters, TheSameMotionToTheLastBitIn3D) {
  for (const double skin : {0.0, 0.0762}) {
    const World<3> listed = turning_3d(true, 3.0, skin, 3000);
    const World<3> searched = turning_3d(false, 3.0, skin, 3000);
    EXPECT_EQ(testing::differing_particles(listed, searched), 0u) << "skin " << skin;
    EXPECT_EQ(listed.energy_account().shell_work, searched.energy_account().shell_work);
    // The lists were off in the searched run and in use in the listed one.
    EXPECT_EQ(searched.nearby_lifter_refreshes(), 0) << "skin " << skin;
    EXPECT_GE(listed.nearby_lifter_refreshes(), listed.neighbour_rebuilds());
    if (skin > 0.0) {
      EXPECT_GT(listed.nearby_lifter_refreshes(), listed.neighbour_rebuilds() + 10)
          << listed.neighbour_rebuilds() << " rebuilds";
    }
    EXPECT_GT(listed.energy_account().shell_work, 0.0);
  }
}

}  // namespace
}  // namespace millsim
