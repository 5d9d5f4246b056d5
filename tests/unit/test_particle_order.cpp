// Particles renumbered in cell order (World::set_cell_order_interval): each keeps its id, the
// contacts it had and its physics, and every output lists the particles by id, in the order
// they were added, as without renumbering.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "millsim/builtin_example.hpp"
#include "millsim/io/config.hpp"
#include "millsim/io/output.hpp"
#include "millsim/sim/charge.hpp"
#include "millsim/sim/scene_run.hpp"
#include "millsim/sim/world.hpp"
#include "support/temporary_directory.hpp"

namespace millsim {
namespace {

/// The built-in example's charge falling for `steps` steps from where it was placed, with
/// the particles renumbered at every `every`-th neighbour-list rebuild (0: never).
World<2> falling_charge(int every, int steps) {
  const MillPlan plan = plan_mill(
      parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", {"output.snapshot_interval=0"}));
  World<2> world = build_mill_world<2>(plan);
  world.set_cell_order_interval(every);
  for (int n = 0; n < steps; ++n) world.step();
  return world;
}

/// Particles whose index is not their id.
std::size_t renumbered(const World<2>& world) {
  std::size_t moved = 0;
  for (std::size_t i = 0; i < world.particles().size(); ++i) {
    moved += world.particle_id(i) != i ? 1 : 0;
  }
  return moved;
}

/// The lines of a text file.
std::vector<std::string> lines_of(const std::filesystem::path& path) {
  std::ifstream file(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(file, line);) lines.push_back(line);
  return lines;
}

/// The comma-separated fields of a CSV row.
std::vector<std::string> fields_of(const std::string& row) {
  std::vector<std::string> fields;
  std::stringstream stream(row);
  for (std::string field; std::getline(stream, field, ',');) fields.push_back(field);
  return fields;
}

// 2250 steps (0.29 s) of the example's charge falling into the still mill, through 33
// rebuilds, to 45 contacts: renumbered at every rebuild, each particle, found by its id, is
// where it is without renumbering but for the last bits that the other order of the force sums
// changes (seen: bitwise the same until particles touch two others, 1 ulp of position at step
// 2000, 3.6e-15 m at 2250, then ten times more every 250 steps as collisions amplify it), and
// the contacts kept their springs across the renumberings.
TEST(ParticleOrder, RenumberedParticlesKeepTheirIdsContactsAndPhysics) {
  const int steps = 2250;
  const World<2> plain = falling_charge(0, steps);
  const World<2> sorted = falling_charge(1, steps);
  ASSERT_EQ(sorted.particles().size(), plain.particles().size());
  EXPECT_EQ(renumbered(plain), 0u);
  EXPECT_GT(renumbered(sorted), sorted.particles().size() / 2) << "the charge was renumbered";
  EXPECT_GT(sorted.neighbour_rebuilds(), 10);
  EXPECT_GT(plain.touching_contacts(), 30u) << "the charge has reached the shell";

  // Ids are a permutation, each particle_index the inverse of particle_id.
  const std::size_t count = sorted.particles().size();
  std::vector<bool> seen(count, false);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t id = sorted.particle_id(i);
    ASSERT_LT(id, count);
    EXPECT_FALSE(seen[id]) << "id " << id << " twice";
    seen[id] = true;
    EXPECT_EQ(sorted.particle_index(id), i);
  }

  const ParticleStore<2> by_id = sorted.particles_by_id();
  const ParticleStore<2>& expected = plain.particles();
  double largest_offset = 0.0;
  for (std::size_t id = 0; id < count; ++id) {
    EXPECT_EQ(by_id.radius[id], expected.radius[id]) << "particle " << id;
    EXPECT_EQ(by_id.mass[id], expected.mass[id]) << "particle " << id;
    largest_offset = std::max(largest_offset, norm(by_id.position[id] - expected.position[id]));
    const std::size_t i = sorted.particle_index(id);
    EXPECT_EQ(sorted.particles().position[i], by_id.position[id]);
  }
  EXPECT_LT(largest_offset, 1e-12) << "m, after " << steps << " steps";
  EXPECT_EQ(sorted.touching_contacts(), plain.touching_contacts());
  EXPECT_NEAR(sorted.stored_spring_energy(), plain.stored_spring_energy(),
              1e-9 * plain.stored_spring_energy())
      << "contact springs survive the renumbering";
  EXPECT_NEAR(sorted.kinetic_energy(), plain.kinetic_energy(), 1e-12 * plain.kinetic_energy());
}

// A snapshot of a renumbered world lists the particles by id, 0, 1, 2, ..., each with its own
// radius and position, written so that they read back to the same doubles; index.csv names it
// with its time.
TEST(ParticleOrder, SnapshotListsParticlesById) {
  const World<2> world = falling_charge(1, 1000);
  ASSERT_GT(renumbered(world), 0u);
  const std::filesystem::path directory = testing::fresh_directory("particle-order");
  {
    SnapshotWriter snapshots(directory);
    snapshots.write(world);
  }
  const std::vector<std::string> lines = lines_of(directory / "snapshot_000000.csv");
  const ParticleStore<2> by_id = world.particles_by_id();
  ASSERT_EQ(lines.size(), by_id.size() + 1);
  EXPECT_EQ(lines[0], "id,x,y,vx,vy,omega,radius,fx,fy");
  for (std::size_t id = 0; id < by_id.size(); ++id) {
    const std::vector<std::string> fields = fields_of(lines[id + 1]);
    ASSERT_EQ(fields.size(), 9u);
    EXPECT_EQ(fields[0], fmt::format("{}", id));
    EXPECT_EQ(std::stod(fields[1]), by_id.position[id][0]) << "particle " << id;
    EXPECT_EQ(std::stod(fields[2]), by_id.position[id][1]) << "particle " << id;
    EXPECT_EQ(std::stod(fields[6]), by_id.radius[id]) << "particle " << id;
  }
  const std::vector<std::string> index = lines_of(directory / "index.csv");
  ASSERT_EQ(index.size(), 2u);
  EXPECT_EQ(index[0], "snapshot,file,time_s,shell_angle_rad");
  const std::vector<std::string> row = fields_of(index[1]);
  ASSERT_EQ(row.size(), 4u);
  EXPECT_EQ(row[0], "0");
  EXPECT_EQ(row[1], "snapshot_000000.csv");
  EXPECT_EQ(std::stod(row[2]), world.time());
  std::filesystem::remove_all(directory);
}

// A scene's particles are listed against the cell order (the last is in the first cell), so
// the first step renumbers them; final.csv and trajectory.csv still list them in the config's
// order. They fly free (no gravity, no walls, 0.2 m apart), so each ends where its own velocity
// takes it.
TEST(ParticleOrder, SceneOutputsListParticlesInTheConfigsOrder) {
  std::string text = R"([simulation]
dimension = 2
time_step = 1e-4
duration = 0.01
gravity = [0.0, 0.0]

[output]
directory = "out"
trajectory_interval = 0.005
)";
  const int count = 6;
  for (int k = 0; k < count; ++k) {
    text += fmt::format(
        "\n[[particles]]\nposition = [{}, {}]\nvelocity = [{}, 0.0]\ndiameter = 0.02\n"
        "density = 7800\n",
        0.2 * (count - 1 - k), 0.2 * (count - 1 - k), 0.1 * (k + 1));
  }
  const ScenePlan plan = plan_scene(std::get<SceneConfig>(parse_config(text, "fly.toml")));
  World<2> world = build_scene_world<2>(plan);
  world.step();
  EXPECT_EQ(renumbered(world), static_cast<std::size_t>(count)) << "reversed by the cell order";

  const std::filesystem::path directory = testing::fresh_directory("particle-order");
  run_scene(plan, directory);
  const std::vector<std::string> final_rows = lines_of(directory / "final.csv");
  ASSERT_EQ(final_rows.size(), static_cast<std::size_t>(count + 1));
  for (int k = 0; k < count; ++k) {
    const std::vector<std::string> fields = fields_of(final_rows[k + 1]);
    ASSERT_EQ(fields.size(), 7u);
    EXPECT_EQ(fields[1], fmt::format("{}", k));
    const double start = 0.2 * (count - 1 - k);
    EXPECT_NEAR(std::stod(fields[2]), start + 0.1 * (k + 1) * plan.config.duration, 1e-12);
    EXPECT_NEAR(std::stod(fields[3]), start, 1e-12);
  }
  // trajectory.csv: rows at t = 0, 0.005 s and the end, each block in the config's order.
  const std::vector<std::string> trajectory = lines_of(directory / "trajectory.csv");
  ASSERT_EQ(trajectory.size(), static_cast<std::size_t>(3 * count + 1));
  for (std::size_t row = 1; row < trajectory.size(); ++row) {
    EXPECT_EQ(fields_of(trajectory[row])[1], fmt::format("{}", (row - 1) % count));
  }
  std::filesystem::remove_all(directory);
}

}  // namespace
}  // namespace millsim
