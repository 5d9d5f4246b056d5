// The millsim program on bad input: each refusal exits with status 2, prints one message on
// stderr ("millsim: error: FILE:LINE: dotted.key: ...; allowed: ...") and writes nothing. Each
// test runs the built program in a fresh temporary directory.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "millsim/core/version.hpp"
#include "support/config_text.hpp"
#include "support/program_test.hpp"

namespace {

using millsim::testing::line_of;
using millsim::testing::Outcome;
using millsim::testing::ProgramTest;
using millsim::testing::quoted;
using millsim::testing::read_all;
using millsim::testing::with;

namespace fs = std::filesystem;

// A small complete config; the tests change one line of it at a time.
constexpr std::string_view base_config = R"([simulation]
time_step = "auto"
revolutions = 6
measure_revolutions = 4

[mill]
diameter = 0.9
length = 0.15
speed = 0.5

[mill.lifters]
count = 8
height = 0.04
width = 0.04

[charge]
filling = 0.3
density = 7800
ball_diameter = 0.0508

[output]
directory = "out"
snapshot_interval = 0.05
)";

// A run short enough for a unit test (a fraction of a second).
constexpr const char* tiny_run =
    "--set simulation.revolutions=1 --set simulation.measure_revolutions=1 "
    "--set simulation.settle_time=0.01 --set output.snapshot_interval=0";

/// "mill.toml:LINE" for the line of `text` that starts with `start`.
std::string at_line(std::string_view text, std::string_view start) {
  return millsim::testing::at_line("mill.toml", text, start);
}

class Cli : public ProgramTest {
 protected:
  /// Writes the config `mill.toml` in the working directory.
  void write_config(std::string_view text) const { std::ofstream(work_ / "mill.toml") << text; }

  /// Runs `millsim run mill.toml -o out -q EXTRA` on `text`.
  Outcome run_config(std::string_view text, const std::string& extra = {}) const {
    write_config(text);
    return millsim("run mill.toml -o out -q " + extra);
  }

  /// The run was refused as bad input: status 2, one "millsim: error:" message holding every
  /// part, and nothing written next to the config.
  void expect_refused(const Outcome& o, std::initializer_list<std::string_view> parts) const {
    EXPECT_EQ(o.status, 2) << o.err;
    EXPECT_TRUE(o.err.starts_with("millsim: error: ")) << o.err;
    EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
    for (const std::string_view part : parts) {
      EXPECT_NE(o.err.find(part), std::string::npos)
          << "message lacks \"" << part << "\":\n  " << o.err;
    }
    EXPECT_FALSE(fs::exists(work_ / "out")) << "the output directory was created";
    for (const auto& entry : fs::directory_iterator(work_)) {
      EXPECT_EQ(entry.path().filename(), "mill.toml") << "written: " << entry.path();
    }
  }
};

TEST_F(Cli, ATinyRunOfTheBaseConfigWritesItsResults) {
  // The control for every "nothing written" check below.
  const Outcome o = run_config(base_config, tiny_run);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_TRUE(fs::exists(work_ / "out" / "summary.json"));
  EXPECT_NE(o.out.find("power"), std::string::npos) << o.out;
  // The summary names the program that made it, as --version does.
  EXPECT_NE(read_all(work_ / "out" / "summary.json")
                .find("\"millsim_version\" : \"" + millsim::version_text() + "\""),
            std::string::npos)
      << read_all(work_ / "out" / "summary.json");
}

TEST_F(Cli, ContactsThatOverlapDeeplyAreWarnedOfAndTheDeepestIsInTheSummary) {
  // MODEL.md's springs (4e5 N/m) in this mill: no warning, a few per cent of a radius.
  const Outcome sound = run_config(base_config, tiny_run);
  ASSERT_EQ(sound.status, 0) << sound.err;
  EXPECT_EQ(sound.err.find("overlapped"), std::string::npos) << sound.err;
  const std::string summary = read_all(work_ / "out" / "summary.json");
  const std::smatch found = [&] {
    std::smatch m;
    std::regex_search(summary, m, std::regex("\"largest_overlap_fraction\" : ([0-9.e+-]+)"));
    return m;
  }();
  ASSERT_EQ(found.size(), 2u) << summary;
  const double sound_fraction = std::stod(found[1].str());
  EXPECT_GT(sound_fraction, 0.0);
  EXPECT_LT(sound_fraction, 0.5);
  // Springs of 100 N/m: a disc of 0.52 kg sinks 5 cm under its own weight, twice its radius
  // (seen: 5.1 radii), and through the shell.
  fs::remove_all(work_ / "out");
  std::string soft_springs;
  for (const char* contact : {"ball_ball", "ball_wall"}) {
    for (const char* spring : {"normal_stiffness", "tangential_stiffness"}) {
      soft_springs += fmt::format(" --set materials.{}.{}=100", contact, spring);
    }
  }
  const Outcome soft = run_config(base_config, tiny_run + soft_springs);
  ASSERT_EQ(soft.status, 0) << soft.err;
  EXPECT_NE(soft.err.find("millsim: warning: results in out/: contacts overlapped by up to "),
            std::string::npos)
      << soft.err;
  EXPECT_NE(soft.err.find("of the smaller ball's radius (more than 50 %): the springs are soft "
                          "for these balls and this mill (materials.*.normal_stiffness), balls "
                          "sink into each other and may pass through one another or a wall"),
            std::string::npos)
      << soft.err;
}

TEST_F(Cli, VersionPrintsTheVersionAndTheSourceRevision) {
  const Outcome o = millsim("--version");
  EXPECT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(o.out, "millsim " + millsim::version_text() + "\n");
  // The revision is cmake/version.cmake's `git describe --always --dirty --abbrev=12` of the
  // source directory at build time: at least 12 hex digits of the commit (more where 12 are
  // ambiguous), after "TAG-N-g" when a tag is reachable, and "-dirty" if the tree had changes;
  // "unknown" when the source is not a git checkout (or git is missing), as README.md says.
  const std::regex from_git(R"(millsim 0\.1\.0 \((.+-g)?([0-9a-f]{12,})(-dirty)?\)\n)");
  const std::regex outside_git(R"(millsim 0\.1\.0 \(unknown\)\n)");
  const fs::path source(MILLSIM_SOURCE_DIR);
  // The test asks git the same question version.cmake asks: is there a checkout it can read?
  const bool checkout =
      fs::exists(source / ".git") &&
      std::system(
          ("git -C " + quoted(source.string()) + " rev-parse HEAD >/dev/null 2>&1").c_str()) == 0;
  std::smatch match;
  if (checkout) {
    ASSERT_TRUE(std::regex_match(o.out, match, from_git)) << o.out;
    // And the digits name a commit of this checkout, not any 12 hex digits.
    EXPECT_EQ(std::system(("git -C " + quoted(source.string()) + " cat-file -e " + match[2].str() +
                           "^{commit} 2>/dev/null")
                              .c_str()),
              0)
        << match[2] << " is not a commit of " << source;
  } else {
    EXPECT_TRUE(std::regex_match(o.out, outside_git) || std::regex_match(o.out, from_git)) << o.out;
  }
}

TEST_F(Cli, RefusesATimeStepAboveTheStabilityLimitAndGivesTheLimit) {
  // The limit of docs/model.md ("Time step"), each mode's 2 / (ω (sqrt(1 + 4 ζ²) + 2 ζ)), for
  // base_config: 2D discs of 0.0508 m and 7800 kg/m³, weighed as spheres, m = 4/3 π 0.0254³ ×
  // 7800 = 0.53540739 kg; default materials k_n = 4e5 N/m, k_s = 2/3 k_n = 266 667 N/m and
  // e = 0.6 (ζ = 0.16049305) for both ball–ball and ball–wall. Discs (I = m r²/2) add
  // 1/m + 2/m each to 1/m_t, and the tangential mode's ratio is ζ sqrt(m*/m_t) = ζ √3:
  //   disc–disc: m* = m/2, ω_n = sqrt(4e5/0.26770) = 1222.4 s⁻¹, limit 2/(1222.4 · 1.37124)
  //              = 1.1932e-3 s; m_t = m/6, ω_t = sqrt(266 667 × 6/0.53540739) = 1728.69 s⁻¹,
  //              limit 2/(1728.69 · 1.70012) = 6.80506e-4 s;
  //   disc–wall: m* = m and m_t = m/3, ω √2 times lower: limits √2 times longer.
  // The limit, 6.8050636e-4 s, printed in the fewest digits from six that do not read as
  // above it: 0.000680506.
  const std::string limit = "0.000680506";
  const std::string text = with(base_config, "time_step", "time_step = 0.01");
  const Outcome o = run_config(text, tiny_run);
  expect_refused(o, {at_line(text, "time_step"), "simulation.time_step", "0.01 s is unstable",
                     "(the stability limit is " + limit + " s;",
                     "allowed: \"auto\" or a number of seconds below " + limit + "\n"});
  // The same from the command line.
  expect_refused(run_config(base_config, "--set simulation.time_step=0.01"),
                 {"command line (--set simulation.time_step=0.01)", "simulation.time_step",
                  "(the stability limit is " + limit + " s;",
                  "allowed: \"auto\" or a number of seconds below " + limit + "\n"});
}

TEST_F(Cli, RefusesATomlSyntaxErrorWithFileAndLine) {
  const std::string text = with(base_config, "length", "length = 0.15 0.2");
  expect_refused(run_config(text), {at_line(text, "length"), "not valid TOML", "allowed: TOML"});
}

TEST_F(Cli, RefusesAnUnknownKey) {
  const std::string text = with(base_config, "length", "length = 0.15\ncolour = \"red\"");
  expect_refused(run_config(text), {at_line(text, "colour"), "mill.colour: unknown key",
                                    "allowed in [mill]: diameter, length, speed"});
}

TEST_F(Cli, RefusesAnUnknownTable) {
  const std::string text = with(base_config, "[output]", "[outptu]");
  expect_refused(run_config(text), {at_line(text, "[outptu]"), "outptu: unknown table",
                                    "did you mean output?", "allowed at the top level"});
}

TEST_F(Cli, RefusesAMisspeltKeyInANestedTable) {
  const std::string text = with(base_config, "height", "hieght = 0.04");
  expect_refused(run_config(text), {at_line(text, "hieght"), "mill.lifters.hieght: unknown key",
                                    "did you mean height?", "count, height, width"});
}

TEST_F(Cli, RefusesAWrongType) {
  const std::string text = with(base_config, "diameter", "diameter = \"0.9\"");
  expect_refused(run_config(text), {at_line(text, "diameter"), "mill.diameter",
                                    "\"0.9\" is a string", "allowed: a number of metres > 0"});
}

TEST_F(Cli, RefusesAMissingRequiredKey) {
  const std::string text = with(base_config, "length", "");
  expect_refused(run_config(text), {at_line(text, "[mill]"), "mill.length", "missing required key",
                                    "allowed: a number of metres"});
}

TEST_F(Cli, RefusesANegativeDiameter) {
  const std::string text = with(base_config, "diameter", "diameter = -0.9");
  expect_refused(run_config(text), {at_line(text, "diameter"), "mill.diameter",
                                    "-0.9 is not allowed", "allowed: a number of metres > 0"});
}

TEST_F(Cli, RefusesAFillingOfOneOrMore) {
  for (const char* filling : {"filling = 1", "filling = 1.2"}) {
    const std::string text = with(base_config, "filling", filling);
    expect_refused(run_config(text), {at_line(text, "filling"), "charge.filling", "is not allowed",
                                      "allowed: a fraction", "< 1"});
  }
}

TEST_F(Cli, RefusesLiftersThatOverlap) {
  const std::string text = with(base_config, "width", "width = 0.34");
  expect_refused(run_config(text), {at_line(text, "width"), "mill.lifters.width",
                                    "0.34 is not allowed", "inner corners", "would meet"});
  // The limit, where neighbours' inner corners meet, 2 (0.45 − 0.04) tan(π/8) =
  // 0.33965512114593793 m, in six digits (below it).
  const std::string past_limit = with(base_config, "width", "width = 0.339656");
  expect_refused(run_config(past_limit), {"0.339656 is not allowed", "> 0 and < 0.339655 ("});
}

TEST_F(Cli, RefusesLiftersThatFillTheMill) {
  const std::string text = with(base_config, "height", "height = 0.5");
  expect_refused(run_config(text), {at_line(text, "height"), "mill.lifters.height",
                                    "0.5 is not allowed", "< 0.45", "fill the mill"});
}

TEST_F(Cli, RefusesBothSpeeds) {
  const std::string text = with(base_config, "speed", "speed = 0.5\nspeed_rpm = 20");
  expect_refused(run_config(text), {at_line(text, "speed_rpm"), "mill.speed_rpm",
                                    "given as well as mill.speed", "not both"});
}

TEST_F(Cli, RefusesNoSpeed) {
  const std::string text = with(base_config, "speed", "");
  expect_refused(run_config(text), {at_line(text, "[mill]"), "mill.speed", "missing required key",
                                    "allowed: either mill.speed"});
}

TEST_F(Cli, RefusesMassFractionsThatDoNotSumToOne) {
  const std::string text = with(base_config, "ball_diameter",
                                "sizes = [{ diameter = 0.05, mass_fraction = 0.7 },\n"
                                "         { diameter = 0.04, mass_fraction = 0.4 }]");
  expect_refused(run_config(text), {at_line(text, "sizes"), "charge.sizes", "sum to 1.1",
                                    "allowed: mass fractions that sum to 1"});
}

TEST_F(Cli, RefusesASlabTooShortForItsBalls) {
  const std::string text =
      with(with(base_config, "time_step", "dimension = 3\ntime_step = \"auto\""), "speed",
           "speed = 0.5\nperiodic = true\nslab_length = 0.1");
  expect_refused(run_config(text), {at_line(text, "slab_length"), "mill.slab_length", "too short",
                                    "at least three largest ball diameters"});
  // In a mill 0.15 m long no slab of 5.08 cm balls fits (three diameters are 0.1524 m): the
  // message says so rather than allow a range with nothing in it.
  const std::string none = with(text, "slab_length = 0.1", "slab_length = 0.15");
  expect_refused(run_config(none),
                 {"0.15 m is too short for balls of 0.0508 m",
                  "three largest ball diameters, "
                  "0.1524",
                  "at most mill.length (0.15 m, shorter than that: no slab of these "
                  "balls fits this mill; use smaller balls, a longer mill.length or a whole "
                  "mill, mill.periodic = false)"});
}

TEST_F(Cli, RefusesLiftersSoCloseThatABallCouldTouchOneBeyondTheNeighbours) {
  // The contact search tests the nearest lifter and its two neighbours. 70 lifters 0.1 m high
  // and 0.02 m wide in the 0.9 m mill: their inner corners are 0.3501 m from the axis, 0.02856
  // rad off each lifter's middle, and a ball may be at most 2 (0.3501) sin(3π/70 − 0.02856) =
  // 0.07414 m wide (widest_particle_for_lifters). Balls of 8 cm: refused.
  const std::string dense =
      with(with(with(with(base_config, "count", "count = 70"), "height", "height = 0.1"), "width",
                "width = 0.02"),
           "ball_diameter", "ball_diameter = 0.08");
  expect_refused(run_config(dense),
                 {at_line(dense, "count"), "mill.lifters.count",
                  "a ball wider than 0.0741442 m can touch a lifter beyond the two neighbours",
                  "the largest ball is 0.08 m",
                  "allowed: fewer, lower or narrower lifters, or smaller balls"});
  // Balls of 7 cm: accepted.
  const std::string smaller = with(dense, "ball_diameter", "ball_diameter = 0.07");
  const Outcome accepted = run_config(smaller, tiny_run);
  EXPECT_EQ(accepted.status, 0) << accepted.err;
}

TEST_F(Cli, InfoOfAConicalMillPrintsItsCones) {
  // examples/conical-mill-3d.toml: 20°, 0.1 m cones on a 0.9 m mill, r_t = 0.45 − 0.1 / tan 20°.
  const Outcome info =
      millsim(std::string("info ") + MILLSIM_SOURCE_DIR + "/examples/conical-mill-3d.toml");
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_NE(info.out.find("conical ends: 0.1 m long each at 20 degrees, trunnion radius 0.1753 m"),
            std::string::npos)
      << info.out;
  EXPECT_NE(info.out.find("particles             385"), std::string::npos) << info.out;
}

TEST_F(Cli, InfoTakesEveryShippedConfig) {
  // Every config a user is pointed to (examples/, bench/) is read and checked as `run` would
  // read it, so that none drifts from the config format unnoticed; the mills' charges are
  // placed (up to 200 000 particles) and the scenes' time steps worked out.
  std::vector<std::filesystem::path> configs;
  for (const char* folder : {"examples", "bench"}) {
    for (const auto& entry : std::filesystem::recursive_directory_iterator(
             std::filesystem::path(MILLSIM_SOURCE_DIR) / folder)) {
      if (entry.is_regular_file() && entry.path().extension() == ".toml") {
        configs.push_back(entry.path());
      }
    }
  }
  std::sort(configs.begin(), configs.end());
  ASSERT_GE(configs.size(), 20U);  // 26 when written: the folders were found and walked
  for (const auto& config : configs) {
    SCOPED_TRACE(config.string());
    const Outcome info = millsim("info " + quoted(config.string()));
    EXPECT_EQ(info.status, 0) << info.err;
    EXPECT_EQ(info.err, "");
    EXPECT_NE(info.out.find("config                " + config.string()), std::string::npos)
        << info.out;
    EXPECT_NE(info.out.find("time step"), std::string::npos) << info.out;
  }
}

TEST_F(Cli, RefusesAFillingTheMillCannotHoldBothInRunAndInInfo) {
  // J = 0.68 plans 171 discs (2D void fraction 0.2), more than fit between the lifters (155
  // do), though below what random placement reaches in an open plane (past that, the plan
  // refuses it: tests/unit/test_mill_plan.cpp): the placement gives up, and `info`, which
  // places the charge too, says so before printing.
  const std::string text = with(base_config, "filling", "filling = 0.68");
  const std::vector<std::string_view> parts = {"mill.toml", "charge.filling", "could not place",
                                               "lower the filling or use smaller balls"};
  const Outcome run = run_config(text);
  expect_refused(run, {parts[0], parts[1], parts[2], parts[3]});
  const Outcome info = millsim("info mill.toml");
  EXPECT_EQ(info.status, 2) << info.err;
  EXPECT_EQ(info.out, "");
  EXPECT_EQ(info.err, run.err);
  // Without -q, run says nothing on stdout (no "running ...") for a charge it refuses.
  const Outcome loud = millsim("run mill.toml -o out");
  EXPECT_EQ(loud.status, 2) << loud.err;
  EXPECT_EQ(loud.out, "");
  EXPECT_EQ(loud.err, run.err);
  // A sweep places every point's charge before running any: refused, nothing written.
  const Outcome sweep = millsim(std::string("sweep mill.toml -q -o runs --vary "
                                            "charge.filling=0.3,0.68 ") +
                                tiny_run);
  EXPECT_EQ(sweep.status, 2) << sweep.err;
  EXPECT_NE(sweep.err.find("sweep point 1 (charge.filling=0.68)"), std::string::npos) << sweep.err;
  EXPECT_NE(sweep.err.find("could not place"), std::string::npos) << sweep.err;
  EXPECT_FALSE(fs::exists(work_ / "runs"));

  // The same mill at J = 0.3 (75 discs) is placed by info, which says so.
  write_config(base_config);
  const Outcome fits = millsim("info mill.toml");
  ASSERT_EQ(fits.status, 0) << fits.err;
  EXPECT_NE(fits.out.find("particles             75, placed without overlap as run places them"),
            std::string::npos)
      << fits.out;
}

TEST_F(Cli, RefusesConesOnA2DMill) {
  const std::string text = with(base_config, "speed", "speed = 0.5\ncone_angle = 15");
  expect_refused(run_config(text),
                 {at_line(text, "cone_angle"), "mill.cone_angle", "simulation.dimension = 3"});
}

TEST_F(Cli, RefusesANamedTimeStepOtherThanAuto) {
  const std::string text = with(base_config, "time_step", "time_step = \"fast\"");
  expect_refused(run_config(text), {at_line(text, "time_step"), "simulation.time_step",
                                    "\"fast\" is not allowed", "allowed: \"auto\""});
}

TEST_F(Cli, AcceptsAnIntegerForANumberAndRefusesAFractionForAnInteger) {
  write_config(with(base_config, "density", "density = 7800"));
  const Outcome ok = millsim("info mill.toml");
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(ok.out.find("density 7800 kg/m3"), std::string::npos) << ok.out;

  const std::string text = with(base_config, "count", "count = 8.5");
  expect_refused(run_config(text), {at_line(text, "count"), "mill.lifters.count",
                                    "8.5 is not a whole number", "allowed: a whole number"});
}

TEST_F(Cli, AValidOverrideChangesTheValue) {
  write_config(base_config);
  const Outcome before = millsim("info mill.toml");
  const Outcome after = millsim("info mill.toml --set mill.speed=0.6");
  ASSERT_EQ(before.status, 0) << before.err;
  ASSERT_EQ(after.status, 0) << after.err;
  EXPECT_NE(before.out.find("= 50.0% of critical"), std::string::npos) << before.out;
  EXPECT_NE(after.out.find("= 60.0% of critical"), std::string::npos) << after.out;
}

TEST_F(Cli, RefusesAnOverrideOfAnUnknownKeyNamingTheOption) {
  expect_refused(run_config(base_config, "--set mill.lifters.hieght=0.04"),
                 {"command line (--set mill.lifters.hieght=0.04)", "mill.lifters.hieght",
                  "unknown key", "did you mean height?", "allowed in [mill.lifters]"});
}

TEST_F(Cli, RefusesAnOverrideWithABadValueNamingTheOption) {
  expect_refused(run_config(base_config, "--set charge.filling=1"),
                 {"command line (--set charge.filling=1)", "charge.filling", "1 is not allowed",
                  "allowed: a fraction"});
}

TEST_F(Cli, RefusesAMalformedOverride) {
  expect_refused(run_config(base_config, "--set mill.speed"),
                 {"command line (--set mill.speed)", "no '='", "allowed: KEY=VALUE"});
}

TEST_F(Cli, RefusesAMissingConfigFile) {
  const Outcome o = millsim("run no-such-mill.toml -o out -q");
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_TRUE(o.err.starts_with("millsim: error: no-such-mill.toml: no such config file")) << o.err;
  EXPECT_NE(o.err.find("allowed: the path of a mill config file"), std::string::npos) << o.err;
  EXPECT_TRUE(fs::is_empty(work_));
}

TEST_F(Cli, RefusesAConfigThatIsNotARegularFileOrIsFarTooLarge) {
  // A FIFO with no writer would block the read for ever, /dev/zero would fill the memory.
  ASSERT_EQ(::mkfifo((work_ / "pipe.toml").c_str(), 0600), 0) << std::strerror(errno);
  const Outcome pipe = millsim("info pipe.toml");
  EXPECT_EQ(pipe.status, 2) << pipe.err;
  EXPECT_NE(pipe.err.find("pipe.toml: is not a regular file (a device, pipe or socket)"),
            std::string::npos)
      << pipe.err;
  const Outcome zero = millsim("run /dev/zero -o out -q");
  EXPECT_EQ(zero.status, 2) << zero.err;
  EXPECT_NE(zero.err.find("/dev/zero: is not a regular file"), std::string::npos) << zero.err;
  // A sparse file of 65 MiB: a size no config has.
  std::ofstream(work_ / "huge.toml").close();
  fs::resize_file(work_ / "huge.toml", 65u << 20);
  const Outcome huge = millsim("info huge.toml");
  EXPECT_EQ(huge.status, 2) << huge.err;
  EXPECT_NE(huge.err.find("huge.toml: is 68157440 bytes long; allowed:"), std::string::npos)
      << huge.err;
  EXPECT_NE(huge.err.find("at most 64 MiB"), std::string::npos) << huge.err;
  EXPECT_FALSE(fs::exists(work_ / "out"));
}

TEST_F(Cli, ASweepRefusesAKeyBothVariedAndSet) {
  write_config(base_config);
  const Outcome o = millsim(
      "sweep mill.toml -q -o runs --vary mill.speed=0.3,0.4 --set "
      "mill.speed=0.5");
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_EQ(o.err,
            "millsim: error: command line (--vary mill.speed=...): mill.speed is also given as "
            "--set mill.speed=0.5; allowed: a key either varied or set\n");
  EXPECT_FALSE(fs::exists(work_ / "runs"));
}

TEST_F(Cli, ACoarseTimeStepAndADoubtfulResultAreRunWithWarnings) {
  // The base config's shortest contact is 2.6 ms: 0.6 ms is below the stability limit (0.68 ms,
  // RefusesATimeStepAboveTheStabilityLimit...) but under 5 steps a contact, and the energy
  // balance of such a run does not close (seen: off by 105 %).
  write_config(base_config);
  const Outcome o =
      millsim(std::string("run mill.toml -q -o out --set simulation.time_step=6e-4 ") + tiny_run);
  EXPECT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.err.find("millsim: warning: command line (--set simulation.time_step=6e-4): "
                       "simulation.time_step: 0.0006 s resolves the shortest contact"),
            std::string::npos)
      << o.err;
  EXPECT_NE(o.err.find("millsim: warning: results in out/: the energy balance is off by"),
            std::string::npos)
      << o.err;
  EXPECT_TRUE(fs::exists(work_ / "out" / "summary.json"));
}

TEST_F(Cli, RefusesAnEmptyConfigPathOrOutputDirectory) {
  // An empty argument is a slip (an unset shell variable), not a request for the defaults.
  const Outcome config = millsim("run '' -o out -q");
  EXPECT_EQ(config.status, 2) << config.err;
  EXPECT_NE(config.err.find("config: an empty path"), std::string::npos) << config.err;
  write_config(base_config);
  const Outcome out = millsim(std::string("run mill.toml -q --out '' ") + tiny_run);
  EXPECT_EQ(out.status, 2) << out.err;
  EXPECT_NE(out.err.find("--out: an empty path"), std::string::npos) << out.err;
  EXPECT_FALSE(fs::exists(work_ / "out"));
}

TEST_F(Cli, AnOutputDirectoryThatCannotBeMadeIsBadInputNamingTheOption) {
  std::ofstream(work_ / "afile") << "not a directory\n";
  write_config(base_config);
  const Outcome o = millsim(std::string("run mill.toml -q --out afile/sub ") + tiny_run);
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_TRUE(
      o.err.starts_with("millsim: error: command line (--out afile/sub): "
                        "output.directory: cannot make \"afile/sub\""))
      << o.err;
}

TEST_F(Cli, AnOutputDirectoryWhoseNameTheSystemRefusesIsBadInputNamingTheOption) {
  // A name of 300 letters is longer than any file system takes (255 bytes): the lookup's error
  // was thrown out of the planning as a failed run (exit 1, no key).
  write_config(base_config);
  const std::string name(300, 'a');
  const Outcome o = millsim("run mill.toml -q --out " + name + " " + tiny_run);
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_TRUE(o.err.starts_with("millsim: error: command line (--out " + name +
                                "): output.directory: cannot use \"" + name + "\" ("))
      << o.err;
  EXPECT_NE(o.err.find("allowed: a directory that can be created and written"), std::string::npos)
      << o.err;
}

TEST_F(Cli, ARunRemovesTheResultsAnEarlierRunLeftInItsDirectory) {
  // A run stopped half-way must not leave the last run's power.csv beside its own files.
  fs::create_directories(work_ / "out");
  for (const char* name : {"power.csv", "power_timeseries.csv", "spectrum.csv",
                           "charge_profile.csv", "summary.json", "notes.txt"}) {
    std::ofstream(work_ / "out" / name) << "stale\n";
  }
  write_config(base_config);
  // Refused at planning (1.7e10 steps of 1 ns are too many): nothing is touched.
  EXPECT_EQ(millsim("run mill.toml -o out -q --set simulation.time_step=1e-9").status, 2);
  EXPECT_EQ(read_all(work_ / "out" / "power.csv"), "stale\n");
  // A run that starts removes the old results first; a file of the user's stays.
  const Outcome o = millsim(std::string("run mill.toml -o out -q ") + tiny_run);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(read_all(work_ / "out" / "power.csv"), "stale\n");
  EXPECT_NE(read_all(work_ / "out" / "charge_profile.csv"), "stale\n");
  EXPECT_EQ(read_all(work_ / "out" / "notes.txt"), "stale\n");

  // A killed run's .partial file and snapshots go too (this run writes no snapshots), and the
  // directory they were moved aside to before removal is gone; so does one that a run (or
  // sweep) stopped while it cleared had left.
  std::ofstream(work_ / "out" / "impacts.csv.partial") << "half\n";
  fs::create_directories(work_ / "out" / ".millsim-earlier-results-a1B2c3" / "snapshots");
  std::ofstream(work_ / "out" / ".millsim-earlier-results-a1B2c3" / "summary.json") << "old\n";
  fs::create_directories(work_ / "out" / "snapshots" / "deep");
  std::ofstream(work_ / "out" / "snapshots" / "deep" / "snapshot_000000.csv") << "stale\n";
  ASSERT_EQ(millsim(std::string("run mill.toml -o out -q ") + tiny_run).status, 0);
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(work_ / "out")) {
    left.push_back(entry.path().filename().string());
  }
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left,
            (std::vector<std::string>{"charge_profile.csv", "impacts.csv", "notes.txt", "power.csv",
                                      "power_timeseries.csv", "spectrum.csv", "summary.json"}));
}

TEST_F(Cli, AResultsPartialNameTakenByADirectoryIsRefusedBeforeTheRun) {
  write_config(base_config);
  // Results are written as NAME.partial and renamed. A directory of the user's (not empty)
  // named spectrum.csv.partial would fail that write at the end of the run, after the other
  // results were written: refused before the run starts, and left as it is.
  // An earlier run's results in the directory are left whole too.
  ASSERT_EQ(millsim(std::string("run mill.toml -o taken -q ") + tiny_run).status, 0);
  const std::string earlier = read_all(work_ / "taken" / "summary.json");
  fs::create_directories(work_ / "taken" / "spectrum.csv.partial" / "mine");
  const Outcome taken = millsim(std::string("run mill.toml -o taken -q ") + tiny_run);
  EXPECT_EQ(taken.status, 2) << taken.err;
  EXPECT_NE(taken.err.find("command line (--out taken): output.directory: \"taken\" holds a "
                           "directory spectrum.csv.partial where the run writes a result (not "
                           "empty); allowed: an output directory where no result's name is taken "
                           "(remove or rename taken/spectrum.csv.partial, or choose another "
                           "directory)"),
            std::string::npos)
      << taken.err;
  EXPECT_EQ(read_all(work_ / "taken" / "summary.json"), earlier);
  for (const char* name :
       {"power.csv", "power_timeseries.csv", "spectrum.csv", "charge_profile.csv", "impacts.csv"}) {
    EXPECT_TRUE(fs::exists(work_ / "taken" / name)) << name;
  }
  EXPECT_TRUE(fs::exists(work_ / "taken" / "spectrum.csv.partial" / "mine"));
}

/// A relative path near the system's limit: `directories` names of 200 letters a, then one of
/// `last` letters b.
std::string long_path(int directories, std::size_t last) {
  std::string path(200, 'a');
  for (int k = 1; k < directories; ++k) path += "/" + std::string(200, 'a');
  return path + "/" + std::string(last, 'b');
}

TEST_F(Cli, AResultThatCannotBeMovedAsideRefusesTheRunAndPutsBackThoseThatWere) {
  // The earlier results are renamed into out/.millsim-earlier-results-XXXXXX/ before they are
  // removed, and so is anything in out/ whose name starts as that directory's does (what a
  // clearing that was stopped left). A path of 4000 characters has room for everything a run
  // writes or moves aside (AnOutputPathWithNoRoom...), but not for a file of 80 characters of
  // that kind moved aside (4113, beyond the system's 4095): summary.json and power.csv are
  // moved first, then that rename fails, and they must be put back.
  write_config(base_config);
  const std::string out = long_path(19, 181);
  ASSERT_EQ(out.size(), 4000U);
  ASSERT_EQ(millsim("run mill.toml -q -o " + out + " " + tiny_run).status, 0);
  const std::string summary = read_all(work_ / out / "summary.json");
  const std::string power = read_all(work_ / out / "power.csv");
  ASSERT_FALSE(summary.empty());
  ASSERT_FALSE(power.empty());
  const std::string left = ".millsim-earlier-results-" + std::string(55, 'c');
  ASSERT_EQ(left.size(), 80U);
  // (Made from the working directory: with it, the path is beyond the system's limit.)
  ASSERT_EQ(std::system(("cd " + quoted(work_.string()) + " && : > " + out + "/" + left).c_str()),
            0);
  const Outcome again = millsim("run mill.toml -q -o " + out + " " + tiny_run);
  EXPECT_EQ(again.status, 2) << again.err;
  EXPECT_NE(again.err.find("cannot clear earlier results from"), std::string::npos) << again.err;
  EXPECT_NE(again.err.find("(" + left + ": File name too long)"), std::string::npos) << again.err;
  EXPECT_EQ(read_all(work_ / out / "summary.json"), summary);
  EXPECT_EQ(read_all(work_ / out / "power.csv"), power);
  for (const auto& entry : fs::directory_iterator(work_ / out)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with(".millsim")) {
      EXPECT_EQ(name, left) << "left behind: " << name;
    }
  }
}

TEST_F(Cli, AnOutputPathWithNoRoomForWhatTheRunWritesOrMovesAsideIsRefusedBeforeTheRun) {
  // The longest path a run makes is an earlier run's snapshot moved aside to be removed,
  // out/.millsim-earlier-results-XXXXXX/snapshots/snapshot_0000000000.csv.partial: 74 more
  // characters. 4022 characters are refused, with or without snapshots (4096, beyond the
  // system's 4095). Such a run once settled its charge and then failed at its first snapshot
  // (exit 1); and a directory of 4043 to 4063 characters could be run into once but not again.
  write_config(base_config);
  const std::string short_run =
      " --set simulation.revolutions=1 --set simulation.measure_revolutions=1 "
      "--set simulation.settle_time=0.01 --set output.snapshot_interval=";
  const std::string too_long = long_path(19, 203);
  ASSERT_EQ(too_long.size(), 4022U);
  for (const std::string interval : {"0.05", "0"}) {
    const Outcome o = millsim(
        std::string("run mill.toml -q -o ").append(too_long).append(short_run).append(interval));
    EXPECT_EQ(o.status, 2) << o.err;
    EXPECT_NE(o.err.find("): output.directory: a path of 4022 characters leaves no room for the "
                         "files the run writes in it, or moves aside there from an earlier run "
                         "(the longest, .millsim-earlier-results-XXXXXX/snapshots/"
                         "snapshot_0000000000.csv.partial, would be a path of 4096); allowed: a "
                         "directory path of at most 4021 characters (the system takes paths of "
                         "at most 4095)"),
              std::string::npos)
        << o.err;
    EXPECT_FALSE(fs::exists(work_ / std::string(200, 'a'))) << "nothing is made";
  }
  // At the limit, a run with snapshots, and again (its results and snapshots moved aside and
  // removed), and again without snapshots.
  // (work_ / out is beyond the system's limit: the test reads it through the program's output.)
  const std::string out = long_path(19, 202);
  ASSERT_EQ(out.size(), 4021U);
  for (const std::string interval : {"0.05", "0.05", "0"}) {
    const Outcome o =
        millsim(std::string("run mill.toml -q -o ").append(out).append(short_run).append(interval));
    EXPECT_EQ(o.status, 0) << o.err;
    EXPECT_TRUE(o.out.starts_with("power ")) << o.out;
    // (Its one measured revolution takes in the spin-up, which is warned of.)
    EXPECT_EQ(o.err.find("could not all be removed"), std::string::npos) << o.err;
    EXPECT_EQ(o.err.find("error"), std::string::npos) << o.err;
  }
}

TEST_F(Cli, ASweepRefusesAPointDirectoryWithNoRoomForItsSnapshotsBeforeAnyPointRuns) {
  // A root of 4039 characters: each point's directory (root/NAME) has room for its results but
  // not for its snapshots, nor for an earlier run's moved aside. The sweep once started, wrote
  // sweep.csv and failed every point (exit 1); it is now refused (exit 2) before anything is
  // made.
  write_config(base_config);
  const std::string out = long_path(20, 19);
  ASSERT_EQ(out.size(), 4039U);
  const Outcome o = millsim("sweep mill.toml -q -o " + out +
                            " --vary mill.speed=0.5,0.6 --set simulation.revolutions=1 --set "
                            "simulation.measure_revolutions=1 --set simulation.settle_time=0.01");
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_NE(o.err.find("command line (--out " + out + "): output.directory: a path of "),
            std::string::npos)
      << o.err;
  EXPECT_NE(o.err.find("leaves no room for the files the run writes in it, or moves aside there "
                       "from an earlier run (the longest, .millsim-earlier-results-XXXXXX/"
                       "snapshots/snapshot_0000000000.csv.partial, would be a path of "),
            std::string::npos)
      << o.err;
  EXPECT_FALSE(fs::exists(work_ / std::string(200, 'a'))) << "nothing is made";
}

TEST_F(Cli, AnUnknownCommandIsNamed) {
  const Outcome o = millsim("frobnicate mill.toml");
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_NE(o.err.find("\"frobnicate\" is not a command; allowed: run, info, validate or sweep"),
            std::string::npos)
      << o.err;
}

TEST_F(Cli, NoCommandOrOptionsBeforeItAreRefusedListingTheCommands) {
  for (const std::string args : {"", "-q"}) {
    const Outcome o = millsim(args);
    EXPECT_EQ(o.status, 2) << args << ": " << o.err;
    EXPECT_TRUE(o.err.starts_with("millsim: error: command line: no command")) << o.err;
    EXPECT_NE(o.err.find("allowed: run, info, validate or sweep"), std::string::npos) << o.err;
  }
  EXPECT_NE(millsim("-q").err.find("no command before \"-q\""), std::string::npos);
}

TEST_F(Cli, RefusesAThreadCountThatIsNoWholeNumberFromOneTo1024) {
  for (const std::string threads : {"abc", "0", "4x", "2.5", "1025", "-3"}) {
    const Outcome o = run_config(base_config, "-j " + threads);
    expect_refused(o, {"--threads: \"" + threads +
                       "\" is not allowed; allowed: a whole number of threads from 1 to 1024"});
  }
}

/// An environment variable set to a value while it lives, then as it was.
class EnvironmentVariable {
 public:
  EnvironmentVariable(const char* name, const std::string& value) : name_(name) {
    if (const char* was = std::getenv(name)) was_ = was;
    ::setenv(name, value.c_str(), 1);
  }
  ~EnvironmentVariable() {
    if (was_) {
      ::setenv(name_, was_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }
  EnvironmentVariable(const EnvironmentVariable&) = delete;
  EnvironmentVariable& operator=(const EnvironmentVariable&) = delete;

 private:
  const char* name_;
  std::optional<std::string> was_;
};

TEST_F(Cli, RefusesAnOmpNumThreadsTheRuntimeCannotReadOrThatExceeds1024) {
  // libomp read "abc" with a warning and then, one run in three, hung or aborted. The message is
  // millsim's last line: GCC's libgomp (the debug build's runtime) warns of a value it cannot
  // read as it loads, before millsim starts, and that line may come first.
  const auto expect_environment_refused = [&](const Outcome& o, const std::string& part) {
    EXPECT_EQ(o.status, 2) << o.err;
    const std::size_t last_line = o.err.rfind('\n', o.err.size() >= 2 ? o.err.size() - 2 : 0);
    const std::string last = o.err.substr(last_line == std::string::npos ? 0 : last_line + 1);
    EXPECT_TRUE(last.starts_with("millsim: error: environment: OMP_NUM_THREADS=")) << o.err;
    EXPECT_NE(last.find(part), std::string::npos) << "lacks \"" << part << "\":\n" << o.err;
    EXPECT_FALSE(fs::exists(work_ / "out")) << "the output directory was created";
  };
  for (const std::string value :
       {"abc", "", "0", "2.5", "4x", " 2", "2,", ",2", "-3", "2,abc", "99999999999999999999999"}) {
    const EnvironmentVariable set("OMP_NUM_THREADS", value);
    expect_environment_refused(
        run_config(base_config, tiny_run),
        "OMP_NUM_THREADS=\"" + value +
            "\" is not allowed; allowed: a whole number of threads from 1 to 1024 (or such "
            "numbers separated by commas, one per level of nesting), or OMP_NUM_THREADS unset\n");
  }
  {
    // -j does not help a value the runtime cannot read: it reads it all the same.
    const EnvironmentVariable set("OMP_NUM_THREADS", "abc");
    expect_environment_refused(run_config(base_config, std::string("-j 1 ") + tiny_run),
                               "OMP_NUM_THREADS=\"abc\" is not allowed");
  }
  for (const std::string value : {"1025", "2,2000"}) {
    const EnvironmentVariable set("OMP_NUM_THREADS", value);
    expect_environment_refused(run_config(base_config, tiny_run),
                               "or -j/--threads N given in its place\n");
    // -j's count replaces it.
    const Outcome o = run_config(base_config, std::string("-j 1 ") + tiny_run);
    EXPECT_EQ(o.status, 0) << value << ": " << o.err;
    fs::remove_all(work_ / "out");
  }
  for (const std::string value : {"1", "2,1", "1024"}) {
    const EnvironmentVariable set("OMP_NUM_THREADS", value);
    const Outcome o = run_config(base_config, tiny_run);
    EXPECT_EQ(o.status, 0) << value << ": " << o.err;
    fs::remove_all(work_ / "out");
  }
  // Sweep and validate check it too; info, which runs nothing, does not.
  const EnvironmentVariable set("OMP_NUM_THREADS", "abc");
  for (const std::string command :
       {"sweep mill.toml -o out --vary mill.speed=0.5,0.6 ", "validate . -o out "}) {
    expect_environment_refused(millsim(command + tiny_run), "OMP_NUM_THREADS=\"abc\"");
  }
  EXPECT_EQ(millsim("info mill.toml").status, 0);
}

TEST_F(Cli, SetTakesOneKeyValueSoTheConfigMayFollowIt) {
  // "Usage: millsim run [OPTIONS] [config]": a --set before the config took the config's path
  // as a second override ("--set mill.toml: no '='").
  write_config(base_config);
  const Outcome info = millsim("info --set mill.speed=0.6 mill.toml");
  EXPECT_EQ(info.status, 0) << info.err;
  EXPECT_NE(info.out.find("mill.toml"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("= 60.0% of critical"), std::string::npos) << info.out;
  const Outcome run = millsim(std::string("run -q ") + tiny_run + " mill.toml -o out");
  EXPECT_EQ(run.status, 0) << run.err;
  EXPECT_TRUE(fs::exists(work_ / "out" / "summary.json"));
  const Outcome sweep =
      millsim(std::string("sweep -q ") + tiny_run + " mill.toml --vary mill.speed=0.5 -o swept");
  EXPECT_EQ(sweep.status, 0) << sweep.err;
  EXPECT_TRUE(fs::exists(work_ / "swept" / "sweep.csv"));
}

TEST_F(Cli, OutputThatCannotBeWrittenIsAFailure) {
  // `millsim info mill.toml > info.txt` on a full disk once gave an empty file and exit 0.
  write_config(base_config);
  for (const std::string& args :
       {std::string("info mill.toml"), std::string("run mill.toml -q -o out ") + tiny_run}) {
    const std::string command = "cd " + quoted(work_.string()) + " && " + quoted(MILLSIM_BINARY) +
                                " " + args + " >/dev/full 2>" + quoted((root_ / "err").string());
    const int raw = std::system(command.c_str());
    ASSERT_TRUE(raw != -1 && WIFEXITED(raw)) << args;
    EXPECT_EQ(WEXITSTATUS(raw), 1) << args;
    EXPECT_NE(read_all(root_ / "err").find("millsim: failed: cannot write to standard output: "),
              std::string::npos)
        << args << ": " << read_all(root_ / "err");
  }
}

TEST_F(Cli, MoreThreadsThanCoresAreWarnedOf) {
  // The run is too small to share out, so 1024 threads cost nothing here; on a bed large
  // enough they would wait for each other at every step.
  write_config(base_config);
  const Outcome many = millsim(std::string("run mill.toml -q -o many -j 1024 ") + tiny_run);
  EXPECT_EQ(many.status, 0) << many.err;
  EXPECT_NE(many.err.find("millsim: warning: 1024 threads on "), std::string::npos) << many.err;
  EXPECT_NE(many.err.find("(the results are the same)"), std::string::npos) << many.err;
  const Outcome one = millsim(std::string("run mill.toml -q -o one -j 1 ") + tiny_run);
  EXPECT_EQ(one.status, 0) << one.err;
  EXPECT_EQ(one.err.find(" threads on "), std::string::npos) << one.err;
  // A refused config says only why (the warning comes as a job starts to run).
  const Outcome refused = millsim("run mill.toml -q -o refused -j 1024 --set mill.speed=7");
  EXPECT_EQ(refused.status, 2) << refused.err;
  EXPECT_EQ(refused.err.find(" threads on "), std::string::npos) << refused.err;
}

TEST_F(Cli, AnOptionBeforeTheCommandIsToldToFollowIt) {
  // "millsim -q run" once said -q was not expected and to see millsim run --help, which lists it.
  write_config(base_config);
  const Outcome o = millsim("-q run mill.toml");
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_EQ(o.err,
            "millsim: error: command line: \"-q\" comes before the command; allowed: the command "
            "first, then its options (millsim run -q ...)\n");
  EXPECT_FALSE(fs::exists(work_ / "out"));
}

TEST_F(Cli, AnOptionTheCommandDoesNotTakePointsToThatCommandsHelp) {
  const Outcome o = millsim("sweep --bogus --vary mill.speed=0.5,0.6");
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_NE(o.err.find("--bogus"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("allowed: see millsim sweep --help"), std::string::npos) << o.err;
}

TEST_F(Cli, ValidateRefusesADirectoryWithoutConfigs) {
  fs::create_directories(work_ / "empty");
  const Outcome o = millsim("validate empty -o runs -q");
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_NE(o.err.find("command line (validate empty): no *.toml configs in it; allowed: a "
                       "directory of *.toml mill configs"),
            std::string::npos)
      << o.err;
  EXPECT_FALSE(fs::exists(work_ / "runs"));
  const Outcome missing = millsim("validate nodir -o runs -q");
  EXPECT_EQ(missing.status, 2) << missing.err;
  EXPECT_NE(missing.err.find("command line (validate nodir): no such directory; allowed:"),
            std::string::npos)
      << missing.err;
}

TEST_F(Cli, AnOutputDirectoryThatTakesNoFilesIsRefusedBeforeTheRun) {
  // /proc/self exists and is a directory, but no file can be made in it, even by root (whom
  // permission bits do not stop): found before the simulation, not when the results are written.
  if (!fs::is_directory("/proc/self")) GTEST_SKIP() << "no /proc/self here";
  write_config(base_config);
  const Outcome o = millsim(std::string("run mill.toml -q --out /proc/self ") + tiny_run);
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_TRUE(
      o.err.starts_with("millsim: error: command line (--out /proc/self): "
                        "output.directory: cannot write in \"/proc/self\""))
      << o.err;
  EXPECT_NE(o.err.find("allowed: a directory that can be created and written"), std::string::npos)
      << o.err;
  // A directory the refused run would have made under it is not left behind either.
  const Outcome below = millsim(std::string("run mill.toml -q --out /proc/self/new ") + tiny_run);
  EXPECT_EQ(below.status, 2) << below.err;
  EXPECT_FALSE(fs::exists("/proc/self/new"));
  // No file of the user's is touched by the check: it writes one of its own name.
  fs::create_directories(work_ / "mine");
  std::ofstream(work_ / "mine" / ".millsim-write-check") << "mine\n";
  ASSERT_EQ(millsim(std::string("run mill.toml -q --out mine ") + tiny_run).status, 0);
  EXPECT_EQ(read_all(work_ / "mine" / ".millsim-write-check"), "mine\n");
}

TEST_F(Cli, OutOverridesTheOutputDirectoryOfTheConfigAndOfSetAsAPlainPath) {
  write_config(base_config);
  const Outcome o =
      millsim(std::string("run mill.toml -q --set output.directory=d1 --out d2 ") + tiny_run);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_TRUE(fs::exists(work_ / "d2" / "summary.json"));
  EXPECT_FALSE(fs::exists(work_ / "d1"));
  EXPECT_FALSE(fs::exists(work_ / "out"));
  // The path as typed, quotes and all (not read as a TOML string).
  const Outcome quoted_path = millsim(std::string("run mill.toml -q --out '\"q\"' ") + tiny_run);
  ASSERT_EQ(quoted_path.status, 0) << quoted_path.err;
  EXPECT_TRUE(fs::exists(work_ / "\"q\"" / "summary.json"));
  EXPECT_FALSE(fs::exists(work_ / "q"));
}

/// A validation case of the base config: its [reference] table, and an [output] table that
/// validate replaces.
std::string validation_case(std::string_view reference) {
  return std::string(base_config) + "\n[reference]\n" + std::string(reference);
}

TEST_F(Cli, ValidateRefusesWhatWouldTakeTheNameOfItsTableBeforeAnyCaseRuns) {
  fs::create_directories(work_ / "cases");
  std::ofstream(work_ / "cases" / "a.toml")
      << validation_case("case = \"a\"\nmeasured_power_kw = 0.6\n");
  // A directory where the table goes: refused, not found once every case has run.
  fs::create_directories(work_ / "runs" / "validation.csv" / "kept");
  const Outcome in_the_way = millsim(std::string("validate cases -o runs ") + tiny_run);
  EXPECT_EQ(in_the_way.status, 2) << in_the_way.err;
  EXPECT_NE(in_the_way.err.find("command line (--out runs): \"runs/validation.csv\" is a "
                                "directory, where validate writes its table; allowed:"),
            std::string::npos)
      << in_the_way.err;
  EXPECT_EQ(in_the_way.err.find("running"), std::string::npos) << in_the_way.err;
  EXPECT_FALSE(fs::exists(work_ / "runs" / "a"));
  EXPECT_TRUE(fs::exists(work_ / "runs" / "validation.csv" / "kept"));
  fs::remove_all(work_ / "runs");
  // The same for the name the table is written under before it is renamed.
  fs::create_directories(work_ / "runs" / "validation.csv.partial" / "kept");
  const Outcome partial = millsim(std::string("validate cases -o runs ") + tiny_run);
  EXPECT_EQ(partial.status, 2) << partial.err;
  EXPECT_NE(partial.err.find("\"runs/validation.csv.partial\" is a directory"), std::string::npos)
      << partial.err;
  EXPECT_FALSE(fs::exists(work_ / "runs" / "a"));
  fs::remove_all(work_ / "runs");
  // A directory of the user's under the name of a scene's result, which a case's run clears
  // too: refused before any case runs, as for a mill's result (it was once refused by the
  // case's run, after others had run, as a failed case).
  fs::create_directories(work_ / "runs" / "a" / "trajectory.csv" / "kept");
  const Outcome scene_name = millsim(std::string("validate cases -o runs ") + tiny_run);
  EXPECT_EQ(scene_name.status, 2) << scene_name.err;
  EXPECT_NE(scene_name.err.find("trajectory.csv"), std::string::npos) << scene_name.err;
  EXPECT_EQ(scene_name.err.find("running"), std::string::npos) << scene_name.err;
  EXPECT_TRUE(fs::exists(work_ / "runs" / "a" / "trajectory.csv" / "kept"));
  EXPECT_FALSE(fs::exists(work_ / "runs" / "validation.csv"));
  fs::remove_all(work_ / "runs");
  // A case whose results would go to OUT/validation.csv/.
  fs::copy_file(work_ / "cases" / "a.toml", work_ / "cases" / "validation.csv.toml");
  const Outcome named = millsim(std::string("validate cases -o runs ") + tiny_run);
  EXPECT_EQ(named.status, 2) << named.err;
  EXPECT_NE(named.err.find("cases/validation.csv.toml: a case named validation.csv would write "
                           "its results where validate writes its table"),
            std::string::npos)
      << named.err;
  EXPECT_FALSE(fs::exists(work_ / "runs"));
  fs::remove(work_ / "cases" / "validation.csv.toml");
  // Two cases of one name, which the table could not tell apart.
  fs::copy_file(work_ / "cases" / "a.toml", work_ / "cases" / "a2.toml");
  const Outcome twice = millsim(std::string("validate cases -o runs ") + tiny_run);
  EXPECT_EQ(twice.status, 2) << twice.err;
  EXPECT_NE(twice.err.find("cases/a2.toml:"), std::string::npos) << twice.err;
  EXPECT_NE(twice.err.find(": [reference]: case = \"a\" is the case of cases/a.toml too; "
                           "allowed: a name of its own for each case"),
            std::string::npos)
      << twice.err;
  EXPECT_FALSE(fs::exists(work_ / "runs"));
  fs::remove(work_ / "cases" / "a2.toml");
  // Cases whose results would go to OUT itself ("..toml") or to its parent ("...toml"), where
  // clearing a run's earlier results would remove the user's snapshots/.
  fs::create_directories(work_ / "parent" / "snapshots");
  std::ofstream(work_ / "parent" / "snapshots" / "notes.txt") << "kept\n";
  for (const std::string name : {"..toml", "...toml"}) {
    fs::copy_file(work_ / "cases" / "a.toml", work_ / "cases" / name);
    const Outcome dots = millsim(std::string("validate cases -o parent/runs ") + tiny_run);
    EXPECT_EQ(dots.status, 2) << name << ": " << dots.err;
    const std::string stem = name.substr(0, name.size() - 5);
    const std::string expected = fmt::format(
        "cases/{}: a case named \"{}\" would write its results to parent/runs/{}, "
        "outside parent/runs; allowed: a case file whose name without .toml is "
        "neither . nor ..",
        name, stem, stem);
    EXPECT_NE(dots.err.find(expected), std::string::npos) << dots.err;
    EXPECT_FALSE(fs::exists(work_ / "parent" / "runs"));
    EXPECT_EQ(read_all(work_ / "parent" / "snapshots" / "notes.txt"), "kept\n");
    fs::remove(work_ / "cases" / name);
  }
}

TEST_F(Cli, AValidationStoppedHalfWayLeavesNothingOfTheOneBefore) {
  // Three cases run one at a time (-j 1) in the order a, b, c. A first validation of all
  // three writes their results and the table; a second, whose case b runs for hours, is
  // stopped (SIGTERM: a background job ignores SIGINT) once a is done: a holds its new results, and
  // neither c nor the table the earlier validation's (c once kept them, not yet cleared by its own
  // start).
  fs::create_directories(work_ / "cases");
  const auto write_case = [&](const char* name, const char* revolutions) {
    std::ofstream(work_ / "cases" / (std::string(name) + ".toml"))
        << with(with(with(with(validation_case(
                                   fmt::format("case = \"{}\"\nmeasured_power_kw = 0.6\n", name)),
                               "revolutions", fmt::format("revolutions = {}", revolutions)),
                          "measure_revolutions", "measure_revolutions = 1\nsettle_time = 0.01"),
                     "snapshot_interval", "snapshot_interval = 0"),
                "time_step", "time_step = \"auto\"");
  };
  // Into runs/, and into a link to a directory (real/, through linked), whose case c is a link
  // too (to elsewhere/).
  fs::create_directories(work_ / "real");
  fs::create_directories(work_ / "elsewhere");
  fs::create_directory_symlink("real", work_ / "linked");
  fs::create_directory_symlink("../elsewhere", work_ / "real" / "c");
  for (const std::string out : {"runs", "linked"}) {
    for (const char* name : {"a", "b", "c"}) write_case(name, "1");
    const Outcome first = millsim("validate cases -q -j 1 -o " + out);
    ASSERT_NE(first.status, 2) << first.err;
    for (const char* name : {"a", "b", "c"}) {
      ASSERT_TRUE(fs::exists(work_ / out / name / "summary.json")) << out << "/" << name;
    }
    ASSERT_TRUE(fs::exists(work_ / out / "validation.csv")) << out;
    write_case("b", "100000");
    // Stopped once a's new summary is written and b's earlier one gone, that is once b runs
    // (at most two minutes on), whatever the build's speed.
    const std::string stopped = fmt::format(
        "cd {} && {{ {} validate cases -q -j 1 -o {} >/dev/null 2>&1 & pid=$!; n=0; "
        "while {{ [ ! -f {}/a/summary.json ] || [ -f {}/b/summary.json ]; }} && [ $n -lt 2400 ] "
        "&& kill -0 $pid 2>/dev/null; do sleep 0.05; n=$((n+1)); done; kill -TERM $pid; "
        "wait $pid; }}",
        work_.string(), MILLSIM_BINARY, out, out, out);
    const int raw = std::system(stopped.c_str());
    ASSERT_TRUE(WIFEXITED(raw)) << out << ": " << raw;
    ASSERT_EQ(WEXITSTATUS(raw), 128 + SIGTERM) << out << ": stopped by the signal";
    EXPECT_TRUE(fs::exists(work_ / out / "a" / "summary.json")) << out << ": a ran again";
    EXPECT_FALSE(fs::exists(work_ / out / "b" / "summary.json")) << out << ": b was stopped";
    EXPECT_FALSE(fs::exists(work_ / out / "validation.csv")) << out;
    for (const auto& entry : fs::directory_iterator(work_ / out / "c")) {
      ADD_FAILURE() << out << ": left in c: " << entry.path();
    }
  }
  EXPECT_TRUE(fs::is_symlink(work_ / "real" / "c")) << "the link is kept";
}

// ThreadSanitizer's runtime does not live under a file-size limit: the program it instruments
// dies of SIGBUS at once (the tsan preset's run of the test below).
#if defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define MILLSIM_UNDER_THREAD_SANITIZER 1
#endif
#endif
#if defined(__SANITIZE_THREAD__)
#define MILLSIM_UNDER_THREAD_SANITIZER 1
#endif

TEST_F(Cli, AValidationCaseThatFailsWhileRunningIsARowOfTheTable) {
#ifdef MILLSIM_UNDER_THREAD_SANITIZER
  GTEST_SKIP() << "ThreadSanitizer cannot run under ulimit -f";
#endif
  // A file-size limit (SIGXFSZ ignored, so that a write past it fails instead of ending the
  // program) that case a's results fit under (its largest file, spectrum.csv, about 12.5 kB)
  // and case b's do not (ten revolutions of power_timeseries.csv, about 57 kB). dash counts
  // ulimit -f in 512-byte blocks, bash in 1024: 19.5 or 39 kB, between the two either way.
  // Case b's failure once ended the validation with no table and case a's comparison lost.
  fs::create_directories(work_ / "cases");
  const auto revolutions = [](const std::string& text, int n) {
    return with(with(text, "revolutions", "revolutions = " + std::to_string(n)),
                "measure_revolutions", "measure_revolutions = 1");
  };
  std::ofstream(work_ / "cases" / "a.toml")
      << revolutions(validation_case("case = \"a\"\nmeasured_power_kw = 0.5\n"), 1);
  std::ofstream(work_ / "cases" / "b.toml") << revolutions(
      validation_case("case = \"b\"\nmeasured_power_kw = 0.6\npaper_power_kw = 0.62\n"), 10);
  const std::string command =
      "cd " + quoted(work_.string()) + " && trap '' XFSZ && ulimit -f 39 && " +
      quoted(MILLSIM_BINARY) +
      " validate cases -q -j 1 -o runs --set simulation.settle_time=0.01 --set "
      "output.snapshot_interval=0 >" +
      quoted((root_ / "out").string()) + " 2>" + quoted((root_ / "err").string());
  const int raw = std::system(command.c_str());
  ASSERT_TRUE(raw != -1 && WIFEXITED(raw));
  const std::string out = read_all(root_ / "out");
  const std::string err = read_all(root_ / "err");
  EXPECT_EQ(WEXITSTATUS(raw), 1) << err;
  EXPECT_NE(
      err.find("millsim: case cases/b.toml failed: runs/b/power_timeseries.csv: write failed: "),
      std::string::npos)
      << err;
  EXPECT_NE(err.find("millsim: 1 of 2 cases failed to run\n"), std::string::npos) << err;
  // Case a compared as ever; b's row says it failed.
  EXPECT_NE(out.find("\na        "), std::string::npos) << out;
  EXPECT_NE(out.find("\nb        "), std::string::npos) << out;
  EXPECT_NE(out.find("failed (see above)"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(work_ / "runs" / "a" / "summary.json"));
  EXPECT_FALSE(fs::exists(work_ / "runs" / "b" / "summary.json"));
  const std::string table = read_all(work_ / "runs" / "validation.csv");
  EXPECT_NE(table.find("\nb,0.6,0.62,,,"), std::string::npos) << table;
  EXPECT_NE(table.find(",0.15,failed\n"), std::string::npos) << table;
  EXPECT_NE(table.find("\na,0.5,,0."), std::string::npos) << table;
}

TEST_F(Cli, ValidateReadsEveryCaseBeforeRunningAnyAndShowsAMissingPaperFigureAsNa) {
  fs::create_directories(work_ / "cases");
  std::ofstream(work_ / "cases" / "a.toml")
      << validation_case("case = \"a\"\nmeasured_power_kw = 0.6\n");
  // The second case's filling is impossible: nothing runs, nothing is written.
  std::ofstream(work_ / "cases" / "b.toml")
      << with(validation_case("case = \"b\"\nmeasured_power_kw = 0.6\npaper_power_kw = 0.62\n"),
              "filling", "filling = 3");
  const Outcome bad = millsim(std::string("validate cases -o runs ") + tiny_run);
  EXPECT_EQ(bad.status, 2) << bad.err;
  EXPECT_NE(bad.err.find("b.toml:" + std::to_string(line_of(base_config, "filling")) +
                         ": charge.filling"),
            std::string::npos)
      << bad.err;
  EXPECT_EQ(bad.err.find("running"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(work_ / "runs"));
  // A filling the plan accepts but the mill cannot hold (placement fails): refused before any
  // case runs, as info refuses it.
  std::ofstream(work_ / "cases" / "b.toml") << with(
      validation_case("case = \"b\"\nmeasured_power_kw = 0.6\n"), "filling", "filling = 0.68");
  const Outcome crowded = millsim(std::string("validate cases -o runs ") + tiny_run);
  EXPECT_EQ(crowded.status, 2) << crowded.err;
  EXPECT_NE(crowded.err.find("charge.filling: could not place"), std::string::npos) << crowded.err;
  EXPECT_EQ(crowded.err.find("running"), std::string::npos) << crowded.err;
  EXPECT_FALSE(fs::exists(work_ / "runs"));
  // A case without [reference]: refused by name before any runs.
  std::ofstream(work_ / "cases" / "b.toml") << base_config;
  const Outcome unreferenced = millsim(std::string("validate cases -o runs ") + tiny_run);
  EXPECT_EQ(unreferenced.status, 2) << unreferenced.err;
  EXPECT_NE(unreferenced.err.find("b.toml: [reference]: missing; allowed:"), std::string::npos)
      << unreferenced.err;
  EXPECT_FALSE(fs::exists(work_ / "runs"));
  // Both cases good; the first has no paper figure. -q: no line per case on stderr.
  std::ofstream(work_ / "cases" / "b.toml")
      << validation_case("case = \"b\"\nmeasured_power_kw = 0.6\npaper_power_kw = 0.62\n");
  const Outcome good = millsim(std::string("validate cases -q -o runs ") + tiny_run);
  // Status 1 and one line saying how many when a case is outside its tolerance.
  std::size_t outside = 0;
  for (auto at = good.out.find("  NO ("); at != std::string::npos;
       at = good.out.find("  NO (", at + 1)) {
    ++outside;
  }
  EXPECT_EQ(good.status, outside == 0 ? 0 : 1) << good.err;
  // Before it, only warnings (a run of one revolution measures the spin-up, which they say).
  const std::string count_line = outside == 0 ? std::string()
                                              : "millsim: " + std::to_string(outside) +
                                                    " of 2 cases outside their tolerance\n";
  EXPECT_TRUE(good.err.ends_with(count_line)) << good.err;
  std::istringstream err_lines(good.err.substr(0, good.err.size() - count_line.size()));
  for (std::string line; std::getline(err_lines, line);) {
    // (and, where OMP_NUM_THREADS asks for more threads than the cores, that warning)
    EXPECT_TRUE(line.starts_with("millsim: warning: results in runs/") ||
                line.find(" threads on ") != std::string::npos)
        << line;
  }
  EXPECT_TRUE(fs::exists(work_ / "runs" / "a" / "summary.json"));
  EXPECT_TRUE(fs::exists(work_ / "runs" / "b" / "summary.json"));
  const auto row_of = [&](std::string_view name) {
    std::istringstream lines(good.out);
    std::string line;
    while (std::getline(lines, line)) {
      if (line.starts_with(name)) return line;
    }
    return std::string();
  };
  std::istringstream a(row_of("a "));
  std::string name, measured, paper, predicted, error, paper_error;
  a >> name >> measured >> paper >> predicted >> error >> paper_error;
  EXPECT_EQ(paper, "n/a") << good.out;
  EXPECT_EQ(paper_error, "n/a") << good.out;
  std::istringstream b(row_of("b "));
  b >> name >> measured >> paper >> predicted >> error >> paper_error;
  EXPECT_EQ(paper, "0.62") << good.out;
  EXPECT_EQ(paper_error, "+3.3") << good.out;
  // The same table in runs/validation.csv, with the summaries' names and full numbers: each
  // power as its summary.json has it, the errors relative, an empty cell for no paper figure.
  const auto power_of = [&](std::string_view case_name) {
    const std::string json = read_all(work_ / "runs" / case_name / "summary.json");
    const auto at = json.find("\"power_kw\" : ");
    EXPECT_NE(at, std::string::npos) << json;
    return std::stod(json.substr(at + 13));
  };
  std::istringstream table(read_all(work_ / "runs" / "validation.csv"));
  std::string line;
  std::getline(table, line);
  EXPECT_EQ(line,
            "case,measured_power_kw,paper_power_kw,power_kw,error,paper_error,tolerance,within");
  std::size_t outside_in_file = 0;
  for (const std::string case_name : {"a", "b"}) {
    ASSERT_TRUE(std::getline(table, line));
    std::vector<std::string> cells;
    std::istringstream row(line + ",");
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    ASSERT_EQ(cells.size(), 8U) << line;
    EXPECT_EQ(cells[0], case_name);
    EXPECT_EQ(cells[1], "0.6");
    const double power = power_of(case_name);
    EXPECT_EQ(std::stod(cells[3]), power) << line;
    EXPECT_EQ(std::stod(cells[4]), (power - 0.6) / 0.6) << line;
    EXPECT_EQ(cells[6], "0.15");
    EXPECT_EQ(cells[7], std::abs(power - 0.6) <= 0.15 * 0.6 ? "yes" : "no") << line;
    outside_in_file += cells[7] == "no" ? 1 : 0;
    if (case_name == "a") {
      EXPECT_EQ(cells[2], "");
      EXPECT_EQ(cells[5], "");
    } else {
      EXPECT_EQ(cells[2], "0.62");
      EXPECT_EQ(std::stod(cells[5]), (0.62 - 0.6) / 0.6);
    }
  }
  EXPECT_FALSE(std::getline(table, line)) << line;
  EXPECT_EQ(outside_in_file, outside);
  // validate places each case under --out itself: a --set of the directory is refused.
  const Outcome set = millsim(std::string("validate cases -q -o runs2 ") + tiny_run +
                              " --set output.directory=elsewhere");
  EXPECT_EQ(set.status, 2) << set.err;
  EXPECT_NE(set.err.find("command line (--set output.directory=elsewhere): output.directory: "
                         "validate writes each run to a directory of its own"),
            std::string::npos)
      << set.err;
  EXPECT_FALSE(fs::exists(work_ / "runs2"));
  EXPECT_FALSE(fs::exists(work_ / "elsewhere"));
  // The cases one after another on one thread, or together on one thread each: the same table.
  for (const char* threads : {"1", "2"}) {
    const Outcome again = millsim(std::string("validate cases -q -o runs-j") + threads + " -j " +
                                  threads + " " + tiny_run);
    EXPECT_EQ(again.status, good.status) << again.err;
    EXPECT_EQ(read_all(work_ / (std::string("runs-j") + threads) / "validation.csv"),
              read_all(work_ / "runs" / "validation.csv"))
        << threads;
  }
  // Again into the first one's directory: its results are cleared and replaced, not refused.
  const Outcome over = millsim(std::string("validate cases -q -o runs ") + tiny_run);
  EXPECT_EQ(over.status, good.status) << over.err;
  EXPECT_EQ(read_all(work_ / "runs" / "validation.csv"),
            read_all(work_ / "runs-j1" / "validation.csv"));
  // A case whose results cannot be cleared (a directory of the user's, not empty, under a
  // result's name) is refused before any case runs, as a sweep's point is.
  fs::remove(work_ / "runs-j1" / "b" / "summary.json");
  fs::create_directories(work_ / "runs-j1" / "b" / "summary.json" / "kept");
  const Outcome taken = millsim(std::string("validate cases -o runs-j1 ") + tiny_run);
  EXPECT_EQ(taken.status, 2) << taken.err;
  EXPECT_NE(taken.err.find("\"runs-j1/b\" holds a directory summary.json where the run writes a "
                           "result (not empty)"),
            std::string::npos)
      << taken.err;
  EXPECT_EQ(taken.err.find("running"), std::string::npos) << taken.err;
  EXPECT_TRUE(fs::exists(work_ / "runs-j1" / "validation.csv"));  // the earlier table stays
  // The key as the config reader reads it, blanks (a carriage return too) trimmed.
  const Outcome blank = millsim(std::string("validate cases -q -o runs2 ") + tiny_run +
                                " --set \"$(printf 'output.directory\\r=elsewhere')\"");
  EXPECT_EQ(blank.status, 2) << blank.err;
  EXPECT_FALSE(fs::exists(work_ / "runs2"));
}

}  // namespace
