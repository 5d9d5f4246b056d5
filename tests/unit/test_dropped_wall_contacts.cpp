// A particle pressed into more walls at once than it has slots of wall-contact history
// (World::max_wall_contacts): the contacts left out are counted, written to a scene's summary
// and warned of, never dropped silently.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "millsim/core/constants.hpp"
#include "millsim/io/config.hpp"
#include "millsim/sim/scene_run.hpp"
#include "millsim/sim/world.hpp"
#include "support/temporary_directory.hpp"

namespace millsim {
namespace {

/// A 2D scene: a disc falling at 1 m/s, no gravity, onto `planes` planes through the origin
/// whose normals lie within 6° of +y (90°, 87°, 93°, 84°, 96°, in that order). It starts clear
/// of them all (0.0202 m above the origin: at least 0.0202 sin 84° = 0.02009 m from each, more
/// than its radius of 0.02 m) and presses 0.3 mm or so into them: below 0.0199 m it overlaps
/// every one.
std::string bowl_scene(int planes) {
  std::string text = R"([simulation]
dimension = 2
time_step = 1e-5
duration = 3e-3
gravity = [0.0, 0.0]

[[particles]]
position = [0.0, 0.0202]
velocity = [0.0, -1.0]
diameter = 0.04
density = 7800

[output]
directory = "out"
)";
  const double degrees[] = {90.0, 87.0, 93.0, 84.0, 96.0};
  for (int k = 0; k < planes; ++k) {
    const double angle = degrees[k] * pi / 180.0;
    text += fmt::format("\n[[walls]]\npoint = [0.0, 0.0]\nnormal = [{}, {}]\n", std::cos(angle),
                        std::sin(angle));
  }
  return text;
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

TEST(DroppedWallContacts, FivePlanesAtOnceLeaveOneOutAndTheRunSaysSo) {
  // Four slots in 2D: while the disc overlaps all five planes, the fifth one's contact is left
  // out at each step.
  ASSERT_EQ(World<2>::max_wall_contacts, 4);
  const ScenePlan plan =
      plan_scene(std::get<SceneConfig>(parse_config(bowl_scene(5), "bowl.toml")));
  const std::filesystem::path directory = testing::fresh_directory("dropped-wall-contacts");
  const SceneResult result = run_scene(plan, directory);
  EXPECT_GT(result.dropped_wall_contacts, 10);
  EXPECT_LT(result.dropped_wall_contacts, result.steps);  // it bounces off
  EXPECT_NE(read_file(directory / "summary.json")
                .find(fmt::format("\"dropped_wall_contacts\" : {}", result.dropped_wall_contacts)),
            std::string::npos);
  const std::vector<std::string> warnings = scene_result_warnings(result);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(
      warnings[0].find(fmt::format("{} wall contacts were left out", result.dropped_wall_contacts)),
      std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[0].find("more than 4 walls at once"), std::string::npos) << warnings[0];
  std::filesystem::remove_all(directory);
}

TEST(DroppedWallContacts, FourPlanesAtOnceLeaveNoneOut) {
  const ScenePlan plan =
      plan_scene(std::get<SceneConfig>(parse_config(bowl_scene(4), "bowl.toml")));
  const std::filesystem::path directory = testing::fresh_directory("dropped-wall-contacts-4");
  const SceneResult result = run_scene(plan, directory);
  EXPECT_EQ(result.dropped_wall_contacts, 0);
  EXPECT_GT(result.ball_wall_collisions, 0);  // it did strike them
  EXPECT_NE(read_file(directory / "summary.json").find("\"dropped_wall_contacts\" : 0"),
            std::string::npos);
  EXPECT_TRUE(scene_result_warnings(result).empty());
  std::filesystem::remove_all(directory);
}

}  // namespace
}  // namespace millsim
