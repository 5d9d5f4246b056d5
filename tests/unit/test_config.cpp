// Reading a mill config (config.hpp): good input gives the values written, bad input is refused
// with a message that names the file, the line, the dotted key and what is allowed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "millsim/core/error.hpp"
#include "millsim/io/config.hpp"
#include "millsim/io/toml_reader.hpp"
#include "support/config_text.hpp"

namespace millsim {
namespace {

using testing::line_of;
using testing::with;

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

constexpr const char* file_name = "mill.toml";

/// "mill.toml:LINE" for the line of `text` that starts with `start`.
std::string at_line(std::string_view text, std::string_view start) {
  return millsim::testing::at_line(file_name, text, start);
}

/// The message of the InputError that reading `text` throws; a test failure if none.
std::string error_of(std::string_view text, const std::vector<std::string>& overrides = {}) {
  try {
    parse_mill_config(text, file_name, overrides);
  } catch (const InputError& error) {
    return error.what();
  } catch (const std::exception& error) {
    ADD_FAILURE() << "not an InputError: " << error.what();
    return {};
  }
  ADD_FAILURE() << "accepted:\n" << text;
  return {};
}

void expect_has(const std::string& message, std::initializer_list<std::string_view> parts) {
  for (const std::string_view part : parts) {
    EXPECT_NE(message.find(part), std::string::npos)
        << "message lacks \"" << part << "\":\n  " << message;
  }
}

TEST(Config, ReadsTheBaseConfig) {
  const MillConfig c = parse_mill_config(base_config, file_name);
  EXPECT_EQ(c.source, file_name);
  EXPECT_EQ(c.dimension, 2);
  EXPECT_FALSE(c.time_step.has_value());
  EXPECT_DOUBLE_EQ(c.diameter, 0.9);
  EXPECT_DOUBLE_EQ(c.length, 0.15);
  ASSERT_TRUE(c.speed_fraction.has_value());
  EXPECT_DOUBLE_EQ(*c.speed_fraction, 0.5);
  EXPECT_FALSE(c.speed_rpm.has_value());
  EXPECT_EQ(c.lifter_count, 8);
  EXPECT_DOUBLE_EQ(c.lifter_height, 0.04);
  EXPECT_DOUBLE_EQ(c.filling, 0.3);
  ASSERT_EQ(c.sizes.size(), 1u);
  EXPECT_DOUBLE_EQ(c.sizes[0].diameter, 0.0508);
  EXPECT_DOUBLE_EQ(c.sizes[0].mass_fraction, 1.0);
  EXPECT_EQ(c.output_directory, "out");
  EXPECT_EQ(c.measure_revolutions, 4);
}

TEST(Config, MaterialsDefaultToSteelWithTheTangentialStiffnessTwoThirdsOfTheNormal) {
  // MODEL.md §3: k_s defaults to 2/3 k_n, of the k_n given or of the default 4e5 N/m.
  const MillConfig defaults = parse_mill_config(base_config, file_name);
  EXPECT_EQ(defaults.ball_ball.normal_stiffness, 4.0e5);
  EXPECT_DOUBLE_EQ(defaults.ball_ball.tangential_stiffness, 4.0e5 * 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(defaults.ball_wall.tangential_stiffness, 4.0e5 * 2.0 / 3.0);
  EXPECT_EQ(defaults.ball_ball.restitution, 0.6);
  EXPECT_EQ(defaults.ball_ball.friction, 0.5);

  const MillConfig given = parse_mill_config(
      std::string(base_config) + "[materials.ball_ball]\nnormal_stiffness = 9.0e5\n\n" +
          "[materials.ball_wall]\nnormal_stiffness = 6.0e5\ntangential_stiffness = 5.5e5\n",
      file_name);
  EXPECT_EQ(given.ball_ball.normal_stiffness, 9.0e5);
  EXPECT_DOUBLE_EQ(given.ball_ball.tangential_stiffness, 6.0e5);
  EXPECT_EQ(given.ball_wall.normal_stiffness, 6.0e5);
  EXPECT_EQ(given.ball_wall.tangential_stiffness, 5.5e5);
}

TEST(Config, ReadsTheShippedExample) {
  const std::string path = std::string(MILLSIM_SOURCE_DIR) + "/examples/lab-mill-2d.toml";
  const MillConfig c = load_mill_config(path);
  EXPECT_EQ(c.source, path);
  // The file's values (examples/lab-mill-2d.toml: case 3D-g's mill as a 2D slice).
  EXPECT_EQ(c.dimension, 2);
  EXPECT_FALSE(c.time_step.has_value()) << "auto";
  EXPECT_EQ(c.settle_time, 1.0);
  EXPECT_EQ(c.revolutions, 6);
  EXPECT_EQ(c.measure_revolutions, 4);
  EXPECT_EQ(c.seed, 1u);
  EXPECT_EQ(c.diameter, 0.9);
  EXPECT_EQ(c.length, 0.15);
  EXPECT_EQ(c.speed_fraction.value_or(-1.0), 0.5);
  EXPECT_EQ(c.lifter_count, 8);
  EXPECT_EQ(c.lifter_height, 0.04);
  EXPECT_EQ(c.lifter_width, 0.04);
  EXPECT_EQ(c.filling, 0.30);
  EXPECT_EQ(c.porosity, 0.4);
  EXPECT_EQ(c.density, 7800.0);
  ASSERT_EQ(c.sizes.size(), 1u);
  EXPECT_EQ(c.sizes[0].diameter, 0.0508);
  EXPECT_EQ(c.sizes[0].mass_fraction, 1.0);
  EXPECT_EQ(c.ball_ball.normal_stiffness, 4.0e5);
  EXPECT_EQ(c.ball_ball.tangential_stiffness, 3.0e5);
  EXPECT_EQ(c.ball_ball.restitution, 0.6);
  EXPECT_EQ(c.ball_ball.friction, 0.5);
  EXPECT_EQ(c.ball_wall.normal_stiffness, 4.0e5);
  EXPECT_EQ(c.ball_wall.restitution, 0.6);
}

TEST(Config, AcceptsAnIntegerWhereANumberIsExpected) {
  // density = 7800 is a TOML integer.
  const MillConfig c = parse_mill_config(with(base_config, "diameter", "diameter = 1"), file_name);
  EXPECT_DOUBLE_EQ(c.density, 7800.0);
  EXPECT_DOUBLE_EQ(c.diameter, 1.0);
}

TEST(Config, AcceptsAWholeFloatWhereAnIntegerIsExpected) {
  const MillConfig c = parse_mill_config(with(base_config, "count", "count = 8.0"), file_name);
  EXPECT_EQ(c.lifter_count, 8);
}

TEST(Config, RefusesAFractionWhereAnIntegerIsRequired) {
  const std::string text = with(base_config, "count", "count = 8.5");
  expect_has(error_of(text), {at_line(text, "count"), "mill.lifters.count", "8.5",
                              "not a whole number", "allowed: a whole number from 0 to 360"});
}

TEST(Config, RefusesATomlSyntaxErrorWithFileAndLine) {
  const std::string text = with(base_config, "length", "length = 0.15 0.2");
  expect_has(error_of(text), {at_line(text, "length"), "not valid TOML", "allowed: TOML"});
  const std::string unclosed = with(base_config, "[charge]", "[charge");
  expect_has(error_of(unclosed), {at_line(unclosed, "[charge"), "not valid TOML"});
}

TEST(Config, RefusesAnUnknownTable) {
  const std::string text = with(base_config, "[output]", "[outptu]");
  expect_has(error_of(text), {at_line(text, "[outptu]"), "outptu: unknown table",
                              "did you mean output?", "allowed at the top level", "simulation"});
}

TEST(Config, RefusesAnUnknownKeyAndSaysWhereItBelongs) {
  const std::string text = with(base_config, "length", "length = 0.15\nfilling = 0.3");
  // The first line starting "filling" is the one in [mill].
  expect_has(error_of(text), {at_line(text, "filling"), "mill.filling: unknown key",
                              "it belongs in [charge]", "allowed in [mill]: diameter, length"});
}

TEST(Config, RefusesAMisspeltKeyInANestedTableAsMisspelt) {
  // Not "height: missing required key": the misspelt key is the problem.
  const std::string text = with(base_config, "height", "hieght = 0.04");
  expect_has(error_of(text),
             {at_line(text, "hieght"), "mill.lifters.hieght: unknown key", "did you mean height?",
              "allowed in [mill.lifters]: count, height, width"});
}

TEST(Config, RefusesAValueOfTheWrongType) {
  const std::string text = with(base_config, "diameter", "diameter = \"0.9\"");
  expect_has(error_of(text), {at_line(text, "diameter"), "mill.diameter", "\"0.9\" is a string",
                              "allowed: a number of metres > 0"});
  const std::string table = with(base_config, "snapshot_interval", "snapshot_interval = [1]");
  expect_has(error_of(table), {"output.snapshot_interval", "an array", "allowed: a number"});
}

TEST(Config, RefusesAMissingRequiredKeyAtTheStartOfItsTable) {
  const std::string text = with(base_config, "length", "");
  expect_has(error_of(text), {at_line(text, "[mill]"), "mill.length", "missing required key",
                              "[mill]", "allowed: a number of metres > 0"});
}

TEST(Config, RefusesAMissingRequiredTable) {
  std::string text(base_config.substr(0, base_config.find("[charge]")));
  expect_has(error_of(text), {"mill.toml: charge: missing required table [charge]",
                              "allowed: a table [charge]", "filling"});
}

TEST(Config, NamesTheFileForAKeyMissingFromATableOnlyAnOverrideWrote) {
  // [charge] is not in the file: --set charge.filling creates it, and ball_diameter is missing.
  std::string text(base_config.substr(0, base_config.find("[charge]")));
  expect_has(
      error_of(text, {"charge.filling=0.3"}),
      {"mill.toml: charge.ball_diameter: missing required key", "[charge] is not in the file",
       "--set charge.filling=0.3", "allowed: one of ball_diameter"});
}

TEST(Config, PointsAtADottedKeyForAKeyMissingFromTheTableItMade) {
  const std::string text = with(
      with(with(with(base_config, "[mill.lifters]", ""), "count", ""), "height", ""), "width", "");
  const std::string dotted = with(text, "speed", "speed = 0.5\nlifters.count = 8");
  expect_has(error_of(dotted), {at_line(dotted, "lifters.count"), "mill.lifters.height",
                                "missing required key", "needed because count = 8"});
}

TEST(Config, RefusesALifterShapeWithoutACount) {
  const std::string text = with(base_config, "count", "");
  expect_has(error_of(text), {at_line(text, "[mill.lifters]"), "mill.lifters.count",
                              "missing required key", "needed when height or width is given"});
  // count = 0 (a smooth shell, e.g. from --set) keeps the shape unused.
  const MillConfig smooth = parse_mill_config(base_config, file_name, {"mill.lifters.count=0"});
  EXPECT_EQ(smooth.lifter_count, 0);
}

TEST(Config, RefusesImpossibleValues) {
  const std::string negative = with(base_config, "diameter", "diameter = -0.9");
  expect_has(error_of(negative), {at_line(negative, "diameter"), "mill.diameter",
                                  "-0.9 is not allowed", "allowed: a number of metres > 0"});
  for (const char* filling : {"filling = 1", "filling = 1.5", "filling = 0"}) {
    const std::string text = with(base_config, "filling", filling);
    expect_has(error_of(text), {at_line(text, "filling"), "charge.filling", "is not allowed",
                                "allowed: a fraction of the mill volume > 0 and < 1"});
  }
  const std::string porosity = with(base_config, "density", "density = 7800\nporosity = 1");
  expect_has(error_of(porosity), {at_line(porosity, "porosity"), "charge.porosity", "< 1"});
  const std::string nan = with(base_config, "length", "length = nan");
  expect_has(error_of(nan), {at_line(nan, "length"), "mill.length", "nan is not allowed"});
  // Values that would make the mill's mass or power infinite, or a ball's mass zero.
  const std::string long_mill = with(base_config, "length", "length = 1.7e308");
  expect_has(error_of(long_mill), {at_line(long_mill, "length"), "mill.length",
                                   "1.7e+308 is not allowed", "at most 1000"});
  const std::string wide_mill = with(base_config, "diameter", "diameter = 101");
  expect_has(error_of(wide_mill), {at_line(wide_mill, "diameter"), "mill.diameter",
                                   "101 is not allowed", "at most 100"});
  EXPECT_EQ(
      parse_mill_config(base_config, file_name, {"mill.length=1000", "mill.diameter=100"}).length,
      1000.0);
  const std::string tiny_ball = with(base_config, "ball_diameter", "ball_diameter = 1e-100");
  expect_has(error_of(tiny_ball), {at_line(tiny_ball, "ball_diameter"), "charge.ball_diameter",
                                   "1e-100 is not allowed", "from 0.0001 (0.1 mm)"});
  EXPECT_EQ(
      parse_mill_config(base_config, file_name, {"charge.ball_diameter=0.0001"}).sizes[0].diameter,
      1e-4);
}

TEST(Config, RefusesADottedKeyOfTooManyPartsBeforeParsingIt) {
  // toml++ takes each part one call deeper: 35 000 parts ran out of stack (a crash, no message).
  std::string deep;
  for (int i = 0; i < 35000; ++i) deep += "x.";
  const std::string text = std::string(base_config) + deep + "y = 1\n";
  expect_has(error_of(text),
             {std::string(file_name) + ":" + std::to_string(line_of(text, "x.")),
              "a dotted key or table name of more than 64 parts", "allowed: at most 64 parts"});
  const std::string header = std::string(base_config) + "[" + deep + "y]\n";
  expect_has(error_of(header), {"more than 64 parts"});
  // 64 parts are read (and, in [output], refused as an unknown key: the next check).
  std::string most;
  for (int i = 0; i < 63; ++i) most += "x.";
  expect_has(error_of(std::string(base_config) + most + "y = 1\n"), {"output.x: unknown key"});
  // A dotted word of 101 parts in strings and comments is no key (nor are numbers' points).
  std::string dotted;
  for (int i = 0; i < 100; ++i) dotted += "x.";
  dotted += "y";
  const MillConfig quiet = parse_mill_config(
      with(base_config, "directory", "directory = \"" + dotted + "\" # " + dotted), file_name);
  EXPECT_EQ(quiet.output_directory, dotted);
  EXPECT_FALSE(line_of_overlong_key("a = '" + dotted + "' # " + dotted).has_value());
  EXPECT_FALSE(line_of_overlong_key("a = \"\\\"" + dotted + "\"").has_value());  // "\"x.x..."
  EXPECT_FALSE(line_of_overlong_key("a = '''\n" + dotted + "\n'''\nb = 1").has_value());
  EXPECT_FALSE(line_of_overlong_key("a = \"\"\"\n" + dotted + "\n\"\"\"\nb = 1").has_value());
  std::string floats = "a = [";
  for (int i = 0; i < 100; ++i) floats += "1.5, ";
  EXPECT_FALSE(line_of_overlong_key(floats + "2.5]").has_value());
  // Outside them it is one, on the line where it passes 64 parts.
  EXPECT_EQ(line_of_overlong_key("a = 1\n" + dotted + " = 1"), 2u);
  EXPECT_EQ(line_of_overlong_key("a = \"\"\"\nx\n\"\"\"\n\n" + most + "x.y = 1"), 5u);
}

TEST(Config, RefusesAnUnknownKeyWithAControlCharacterShowingAllOfIt) {
  // A NUL in the key ended the message at it ("mill.spe"): it is escaped now.
  const std::string text = with(base_config, "speed", "\"spe\\u0000ed\" = 0.5\nspeed = 0.5");
  expect_has(error_of(text),
             {at_line(text, "\"spe"), "mill.spe\\x00ed: unknown key", "allowed in [mill]"});
}

TEST(Config, RefusesABlankCaseNameAndATolerancePastOne) {
  // validate printed the first as a row with no name, the second as ±10000%.
  expect_has(error_of(base_config, {"reference.case=\" \"", "reference.measured_power_kw=1"}),
             {"command line (--set reference.case=\" \")", "reference.case", "\" \" is not allowed",
              "more than blanks"});
  // Any white space is blank (a newline was taken as a name), and shown escaped.
  expect_has(error_of(base_config, {"reference.case=\"\\n\\t\"", "reference.measured_power_kw=1"}),
             {"reference.case", "\"\\n\\t\" is not allowed", "more than blanks"});
  expect_has(error_of(base_config, {"reference.case=x", "reference.measured_power_kw=1",
                                    "reference.tolerance=100"}),
             {"reference.tolerance", "100 is not allowed", "at most 1 (100 %)"});
  const MillConfig one = parse_mill_config(
      base_config, file_name,
      {"reference.case=x", "reference.measured_power_kw=1", "reference.tolerance=1"});
  ASSERT_TRUE(one.reference.has_value());
  EXPECT_EQ(one.reference->tolerance, 1.0);
}

TEST(Config, RefusesAnOverrideWithMoreTomlAfterItsValue) {
  // The second line was parsed as a key of its own and dropped unread.
  expect_has(error_of(base_config, {"mill.speed=0.7\nbogus.key = \"x\""}),
             {"command line (--set mill.speed=0.7\\nbogus.key = \"x\")", "more than one value",
              "allowed: one value"});
  // A value over several lines is still one value.
  const MillConfig sizes = parse_mill_config(
      base_config, file_name,
      {"charge.sizes=[{diameter = 0.05, mass_fraction = 0.6},\n {diameter = 0.04, mass_fraction "
       "= 0.4}]"});
  EXPECT_EQ(sizes.sizes.size(), 2u);
}

TEST(Config, RefusesLiftersThatFillTheMill) {
  const std::string text = with(base_config, "height", "height = 0.45");
  expect_has(error_of(text), {at_line(text, "height"), "mill.lifters.height", "0.45 is not allowed",
                              "< 0.45 (the mill radius", "fill the mill"});
}

TEST(Config, RefusesLiftersThatOverlap) {
  // 8 lifters 4 cm high: neighbours, 45° apart, meet where their inner corners do, at
  // w = 2 (0.45 − 0.04) tan(22.5°) = 0.3396551 m. (Until 2026-12-07 the limit was the inner
  // circle's share, 2π (0.45 − 0.04) / 8 = 0.322 m, which refused lifters 9 mm apart.)
  const std::string text = with(base_config, "width", "width = 0.34");
  expect_has(error_of(text), {at_line(text, "width"), "mill.lifters.width", "0.34 is not allowed",
                              "< 0.339655", "inner corners of 8 lifters 0.04 m high would meet"});
  EXPECT_EQ(parse_mill_config(with(base_config, "width", "width = 0.33"), file_name).lifter_width,
            0.33);
  // Two lifters cannot meet: the width is bounded by each one's share of the inner circle,
  // π (0.45 − 0.3) = 0.4712389 m for lifters 0.3 m high.
  const std::string two =
      with(with(with(base_config, "count", "count = 2"), "height", "height = 0.3"), "width",
           "width = 0.48");
  expect_has(error_of(two), {at_line(two, "width"), "0.48 is not allowed", "< 0.471238",
                             "the inner circle's share of each of 2 lifters 0.3 m high"});
}

TEST(Config, RefusesLiftersWiderThanTheShellsChord) {
  // A bar wider than the shell's chord at its inner face stands with its inner corners outside
  // the shell (and touches as a chord of it): 2 sqrt(0.45² − 0.41²) = 0.3709447 m for lifters
  // 4 cm high, less than two lifters' share of the inner circle (1.288 m) or three's spacing
  // (2 × 0.41 tan 60° = 1.42 m). (A review found 1.2 m accepted.)
  for (const char* count : {"count = 2", "count = 3"}) {
    const std::string text = with(with(base_config, "count", count), "width", "width = 0.371");
    expect_has(error_of(text),
               {at_line(text, "width"), "0.371 is not allowed", "< 0.3709447 ",
                "the shell's chord at a lifter's inner face, 0.41 m from the axis"});
    EXPECT_EQ(parse_mill_config(with(with(base_config, "count", count), "width", "width = 0.37"),
                                file_name)
                  .lifter_width,
              0.37);
  }
}

TEST(Config, RefusesBothSpeeds) {
  const std::string text = with(base_config, "speed", "speed = 0.5\nspeed_rpm = 20");
  expect_has(error_of(text), {at_line(text, "speed_rpm"), "mill.speed_rpm",
                              "given as well as mill.speed (" + at_line(text, "speed =") + ")",
                              "allowed: either mill.speed", "not both",
                              std::string_view("mill.speed_rpm (a number of rpm > 0, at most 5 "
                                               "times the critical speed)")});
  // A speed_rpm alone says the same (the bound of 5 times critical is checked by plan_mill).
  const std::string zero = with(base_config, "speed", "speed_rpm = 0");
  expect_has(error_of(zero), {at_line(zero, "speed_rpm"), "mill.speed_rpm: 0 is not allowed",
                              "allowed: a number of rpm > 0, at most 5 times the critical speed"});
}

TEST(Config, RefusesNoSpeed) {
  const std::string text = with(base_config, "speed", "");
  expect_has(error_of(text), {at_line(text, "[mill]"), "mill.speed", "missing required key",
                              "allowed: either mill.speed", "mill.speed_rpm"});
  const MillConfig rpm = parse_mill_config(with(base_config, "speed", "speed_rpm = 20"), file_name);
  EXPECT_FALSE(rpm.speed_fraction.has_value());
  EXPECT_DOUBLE_EQ(rpm.speed_rpm.value_or(0.0), 20.0);
}

TEST(Config, RefusesMassFractionsThatDoNotSumToOne) {
  const std::string text = with(base_config, "ball_diameter",
                                "sizes = [{ diameter = 0.05, mass_fraction = 0.5 },\n"
                                "         { diameter = 0.04, mass_fraction = 0.4 }]");
  expect_has(error_of(text), {at_line(text, "sizes"), "charge.sizes", "sum to 0.9",
                              "allowed: mass fractions that sum to 1"});
  const std::string good = with(base_config, "ball_diameter",
                                "sizes = [{ diameter = 0.05, mass_fraction = 0.6 },\n"
                                "         { diameter = 0.04, mass_fraction = 0.4 }]");
  EXPECT_EQ(parse_mill_config(good, file_name).sizes.size(), 2u);
  EXPECT_EQ(parse_mill_config(good, file_name).size_description, "2 sizes given");
  const std::string one =
      with(base_config, "ball_diameter", "sizes = [{ diameter = 0.05, mass_fraction = 1 }]");
  EXPECT_EQ(parse_mill_config(one, file_name).size_description, "one size given");
}

TEST(Config, RefusesABadSizeListEntryAtItsLine) {
  const std::string text = with(base_config, "ball_diameter",
                                "sizes = [\n  { diameter = 0.05, mass_fraction = 0.5 },\n"
                                "  { diameter = 0.04, mas_fraction = 0.5 }]");
  expect_has(error_of(text), {at_line(text, "  { diameter = 0.04"), "charge.sizes[1].mas_fraction",
                              "unknown key", "did you mean mass_fraction?"});
  const std::string two =
      with(base_config, "ball_diameter", "ball_diameter = 0.05\ntop_size = 0.05");
  expect_has(error_of(two), {at_line(two, "top_size"), "charge.top_size",
                             "given as well as charge.ball_diameter", "allowed: one of"});
}

TEST(Config, ReadsTheDimensionAndRefusesAnyOther) {
  const std::string three = with(base_config, "time_step", "dimension = 3\ntime_step = \"auto\"");
  EXPECT_EQ(parse_mill_config(three, file_name).dimension, 3);
  EXPECT_EQ(parse_mill_config(base_config, file_name).dimension, 2);
  const std::string one = with(base_config, "time_step", "dimension = 1\ntime_step = \"auto\"");
  expect_has(error_of(one), {at_line(one, "dimension"), "simulation.dimension", "1 is not allowed",
                             "allowed: 2 (a slice of discs) or 3 (spheres)"});
}

TEST(Config, ReadsAPeriodicSlabIn3DOnly) {
  const std::string slab =
      with(with(base_config, "time_step", "dimension = 3\ntime_step = \"auto\""), "speed",
           "speed = 0.5\nperiodic = true\nslab_length = 0.2");
  // A slab longer than the 0.15 m mill is refused; one within it is read.
  expect_has(error_of(slab), {at_line(slab, "slab_length"), "mill.slab_length", "0.2",
                              "at most mill.length = 0.15 m"});
  const std::string ok = with(slab, "slab_length", "slab_length = 0.1");
  const MillConfig c = parse_mill_config(ok, file_name);
  EXPECT_TRUE(c.periodic);
  EXPECT_DOUBLE_EQ(c.slab_length, 0.1);
  // Periodic without a slab length, periodic in 2D, a slab length without periodic.
  const std::string missing = with(slab, "slab_length", "");
  expect_has(error_of(missing), {"mill.slab_length", "needed because mill.periodic = true"});
  const std::string flat = with(base_config, "speed", "speed = 0.5\nperiodic = true");
  expect_has(error_of(flat),
             {at_line(flat, "periodic"), "mill.periodic", "needs simulation.dimension = 3"});
  const std::string stray = with(base_config, "speed", "speed = 0.5\nslab_length = 0.1");
  expect_has(error_of(stray),
             {at_line(stray, "slab_length"), "mill.slab_length", "mill.periodic is not true"});
  const std::string typed = with(slab, "periodic", "periodic = \"yes\"");
  expect_has(error_of(typed), {at_line(typed, "periodic"), "mill.periodic", "allowed: true"});
}

TEST(Config, RefusesATimeStepThatIsNotANumberOrAuto) {
  const std::string text = with(base_config, "time_step", "time_step = \"fast\"");
  expect_has(error_of(text),
             {at_line(text, "time_step"), "simulation.time_step", "\"fast\" is not allowed",
              "allowed: \"auto\" or a number of seconds"});
  for (const char* bad : {"time_step = 0", "time_step = -1e-5"}) {
    const std::string step = with(base_config, "time_step", bad);
    expect_has(error_of(step), {at_line(step, "time_step"), "simulation.time_step", "> 0"});
  }
  const std::string flag = with(base_config, "time_step", "time_step = true");
  expect_has(error_of(flag), {"simulation.time_step", "true is a boolean", "\"auto\""});
  const MillConfig fixed =
      parse_mill_config(with(base_config, "time_step", "time_step = 1e-4"), file_name);
  EXPECT_DOUBLE_EQ(fixed.time_step.value_or(0.0), 1e-4);
}

TEST(Config, RefusesMoreMeasuredRevolutionsThanRun) {
  const std::string text = with(base_config, "revolutions", "revolutions = 2");
  expect_has(error_of(text),
             {at_line(text, "measure_revolutions"), "simulation.measure_revolutions",
              "4 is more than", "simulation.revolutions = 2", "from 1 to 2"});
  // The default 4 is checked too.
  const std::string implicit = with(text, "measure_revolutions", "");
  expect_has(error_of(implicit), {at_line(implicit, "revolutions"),
                                  "simulation.measure_revolutions", "default 4", "from 1 to 2"});
  expect_has(error_of(base_config, {"simulation.revolutions=0.5"}),
             {"command line (--set simulation.revolutions=0.5)", "simulation.revolutions",
              "allowed: a whole number of revolutions from 1"});
  expect_has(error_of(base_config, {"simulation.revolutions=1.5"}),
             {"simulation.revolutions", "1.5 is not a whole number"});
  // 1e16 is a whole number, but a float that far out stands for several: it says so.
  expect_has(error_of(base_config, {"simulation.seed=1e16"}),
             {"simulation.seed", "1e+16 is a float beyond 2^53", "written as an integer"});
  EXPECT_EQ(parse_mill_config(base_config, file_name, {"simulation.seed=10000000000000000"}).seed,
            10000000000000000UL);
  // A number TOML cannot hold is kept as text by --set: the message says why it is a string.
  expect_has(error_of(base_config, {"simulation.revolutions=9999999999999999999"}),
             {"simulation.revolutions",
              "\"9999999999999999999\" is a string (TOML did not read it as a number",
              "±9223372036854775807 if whole"});
  const std::string quoted = error_of(base_config, {"simulation.revolutions=\"5\""});
  expect_has(quoted, {"\"5\" is a string; allowed:"});
  // A string typed inside an array or table that TOML read was typed as one, too (the message
  // once said TOML had not read it as a number).
  const std::string in_array =
      error_of(base_config, {"charge.sizes=[{diameter = \"0.05\", mass_fraction = 1}]"});
  EXPECT_EQ(in_array.find("TOML did not read it"), std::string::npos) << in_array;
  expect_has(in_array, {"charge.sizes", "\"0.05\" is a string"});
}

TEST(Config, AValidOverrideChangesTheValueAndIsRecordedAsFromTheCommandLine) {
  const MillConfig c = parse_mill_config(
      base_config, file_name, {"mill.speed=0.75", "simulation.seed=7", "output.directory=2024"});
  EXPECT_DOUBLE_EQ(c.speed_fraction.value_or(0.0), 0.75);
  EXPECT_EQ(c.seed, 7u);
  EXPECT_EQ(c.output_directory, "2024");  // taken as typed, not as the integer 2024
  EXPECT_EQ(c.location_of("mill.speed"), "command line (--set mill.speed=0.75)");
  EXPECT_EQ(c.location_of("mill.diameter"), std::string(file_name) + ":7");
  // A default has no line, and the message says so.
  EXPECT_EQ(c.location_of("charge.porosity"), std::string(file_name) + " (not given: its default)");
}

TEST(Config, RefusesATopSizeWhoseSmallestClassIsBelowATenthOfAMillimetre) {
  // The graded charge's smallest class is 0.8³ = 0.512 of the top size.
  const std::string text = with(base_config, "ball_diameter", "top_size = 0.0001");
  expect_has(error_of(text),
             {at_line(text, "top_size"), "charge.top_size: 0.0001 is not allowed",
              "allowed: a number of metres from 0.0001953125 (whose smallest class, 0.512 of it, "
              "is 0.1 mm)"});
  const MillConfig least =
      parse_mill_config(with(base_config, "ball_diameter", "top_size = 0.0001953125"), file_name);
  for (const SizeClass& size : least.sizes) EXPECT_GE(size.diameter, 1e-4);
}

TEST(Config, SuggestsOnlyKeysThatAreLikelyMisspellings) {
  // One edit in a short key, two from nine letters on; "young" is two edits from "count".
  const std::string young = std::string(base_config) + "[materials.ball_ball]\nyoung = 1\n";
  const std::string message = error_of(young);
  expect_has(message, {"materials.ball_ball.young: unknown key"});
  EXPECT_EQ(message.find("did you mean"), std::string::npos) << message;
  expect_has(error_of(with(base_config, "filling", "filing = 0.3")), {"did you mean filling?"});
  expect_has(error_of(with(base_config, "ball_diameter", "bal_diametr = 0.0508")),
             {"did you mean ball_diameter?"});
}

TEST(Config, AnOverrideOfAnUnknownKeyNamesTheOption) {
  expect_has(error_of(base_config, {"mill.lifters.hieght=0.04"}),
             {"command line (--set mill.lifters.hieght=0.04)", "mill.lifters.hieght", "unknown key",
              "did you mean height?", "allowed in [mill.lifters]"});
  expect_has(error_of(base_config, {"mil.speed=0.7"}),
             {"command line (--set mil.speed=0.7)", "mil: unknown table", "did you mean mill?"});
}

TEST(Config, AnOverrideGivesOneValueOnceAndNeverAWholeTable) {
  // The second of two would win unseen; a table would drop every key of the file's table.
  expect_has(error_of(base_config, {"mill.speed=0.6", "mill.speed=0.7"}),
             {"command line (--set mill.speed=0.7)", "mill.speed: given twice",
              "also as --set mill.speed=0.6", "allowed: each key once"});
  expect_has(error_of(base_config, {"mill={diameter = 1.0, length = 0.15, speed = 0.5}"}),
             {"mill: a table would replace all of [mill]", "--set mill.KEY=VALUE"});
  // An array of tables is a value, not a table.
  const MillConfig sized =
      parse_mill_config(with(base_config, "ball_diameter", ""), file_name,
                        {"charge.sizes=[{diameter = 0.05, mass_fraction = 1.0}]"});
  EXPECT_EQ(sized.sizes.size(), 1u);
}

TEST(Config, AnOverrideOfOneOfTwoAlternativeKeysReplacesTheFilesOther) {
  // The file gives mill.speed and charge.ball_diameter; a sweep over speed_rpm or top_size
  // must be able to replace them.
  const MillConfig rpm = parse_mill_config(base_config, file_name, {"mill.speed_rpm=20"});
  EXPECT_FALSE(rpm.speed_fraction.has_value());
  EXPECT_DOUBLE_EQ(rpm.speed_rpm.value_or(0.0), 20.0);
  const MillConfig back = parse_mill_config(with(base_config, "speed", "speed_rpm = 20"), file_name,
                                            {"mill.speed=0.6"});
  EXPECT_DOUBLE_EQ(back.speed_fraction.value_or(0.0), 0.6);
  EXPECT_FALSE(back.speed_rpm.has_value());
  const MillConfig graded = parse_mill_config(base_config, file_name, {"charge.top_size=0.05"});
  EXPECT_EQ(graded.sizes.size(), 4u);
  EXPECT_DOUBLE_EQ(graded.sizes[0].diameter, 0.05);
  const MillConfig listed = parse_mill_config(
      base_config, file_name, {"charge.sizes=[{diameter = 0.04, mass_fraction = 1.0}]"});
  ASSERT_EQ(listed.sizes.size(), 1u);
  EXPECT_DOUBLE_EQ(listed.sizes[0].diameter, 0.04);
  // Two overrides of alternatives still contradict each other.
  expect_has(error_of(base_config, {"mill.speed_rpm=20", "mill.speed=0.6"}),
             {"command line (--set mill.speed_rpm=20)", "given as well as mill.speed",
              "(command line (--set mill.speed=0.6))", "not both"});
  expect_has(error_of(base_config, {"charge.top_size=0.05", "charge.ball_diameter=0.04"}),
             {"given as well as charge.ball_diameter", "not several"});
  // Two alternatives in the file are refused as before, whatever else is set.
  const std::string both = with(base_config, "speed", "speed = 0.5\nspeed_rpm = 20");
  expect_has(error_of(both, {"mill.length=0.2"}), {at_line(both, "speed_rpm"), "not both"});
}

TEST(Config, ReadsTheSnapshotFormatAndRefusesAnyOther) {
  const MillConfig plain = parse_mill_config(base_config, file_name);
  EXPECT_TRUE(plain.snapshot_csv);
  EXPECT_FALSE(plain.snapshot_vtk);
  const auto formats = [](const std::string& format) {
    const MillConfig c =
        parse_mill_config(with(base_config, "snapshot_interval",
                               "snapshot_interval = 0.05\nsnapshot_format = \"" + format + "\""),
                          file_name);
    return std::pair{c.snapshot_csv, c.snapshot_vtk};
  };
  EXPECT_EQ(formats("csv"), std::pair(true, false));
  EXPECT_EQ(formats("vtk"), std::pair(false, true));
  EXPECT_EQ(formats("both"), std::pair(true, true));
  const std::string text =
      with(base_config, "snapshot_interval", "snapshot_interval = 0.05\nsnapshot_format = \"VTK\"");
  expect_has(error_of(text),
             {at_line(text, "snapshot_format"),
              "output.snapshot_format: \"VTK\" is not a snapshot format; allowed: \"csv\" (a "
              "table a snapshot), \"vtk\" (VTK files and a ParaView collection) or \"both\""});
  expect_has(error_of(base_config, {"output.snapshot_format=\"vtp\""}),
             {"command line (--set output.snapshot_format=\"vtp\")", "\"vtp\" is not a snapshot"});
}

TEST(Config, RefusesANulInTheOutputPath) {
  // TOML allows \u0000 in a string; a path would be cut at it.
  expect_has(error_of(with(base_config, "directory", "directory = \"out\\u0000x\"")),
             {"output.directory", "a NUL character is not allowed"});
}

TEST(Config, AnOverrideWithABadValueNamesTheOption) {
  expect_has(error_of(base_config, {"mill.diameter=-1"}),
             {"command line (--set mill.diameter=-1)", "mill.diameter", "-1 is not allowed",
              "allowed: a number of metres > 0"});
  expect_has(error_of(base_config, {"mill.speed=fast"}),
             {"command line (--set mill.speed=fast)", "mill.speed", "\"fast\" is a string",
              "allowed: a fraction of critical speed"});
  expect_has(error_of(base_config, {"mill.diameter.inner=1"}),
             {"command line (--set mill.diameter.inner=1)", "not a table"});
}

TEST(Config, RefusesAMalformedOverride) {
  expect_has(error_of(base_config, {"mill.speed"}),
             {"command line (--set mill.speed)", "no '='", "allowed: KEY=VALUE"});
  expect_has(error_of(base_config, {"=0.7"}),
             {"command line (--set =0.7)", "no key", "allowed: KEY=VALUE"});
  expect_has(error_of(base_config, {"mill..speed=0.7"}),
             {"command line (--set mill..speed=0.7)", "not a valid key name", "allowed:"});
}

TEST(Config, RefusesAMissingOrUnreadableFile) {
  const std::string missing = "no-such-dir/no-such-mill.toml";
  try {
    load_mill_config(missing);
    ADD_FAILURE() << "accepted a missing file";
  } catch (const InputError& error) {
    expect_has(error.what(), {missing, "no such config file", "allowed: the path of a mill"});
  }
  try {
    load_mill_config(std::filesystem::temp_directory_path().string());
    ADD_FAILURE() << "accepted a directory";
  } catch (const InputError& error) {
    expect_has(error.what(), {"is a directory", "allowed:"});
  }
}

TEST(Config, RefusesAnEmptyFile) {
  expect_has(error_of(""), {"mill.toml: mill: missing required table [mill]", "allowed:"});
}

}  // namespace
}  // namespace millsim
