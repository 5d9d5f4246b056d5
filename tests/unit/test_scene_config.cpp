// Scene configs (no [mill]: particles and plane walls): what is read, the defaults, and the
// refusals, each naming the file, line and key and what is allowed.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <string>
#include <string_view>
#include <variant>

#include "millsim/core/error.hpp"
#include "millsim/core/version.hpp"
#include "millsim/io/config.hpp"
#include "millsim/sim/scene_run.hpp"
#include "support/temporary_directory.hpp"

namespace {

using millsim::SceneConfig;

constexpr std::string_view drop = R"([simulation]
dimension = 3
time_step = 1e-6
duration = 0.01

[[particles]]
position = [0.0, 0.0, 0.0105]
velocity = [3.0, 0.0, -2.0]
angular_velocity = [0.0, 0.0, 0.0]
diameter = 0.02
density = 4000
material = "ball"

[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 2.0]

[materials.ball_wall]
normal_stiffness = 1e6

[output]
directory = "out"
trajectory_interval = 1e-5
)";

SceneConfig scene(std::string_view text, std::initializer_list<std::string> overrides = {}) {
  const millsim::JobConfig job = millsim::parse_config(text, "drop.toml", overrides);
  EXPECT_TRUE(std::holds_alternative<SceneConfig>(job));
  return std::get<SceneConfig>(job);
}

/// The config is refused with a message holding every part.
void expect_refused(std::string_view text, std::initializer_list<std::string> overrides,
                    std::initializer_list<std::string_view> parts) {
  try {
    millsim::plan_scene(scene(text, overrides));
    ADD_FAILURE() << "accepted";
  } catch (const millsim::InputError& error) {
    const std::string message = error.what();
    for (const std::string_view part : parts) {
      EXPECT_NE(message.find(part), std::string::npos)
          << "message lacks \"" << part << "\":\n  " << message;
    }
  }
}

/// The first ```toml block of README.md's "Scenes" section, as the reader sees it; empty if the
/// README or the block is not found.
std::string readme_scene_example() {
  std::ifstream file(std::filesystem::path(MILLSIM_SOURCE_DIR) / "README.md");
  const std::string readme((std::istreambuf_iterator<char>(file)), {});
  const std::size_t section = readme.find("\n## Scenes");
  if (section == std::string::npos) return {};
  const std::string open = "\n```toml\n";
  const std::size_t start = readme.find(open, section);
  if (start == std::string::npos) return {};
  const std::size_t end = readme.find("\n```\n", start + open.size());
  if (end == std::string::npos) return {};
  // Inside the section, not a later one's block.
  if (readme.find("\n## ", section + 1) < start) return {};
  return readme.substr(start + open.size(), end + 1 - start - open.size());
}

TEST(SceneConfig, ReadsTheExampleOfTheReadme) {
  // Read from README.md itself, so that the example and this test cannot drift apart.
  const std::string example = readme_scene_example();
  ASSERT_NE(example.find("[[particles]]"), std::string::npos)
      << "no ```toml block with [[particles]] in README.md's \"Scenes\" section";
  const SceneConfig c = scene(example);
  EXPECT_EQ(c.dimension, 3);
  ASSERT_TRUE(c.time_step.has_value());
  EXPECT_EQ(*c.time_step, 1e-6);
  EXPECT_EQ(c.duration, 0.01);
  EXPECT_EQ(c.gravity, (std::array<double, 3>{0.0, 0.0, -9.81}));
  ASSERT_EQ(c.particles.size(), 1u);
  EXPECT_EQ(c.particles[0].position, (std::array<double, 3>{0.0, 0.0, 0.0105}));
  EXPECT_EQ(c.particles[0].velocity, (std::array<double, 3>{3.0, 0.0, -2.0}));
  EXPECT_EQ(c.particles[0].angular_velocity, (std::array<double, 3>{0.0, 0.0, 0.0}));
  EXPECT_EQ(c.particles[0].diameter, 0.02);
  EXPECT_EQ(c.particles[0].density, 4000.0);
  ASSERT_EQ(c.walls.size(), 1u);
  EXPECT_EQ(c.walls[0].point, (std::array<double, 3>{0.0, 0.0, 0.0}));
  EXPECT_EQ(c.walls[0].normal, (std::array<double, 3>{0.0, 0.0, 1.0}));
  // The empty material tables leave the defaults: k_n = 4e5 N/m, k_s = 2/3 of it.
  EXPECT_EQ(c.ball_ball.normal_stiffness, 4e5);
  EXPECT_EQ(c.ball_wall.normal_stiffness, 4e5);
  EXPECT_DOUBLE_EQ(c.ball_wall.tangential_stiffness, 2.0 / 3.0 * 4e5);
  EXPECT_EQ(c.output_directory, "out");
  EXPECT_EQ(c.trajectory_interval, 1e-5);
  // 0.01 s in steps of 1e-6 s: 10 000 steps; a trajectory row every 1e-5/1e-6 = 10 steps.
  const millsim::ScenePlan plan = millsim::plan_scene(c);
  EXPECT_EQ(plan.steps, 10000);
  EXPECT_EQ(plan.trajectory_every, 10);
}

TEST(SceneConfig, ReadsTheDropTestOfTheseTests) {
  // `drop`, the README's example with a stiffer wall and a normal of length 2.
  const SceneConfig c = scene(drop);
  EXPECT_EQ(c.dimension, 3);
  ASSERT_EQ(c.particles.size(), 1u);
  EXPECT_DOUBLE_EQ(c.particles[0].position[2], 0.0105);
  EXPECT_DOUBLE_EQ(c.particles[0].velocity[0], 3.0);
  EXPECT_DOUBLE_EQ(c.particles[0].density, 4000.0);
  ASSERT_EQ(c.walls.size(), 1u);
  EXPECT_DOUBLE_EQ(c.walls[0].normal[2], 1.0) << "the normal is made a unit vector";
  EXPECT_DOUBLE_EQ(c.ball_wall.normal_stiffness, 1e6);
  EXPECT_DOUBLE_EQ(c.gravity[2], -9.81) << "gravity is on by default";
  EXPECT_DOUBLE_EQ(c.trajectory_interval, 1e-5);
  const millsim::ScenePlan plan = millsim::plan_scene(c);
  EXPECT_EQ(plan.steps, 10000);
  EXPECT_EQ(plan.trajectory_every, 10);
}

TEST(SceneConfig, AMillConfigIsStillAMill) {
  const millsim::JobConfig job = millsim::parse_config(
      "[mill]\ndiameter = 0.9\nlength = 0.15\nspeed = 0.5\n[charge]\nfilling = 0.3\n"
      "ball_diameter = 0.05\n",
      "mill.toml");
  EXPECT_TRUE(std::holds_alternative<millsim::MillConfig>(job));
}

TEST(SceneConfig, TwoDimensionalScenesTakeTwoVectorsAndAScalarSpin) {
  const SceneConfig c = scene(
      "[simulation]\nduration = 0.1\n[[particles]]\nposition = [0.0, 0.5]\n"
      "angular_velocity = 3.0\ndiameter = 0.02\n");
  EXPECT_EQ(c.dimension, 2);
  EXPECT_DOUBLE_EQ(c.gravity[1], -9.81);
  EXPECT_DOUBLE_EQ(c.particles[0].angular_velocity[0], 3.0);
  EXPECT_DOUBLE_EQ(c.particles[0].density, 7800.0);
  const millsim::ScenePlan plan = millsim::plan_scene(c);
  EXPECT_EQ(plan.steps, 1000) << "nothing to touch: 1000 steps over the duration";
}

TEST(SceneConfig, AutoTimeStepIsATwentiethOfTheShortestContact) {
  std::string text(drop);
  text.replace(text.find("time_step = 1e-6"), 16, "time_step = \"auto\"");
  const millsim::ScenePlan plan = millsim::plan_scene(scene(text));
  // By hand: one sphere of 4000 kg/m³ and 0.02 m, m = 4000 π/6 0.02³ = 0.016755161 kg, on a wall
  // (m* = m) of k_n = 1e6 N/m and the default e = 0.6: ζ = −ln 0.6 / sqrt(ln² 0.6 + π²) =
  // 0.16049305, ω_0 = sqrt(k_n/m) = 7725.5 s⁻¹, t_c = π / (ω_0 sqrt(1 − ζ²)) = 4.1199387e-4 s.
  EXPECT_NEAR(plan.shortest_contact, 4.1199387e-4, 1e-11);
  EXPECT_NEAR(plan.time_step, 2.0599693e-5, 1e-12);
  EXPECT_DOUBLE_EQ(plan.time_step, plan.shortest_contact / 20.0);
  EXPECT_LT(plan.time_step, plan.critical_time_step);
}

TEST(SceneConfig, WarnsOfAGivenTimeStepCoarserThanATenthOfTheShortestContact) {
  // The contact above lasts 4.1199387e-4 s: 5e-5 s is 8.2 steps of it, stable but coarse.
  const millsim::ScenePlan coarse = millsim::plan_scene(scene(drop, {"simulation.time_step=5e-5"}));
  ASSERT_EQ(coarse.warnings.size(), 1u);
  for (const char* part : {"command line (--set simulation.time_step=5e-5)", "simulation.time_step",
                           "in 8.24 steps, fewer than 10", "2.06e-05 s"}) {
    EXPECT_NE(coarse.warnings[0].find(part), std::string::npos) << coarse.warnings[0];
  }
  EXPECT_TRUE(millsim::plan_scene(scene(drop, {"simulation.time_step=4e-5"})).warnings.empty());
  EXPECT_TRUE(millsim::plan_scene(scene(drop)).warnings.empty());
}

TEST(SceneConfig, RefusesAnUnstableTimeStepAndGivesTheLimit) {
  // The limit of docs/model.md ("Time step"), each mode's 2 / (ω (sqrt(1 + 4 ζ²) + 2 ζ)), for
  // drop's one sphere on its wall: m = 4000 π/6 0.02³ = 0.016755161 kg (m* = m against a wall);
  // ball–wall k_n = 1e6 N/m, the default k_s = 2/3 k_n = 666 667 N/m and e = 0.6, ζ = 0.16049305.
  // A sphere (I = 2/5 m r²) adds 1/m + 5/2 m to 1/m_t: m_t = 2m/7 = 4.7872e-3 kg, and the
  // tangential ratio is ζ sqrt(m/m_t) = ζ sqrt(3.5) = 0.30025500. ω_n = sqrt(1e6/m) =
  // 7725.484 s⁻¹: limit 2/(7725.484 · 1.37124) = 1.88795e-4 s; ω_t = sqrt(666 667/4.7872e-3) =
  // 11 800.87 s⁻¹: limit 2/(11 800.87 · (sqrt(1 + 4 · 0.300255²) + 2 · 0.300255)) =
  // 2/(11 800.87 · 1.76696) = 9.5915432e-5 s, the shorter, printed as 9.59154e-05 (six digits
  // that do not read as above it).
  // The shortest contact is AutoTimeStepIsATwentiethOfTheShortestContact's t_c = 4.1199387e-4 s
  // (0.000412), and 1/20 of it 2.0599693e-5 s (2.06e-05).
  expect_refused(drop, {"simulation.time_step=1e-3"},
                 {"command line (--set simulation.time_step=1e-3): simulation.time_step: 0.001 s "
                  "is unstable for these particles and materials (the shortest contact lasts "
                  "0.000412 s); allowed: a time step below the stability limit 9.59154e-05 s, and "
                  "for accuracy about 2.06e-05 s (1/20 of the contact), or \"auto\""});
}

TEST(SceneConfig, RefusesADurationShorterThanOneTimeStep) {
  // The drop's auto step is 2.0599693e-5 s (AutoTimeStepIsATwentiethOfTheShortestContact): a
  // scene of 1e-5 s would run one step, twice as long as asked.
  std::string text(drop);
  text.replace(text.find("time_step = 1e-6"), 16, "time_step = \"auto\"");
  expect_refused(text, {"simulation.duration=1e-5"},
                 {"command line (--set simulation.duration=1e-5): simulation.duration: 1e-05 s is "
                  "shorter than one time step, 2.0599693",
                  "(the auto step, 1/20 of the shortest contact: a smaller time_step gives a "
                  "shorter one); allowed: a duration of at least one time step"});
  expect_refused(drop, {"simulation.duration=5e-7"},
                 {"simulation.duration: 5e-07 s is shorter than one time step, 1e-06 s "
                  "(simulation.time_step)"});
  EXPECT_EQ(millsim::plan_scene(scene(drop, {"simulation.duration=1e-6"})).steps, 1);
}

TEST(SceneConfig, RefusesTooManyStepsWithACountThatReads) {
  // 0.01 s in steps of 1e-13 s: 1e11 steps, ten times the most a scene runs.
  expect_refused(drop, {"simulation.time_step=1e-13"},
                 {"simulation.duration: 0.01 s at a time step of 1e-13 s is 1e+11 steps; "
                  "allowed: at most 1e+10 steps"});
  // A subnormal step: 0.01 / 1e-320 overflows, and once read "inf steps".
  expect_refused(drop, {"simulation.time_step=1e-320"},
                 {"is more than 1.7e+308 steps; allowed: at most 1e+10 steps"});
}

TEST(SceneConfig, RefusesAMillKeyInAScene) {
  expect_refused(std::string(drop) + "\n", {"simulation.settle_time=1"},
                 {"simulation.settle_time", "unknown key", "a mill key"});
  // Snapshots are a mill's output; a scene writes its trajectory.
  expect_refused(std::string(drop) + "\n", {"output.snapshot_format=vtk"},
                 {"output.snapshot_format: unknown key (a mill key; a scene (a config without "
                  "[mill]) does not use it)"});
}

TEST(SceneConfig, RefusesAVectorOfTheWrongLength) {
  std::string text(drop);
  text.replace(text.find("[3.0, 0.0, -2.0]"), 16, "[3.0, -2.0]");
  expect_refused(text, {}, {"drop.toml:8", "particles[0].velocity", "2 values", "[x, y, z]"});
}

TEST(SceneConfig, RefusesANonNumberInAVector) {
  std::string text(drop);
  text.replace(text.find("[3.0, 0.0, -2.0]"), 16, "[3.0, \"a\", -2.0]");
  expect_refused(text, {}, {"particles[0].velocity", "not a finite number"});
}

TEST(SceneConfig, RefusesAnUnknownKeyOfAParticle) {
  std::string text(drop);
  text.replace(text.find("density = 4000"), 14, "densty = 4000");
  expect_refused(text, {}, {"drop.toml:11", "particles[0].densty", "did you mean density"});
}

TEST(SceneConfig, RefusesAMissingDurationAndAMissingDiameter) {
  std::string text(drop);
  text.replace(text.find("duration = 0.01"), 15, "");
  expect_refused(text, {}, {"simulation.duration", "missing required key"});
  text = drop;
  text.replace(text.find("diameter = 0.02"), 15, "");
  expect_refused(text, {}, {"particles[0].diameter", "missing required key"});
}

TEST(SceneConfig, RefusesAnUnknownMaterial) {
  std::string text(drop);
  text.replace(text.find("\"ball\""), 6, "\"rock\"");
  expect_refused(text, {},
                 {"drop.toml:12", "particles[0].material", "\"rock\"", "allowed: \"ball\""});
}

TEST(SceneConfig, RefusesAZeroWallNormal) {
  std::string text(drop);
  text.replace(text.find("[0.0, 0.0, 2.0]"), 15, "[0.0, 0.0, 0.0]");
  expect_refused(text, {}, {"walls[0].normal", "zero vector"});
  // A normal too short to square (1e-200² underflows to 0) is not zero: it is scaled first.
  std::string tiny(drop);
  tiny.replace(tiny.find("[0.0, 0.0, 2.0]"), 15, "[0.0, 0.0, 1e-200]");
  EXPECT_EQ(scene(tiny).walls[0].normal, (std::array<double, 3>{0.0, 0.0, 1.0}));
}

TEST(SceneConfig, RefusesAParticleStartingInsideAWall) {
  std::string text(drop);
  text.replace(text.find("0.0105"), 6, "0.005");
  expect_refused(text, {}, {"drop.toml:7", "particles[0]", "overlapping walls[0]"});
}

TEST(SceneConfig, RefusesParticlesThatOverlapAtTheStart) {
  const std::string text =
      std::string(drop) + "\n[[particles]]\nposition = [0.015, 0.0, 0.0105]\ndiameter = 0.02\n";
  expect_refused(text, {}, {"particles[0]", "particles[1] overlap"});
}

TEST(SceneConfig, RefusesAConfigWithoutParticlesOrMill) {
  // Walls without a mill make a scene: the refusal is the scene reader's missing [[particles]],
  // not parse_config's "missing required table [mill], and no [[particles]] either" (which also
  // holds "particles" and "missing required").
  expect_refused("[simulation]\nduration = 1\n[[walls]]\npoint = [0, 0]\nnormal = [0, 1]\n", {},
                 {"drop.toml: particles: missing required table [particles]; allowed: an array of "
                  "tables [[particles]], each with position ([x, y]), diameter, and optionally "
                  "velocity, angular_velocity, density, material"});
}

TEST(SceneConfig, AConfigOfNeitherKindNamesAnUnknownTopLevelTableFirst) {
  // "[[particle]]" for "[[particles]]": the config is then neither a mill nor a scene, and the
  // misspelt table, with its line, is what to say, not only that [mill] is missing.
  expect_refused("[simulation]\nduration = 1\n[[particle]]\nposition = [0, 0]\n", {},
                 {"drop.toml:3: particle: unknown table (did you mean particles?), and the config "
                  "has neither [mill] nor [[particles]]; allowed at the top level: simulation, "
                  "mill, charge, materials, output, reference, particles, walls"});
  expect_refused("[simulation]\nduration = 1\n", {"particle.x=1"},
                 {"command line (--set particle.x=1): particle: unknown table"});
}

TEST(SceneConfig, AConfigOfNeitherKindNamesAnUnknownSimulationKeyNext) {
  // "particles = 5" under [simulation] (a count where a scene lists its particles): named with
  // its line, not only that [mill] is missing.
  expect_refused("[simulation]\ndimension = 2\nparticles = 5\n", {},
                 {"drop.toml:3: simulation.particles: unknown key, and the config has neither "
                  "[mill] nor [[particles]]; allowed in [simulation]: dimension, time_step, "
                  "settle_time, revolutions, measure_revolutions, seed (a mill) or dimension, "
                  "time_step, duration, gravity (a scene)"});
  expect_refused("[simulation]\nduraton = 1\n", {},
                 {"drop.toml:2: simulation.duraton: unknown key (did you mean duration?)"});
  // Every key known to one kind or the other: the missing [mill] is what to say.
  expect_refused("[simulation]\nduration = 1\nseed = 3\n", {},
                 {"drop.toml: mill: missing required table [mill], and no [[particles]] either"});
}

TEST(SceneConfig, AMillCommandRefusesASceneClearly) {
  try {
    millsim::parse_mill_config(drop, "drop.toml");
    ADD_FAILURE() << "accepted";
  } catch (const millsim::InputError& error) {
    EXPECT_NE(std::string(error.what()).find("this is a scene config"), std::string::npos)
        << error.what();
  }
}

/// Runs `millsim ARGS` in `directory`; returns the exit status.
int millsim_in(const std::filesystem::path& directory, const std::string& args) {
  const std::string command = "cd \"" + directory.string() + "\" && \"" + MILLSIM_BINARY + "\" " +
                              args + " >/dev/null 2>stderr.txt";
  const int raw = std::system(command.c_str());
  return raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

TEST(SceneRun, WritesTrajectoryFinalAndSummaryAndNothingPartial) {
  namespace fs = std::filesystem;
  const fs::path work = millsim::testing::fresh_directory("scene");
  ASSERT_FALSE(work.empty());
  std::ofstream(work / "drop.toml") << drop;
  ASSERT_EQ(millsim_in(work, "run drop.toml -q --out out"), 0);
  for (const char* name : {"trajectory.csv", "final.csv", "summary.json"}) {
    EXPECT_TRUE(fs::exists(work / "out" / name)) << name;
  }
  int files = 0;
  for (const auto& entry : fs::directory_iterator(work / "out")) {
    ++files;
    EXPECT_NE(entry.path().extension(), ".partial") << entry.path();
  }
  EXPECT_EQ(files, 3);
  // 10000 steps, a row every 10: 1001 rows and the header.
  std::ifstream trajectory(work / "out" / "trajectory.csv");
  int lines = 0;
  for (std::string line; std::getline(trajectory, line);) ++lines;
  EXPECT_EQ(lines, 1002);
  // The summary names the program that made it.
  std::ifstream summary(work / "out" / "summary.json");
  const std::string json((std::istreambuf_iterator<char>(summary)), {});
  EXPECT_NE(json.find("\"millsim_version\" : \"" + millsim::version_text() + "\""),
            std::string::npos)
      << json;
  EXPECT_NE(json.find("\"shortest_contact_duration_s\" : "), std::string::npos) << json;
  EXPECT_NE(json.find("\"critical_time_step_s\" : "), std::string::npos) << json;

  // A particle that can touch nothing (no wall, no other particle) has no contact duration and
  // no stability limit: the summary leaves both out rather than write 0.
  std::string alone(drop);
  alone.erase(alone.find("[[walls]]"), alone.find("[materials") - alone.find("[[walls]]"));
  std::ofstream(work / "alone.toml") << alone;
  ASSERT_EQ(millsim_in(work, "run alone.toml -q --out alone"), 0);
  std::ifstream alone_summary(work / "alone" / "summary.json");
  const std::string alone_json((std::istreambuf_iterator<char>(alone_summary)), {});
  EXPECT_EQ(alone_json.find("shortest_contact_duration_s"), std::string::npos) << alone_json;
  EXPECT_EQ(alone_json.find("critical_time_step_s"), std::string::npos) << alone_json;
  EXPECT_NE(alone_json.find("\"wall_count\" : 0,"), std::string::npos) << alone_json;

  // A config whose name holds a quote and a backslash: the summary's strings are escaped, so
  // that it stays JSON.
  std::ofstream(work / "a\"b\\c.toml") << drop;
  ASSERT_EQ(millsim_in(work, "run 'a\"b\\c.toml' -q --out odd"), 0);
  std::ifstream odd_summary(work / "odd" / "summary.json");
  const std::string odd_json((std::istreambuf_iterator<char>(odd_summary)), {});
  EXPECT_NE(odd_json.find(R"("config" : "a\"b\\c.toml",)"), std::string::npos) << odd_json;

  // A refused scene writes nothing.
  std::string bad(drop);
  bad.replace(bad.find("0.0105"), 6, "0.005");
  std::ofstream(work / "bad.toml") << bad;
  EXPECT_EQ(millsim_in(work, "run bad.toml -q --out refused"), 2);
  EXPECT_FALSE(fs::exists(work / "refused"));
  std::error_code ignored;
  fs::remove_all(work, ignored);
}

TEST(SceneRun, ASceneRunWhereAMillRanLeavesNoneOfTheMillsResultsAndTheOtherWayRound) {
  // Each kind once cleared only its own results: a scene run into a mill run's directory left
  // power.csv and the rest (and snapshots/) beside the scene's summary.json, which says the
  // run finished, so that they looked like its results.
  namespace fs = std::filesystem;
  const fs::path work = millsim::testing::fresh_directory("scene");
  ASSERT_FALSE(work.empty());
  std::ofstream(work / "drop.toml") << drop;
  const std::string tiny_mill =
      "run -q --out out --set simulation.revolutions=1 --set simulation.measure_revolutions=1 "
      "--set simulation.settle_time=0.01 --set output.snapshot_interval=0.05";
  const std::vector<std::string> mill_files = {"power.csv",    "power_timeseries.csv",
                                               "spectrum.csv", "charge_profile.csv",
                                               "impacts.csv",  "snapshots"};
  ASSERT_EQ(millsim_in(work, tiny_mill), 0);
  for (const std::string& name : mill_files) EXPECT_TRUE(fs::exists(work / "out" / name)) << name;
  ASSERT_EQ(millsim_in(work, "run drop.toml -q --out out"), 0);
  for (const std::string& name : mill_files) EXPECT_FALSE(fs::exists(work / "out" / name)) << name;
  EXPECT_TRUE(fs::exists(work / "out" / "trajectory.csv"));
  ASSERT_EQ(millsim_in(work, tiny_mill), 0);
  EXPECT_FALSE(fs::exists(work / "out" / "trajectory.csv"));
  EXPECT_FALSE(fs::exists(work / "out" / "final.csv"));
  EXPECT_TRUE(fs::exists(work / "out" / "power.csv"));
  std::error_code ignored;
  fs::remove_all(work, ignored);
}

TEST(SceneConfig, ATrajectoryIntervalAsLongAsTheRunOrLongerGivesOnlyStartAndEnd) {
  // 10000 steps of 1e-6 s.
  EXPECT_EQ(millsim::plan_scene(scene(drop)).trajectory_every, 10);
  EXPECT_EQ(
      millsim::plan_scene(scene(drop, {"output.trajectory_interval=0.00999"})).trajectory_every,
      9990);
  // As long as the run, or so long that its step count would not fit in a long (from about
  // 9.2e18 steps; it once wrapped round to a row every step).
  for (const std::string interval : {"0.01", "4.3e14", "1e300"}) {
    EXPECT_EQ(millsim::plan_scene(scene(drop, {"output.trajectory_interval=" + interval}))
                  .trajectory_every,
              0)
        << interval;
  }
}

TEST(SceneConfig, RefusesSpeedsSizesAndPlacesBeyondAnyScene) {
  // Their squares and energies must stay finite (a speed of 1e300 wrote inf into the summary).
  std::string fast(drop);
  fast.replace(fast.find("velocity = [3.0, 0.0, -2.0]"), 27, "velocity = [1e300, 0.0, 0.0]");
  expect_refused(
      fast, {},
      {"drop.toml:8", "particles[0].velocity", "1e+300 is out of range", "within ±10000"});
  expect_refused(drop, {"particles=[{position = [0.0, 0.0, 0.5], diameter = 1e3}]"},
                 {"particles[0].diameter", "from 0.0001 to 100"});
  // A particle of 1e-300 m has no mass in doubles: its contact duration was inf, then nan.
  expect_refused(drop, {"particles=[{position = [0.0, 0.0, 0.5], diameter = 1e-300}]"},
                 {"particles[0].diameter", "1e-300 is not allowed", "from 0.0001 to 100"});
  std::string far(drop);
  far.replace(far.find("normal = [0.0, 0.0, 2.0]"), 24, "normal = [1e300, 1e300, 1e300]");
  expect_refused(far, {}, {"walls[0].normal", "out of range"});
  // Gravity too (1e300 wrote inf and -inf into the summary).
  expect_refused(drop, {"simulation.gravity=[0.0, 0.0, -1e300]"},
                 {"simulation.gravity", "-1e+300 is out of range", "within ±10000"});
  EXPECT_DOUBLE_EQ(scene(drop, {"simulation.gravity=[0.0, 0.0, -1e4]"}).gravity[2], -1e4);
}

TEST(SceneConfig, AConfigThatIsNeitherAMillNorASceneSaysSo) {
  // Without [mill] or [[particles]], judging [simulation] by a mill's keys misled (duration
  // "unknown").
  for (const std::string_view text :
       {std::string_view("[simulation]\nduration = 0.05\n"), std::string_view("")}) {
    try {
      millsim::parse_config(text, "drop.toml", {});
      ADD_FAILURE() << "accepted: " << text;
    } catch (const millsim::InputError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("drop.toml: mill: missing required table [mill], and no "
                             "[[particles]] either"),
                std::string::npos)
          << message;
    }
  }
}

}  // namespace
