#include "millsim/io/config.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <span>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

#include "millsim/core/constants.hpp"
#include "millsim/core/error.hpp"
#include "millsim/io/config_detail.hpp"
#include "millsim/io/toml_reader.hpp"

namespace millsim {

using config_detail::read_material;
using config_detail::read_output_directory;
using config_detail::read_scene_config;
using config_detail::read_time_step;

namespace {

bool positive(double x) {
  return x > 0.0;
}

/// The keys of every table, to say where a key put in the wrong table belongs.
struct KnownTable {
  std::string_view name;
  std::vector<std::string_view> keys;
};

const std::vector<KnownTable>& known_tables() {
  static const std::vector<KnownTable> tables = {
      {"simulation",
       {config_detail::mill_simulation_keys.begin(), config_detail::mill_simulation_keys.end()}},
      {"mill",
       {"diameter", "length", "speed", "speed_rpm", "periodic", "slab_length", "cone_angle",
        "cone_length", "lifters"}},
      {"mill.lifters", {"count", "height", "width"}},
      {"charge", {"filling", "porosity", "density", "ball_diameter", "top_size", "sizes"}},
      {"materials", {"ball_ball", "ball_wall"}},
      {"materials.ball_ball] or [materials.ball_wall",
       {"normal_stiffness", "tangential_stiffness", "restitution", "friction"}},
      {"output", {"directory", "snapshot_interval", "snapshot_format"}},
      {"reference", {"case", "measured_power_kw", "paper_power_kw", "tolerance"}},
  };
  return tables;
}

/// "it belongs in [charge]" for a key that another table has, or "did you mean height in
/// [mill.lifters]?" for one close to a key of another table; empty if there is none.
std::string belongs_elsewhere(std::string_view key) {
  for (const KnownTable& table : known_tables()) {
    if (std::find(table.keys.begin(), table.keys.end(), key) != table.keys.end()) {
      return fmt::format("it belongs in [{}]", table.name);
    }
  }
  for (const KnownTable& table : known_tables()) {
    if (const auto near = closest_key(key, table.keys)) {
      return fmt::format("did you mean {} in [{}]?", *near, table.name);
    }
  }
  return {};
}

}  // namespace

namespace config_detail {

std::optional<double> read_time_step(TableReader& section) {
  const std::string step_rule = "\"auto\" or a number of seconds > 0";
  const toml::node* step = section.node("time_step");
  if (step == nullptr) return std::nullopt;
  if (!step->is_string()) return section.number("time_step", std::nullopt, step_rule, positive);
  if (step->as_string()->get() != "auto") {
    section.fail_at("time_step", fmt::format("{} is not allowed; allowed: {}",
                                             describe_value(*step), step_rule));
  }
  return std::nullopt;
}

}  // namespace config_detail

namespace {

void read_simulation(TableReader section, MillConfig& config) {
  section.allow_keys(config_detail::mill_simulation_keys, belongs_elsewhere);
  config.dimension =
      static_cast<int>(section.integer("dimension", 2, "2 (a slice of discs) or 3 (spheres)",
                                       [](long d) { return d == 2 || d == 3; }));
  config.time_step = read_time_step(section);
  config.settle_time = section.number("settle_time", 1.0, "a number of seconds >= 0, at most 1e4",
                                      [](double t) { return t >= 0.0 && t <= 1e4; });
  // At least one revolution: measure_revolutions (a whole number >= 1) are measured of them.
  // Whole revolutions, so that the measured ones are the whole revolutions of power.csv.
  config.revolutions = static_cast<double>(
      section.integer("revolutions", 6, "a whole number of revolutions from 1 to 100000",
                      [](long n) { return n >= 1 && n <= 100000; }));
  const long most = static_cast<long>(std::floor(config.revolutions));
  const std::string measure_rule =
      fmt::format("a whole number of revolutions from 1 to {} (simulation.revolutions)", most);
  const bool measure_given = section.has("measure_revolutions");
  const long measure =
      section.integer("measure_revolutions", 4, measure_rule, [](long n) { return n >= 1; });
  if (measure > most) {
    const std::string revolutions =
        fmt::format("simulation.revolutions = {} ({})", config.revolutions,
                    section.has("revolutions") ? section.location("revolutions") : "default");
    if (measure_given) {
      section.fail_at("measure_revolutions", fmt::format("{} is more than {}; allowed: {}", measure,
                                                         revolutions, measure_rule));
    }
    throw InputError(fmt::format(
        "{}: simulation.measure_revolutions: not given, and its default {} is more than "
        "simulation.revolutions = {}; allowed: set measure_revolutions to a whole number of "
        "revolutions from 1 to {}",
        section.location("revolutions"), measure, config.revolutions, most));
  }
  config.measure_revolutions = static_cast<int>(measure);
  config.seed = static_cast<std::uint64_t>(
      section.integer("seed", 1, "a whole number from 0 to 9223372036854775807 (2^63 - 1)",
                      [](long s) { return s >= 0; }));
}

void read_lifters(TableReader lifters, MillConfig& config) {
  lifters.allow_keys({"count", "height", "width"}, belongs_elsewhere);
  const double radius = 0.5 * config.diameter;
  const bool shaped = lifters.has("height") || lifters.has("width");
  config.lifter_count = static_cast<int>(
      lifters.integer("count", shaped ? std::nullopt : std::optional<long>(0),
                      shaped ? "a whole number from 0 to 360 (needed when height or width is given)"
                             : "a whole number from 0 to 360 (0 = a smooth shell)",
                      [](long n) { return n >= 0 && n <= 360; }));
  const std::string height_rule = fmt::format(
      "a number of metres > 0 and < {} (the mill radius; taller lifters would fill the mill)",
      radius);
  const auto height_fits = [&](double h) { return h > 0.0 && h < radius; };
  if (config.lifter_count == 0) {
    // A smooth shell (e.g. --set mill.lifters.count=0): the lifter shape is not used, but it
    // must still make sense.
    lifters.optional_number("height", height_rule, height_fits);
    lifters.optional_number("width", "a number of metres > 0", positive);
    return;
  }
  config.lifter_height = lifters.number(
      "height", std::nullopt,
      fmt::format("{}; needed because count = {}", height_rule, config.lifter_count), height_fits);
  // Neighbouring bars, 2π/n apart, meet where their inner faces' corners do, on the ray
  // between them: at w = 2 (R − h) tan(π/n). (Two or one cannot meet: for them the inner
  // circle's share of each, 2π (R − h) / n, bounds the width.)
  const double inner_radius = radius - config.lifter_height;
  const int count = config.lifter_count;
  const double spacing_bound =
      count >= 3 ? 2.0 * inner_radius * std::tan(pi / count) : 2.0 * pi * inner_radius / count;
  // Nor wider than the shell's chord at the inner face: wider, the bar's inner corners and
  // side faces would stand outside the shell, and it would touch as a chord of the shell.
  const double chord = 2.0 * std::sqrt(radius * radius - inner_radius * inner_radius);
  const double widest = std::min(spacing_bound, chord);
  const std::string why =
      chord < spacing_bound
          ? fmt::format(
                "the shell's chord at a lifter's inner face, {:.6g} m from the axis; wider, "
                "its inner corners would stand outside the shell",
                inner_radius)
      : count >= 3 ? fmt::format("wider, the inner corners of {} lifters {} m high would meet",
                                 count, config.lifter_height)
                   : fmt::format("the inner circle's share of each of {} lifters {} m high", count,
                                 config.lifter_height);
  config.lifter_width = lifters.number(
      "width", std::nullopt,
      fmt::format("a number of metres > 0 and < {} ({})", limit_text(widest, Allowed::below), why),
      [&](double w) { return w > 0.0 && w < widest; });
}

/// mill.periodic and mill.slab_length: a 3D slab with periodic ends. The slab must be shorter
/// than the mill; that it is long enough for the balls is checked with the charge.
void read_periodic(TableReader& section, MillConfig& config) {
  const std::string periodic_rule =
      "true (simulate a periodic axial slab of mill.slab_length, power scaled to mill.length) or "
      "false (the whole mill with end plates)";
  config.periodic = section.boolean("periodic", false, periodic_rule);
  if (config.periodic && config.dimension != 3) {
    section.fail_at("periodic", fmt::format("true needs simulation.dimension = 3; allowed: false "
                                            "in 2D (a 2D slice has no ends)"));
  }
  const std::string slab_rule =
      fmt::format("a number of metres > 0 and at most mill.length = {} m", config.length);
  if (!config.periodic) {
    if (section.has("slab_length")) {
      section.fail_at("slab_length",
                      "is given but mill.periodic is not true; allowed: "
                      "slab_length only with mill.periodic = true");
    }
    return;
  }
  config.slab_length =
      section.number("slab_length", std::nullopt,
                     fmt::format("{}; needed because mill.periodic = true", slab_rule),
                     [&](double l) { return l > 0.0 && l <= config.length; });
}

/// mill.cone_angle and mill.cone_length: conical ends of a whole 3D mill, given together. The
/// cone must end before it reaches the axis: its trunnion radius R − cone_length /
/// tan(cone_angle) is above zero.
void read_cones(TableReader& section, MillConfig& config) {
  if (!section.has("cone_angle") && !section.has("cone_length")) return;
  const std::string_view given = section.has("cone_angle") ? "cone_angle" : "cone_length";
  if (config.dimension != 3) {
    section.fail_at(given,
                    "conical ends need simulation.dimension = 3; allowed: no "
                    "mill.cone_angle or mill.cone_length in 2D (a 2D slice has no ends)");
  }
  if (config.periodic) {
    section.fail_at(given,
                    "is given but mill.periodic = true (a periodic slab has no ends); "
                    "allowed: cone_angle and cone_length only for a whole mill");
  }
  const std::string both =
      "mill.cone_angle and mill.cone_length together (conical ends), or neither (flat ends)";
  if (!section.has("cone_angle")) section.fail_missing("cone_angle", both);
  if (!section.has("cone_length")) section.fail_missing("cone_length", both);
  config.cone_angle_degrees = section.number(
      "cone_angle", std::nullopt,
      "degrees > 0 and < 90, between the cone and the plane of a flat end (typically 15-20)",
      [](double a) { return a > 0.0 && a < 90.0; });
  const double longest = 0.5 * config.diameter * std::tan(config.cone_angle_degrees * pi / 180.0);
  config.cone_length = section.number(
      "cone_length", std::nullopt,
      fmt::format("a number of metres > 0 and < {} (longer, a cone at {} degrees from a mill "
                  "of {} m diameter would reach the axis)",
                  limit_text(longest, Allowed::below), config.cone_angle_degrees, config.diameter),
      [&](double l) { return l > 0.0 && l < longest; });
}

void read_mill(TableReader section, MillConfig& config) {
  section.allow_keys({"diameter", "length", "speed", "speed_rpm", "periodic", "slab_length",
                      "cone_angle", "cone_length", "lifters"},
                     belongs_elsewhere);
  // The upper bounds keep every derived figure finite (a mill 1e308 m long weighed inf kg and
  // drew inf kW); the largest mills built are 13 m across and 15 m long.
  config.diameter = section.number("diameter", std::nullopt,
                                   "a number of metres > 0, at most 100 (inside the shell)",
                                   [](double d) { return d > 0.0 && d <= 100.0; });
  config.length = section.number("length", std::nullopt, "a number of metres > 0, at most 1000",
                                 [](double l) { return l > 0.0 && l <= 1000.0; });
  const std::string speed_rule = "a fraction of critical speed > 0, at most 5";
  // (The rpm's upper bound depends on the critical speed, which plan_mill works out and checks.)
  const std::string rpm_rule = "a number of rpm > 0, at most 5 times the critical speed";
  config.speed_fraction =
      section.optional_number("speed", speed_rule, [](double s) { return s > 0.0 && s <= 5.0; });
  config.speed_rpm = section.optional_number("speed_rpm", rpm_rule, positive);
  const std::string either =
      fmt::format("either mill.speed ({}) or mill.speed_rpm ({}), not both", speed_rule, rpm_rule);
  if (config.speed_fraction && config.speed_rpm) {
    section.fail_at("speed_rpm", fmt::format("given as well as mill.speed ({}); allowed: {}",
                                             section.location("speed"), either));
  }
  if (!config.speed_fraction && !config.speed_rpm) section.fail_missing("speed", either);
  read_periodic(section, config);
  read_cones(section, config);
  read_lifters(section.table("lifters", false), config);
}

void read_sizes(TableReader& section, MillConfig& config) {
  const double radius = 0.5 * config.diameter;
  // At least 0.1 mm: a ball of 1e-100 m has a mass of 0 in doubles, and no contact duration.
  const std::string size_rule = fmt::format(
      "a number of metres from 0.0001 (0.1 mm) to below {} (half the mill radius)", 0.5 * radius);
  const auto fits = [&](double d) { return d >= 1e-4 && d < 0.5 * radius; };
  const std::string choices =
      "one of ball_diameter (one size), top_size (a graded charge) or sizes (a list)";
  std::vector<std::string_view> given;
  for (const std::string_view key : {"ball_diameter", "top_size", "sizes"}) {
    if (section.has(key)) given.push_back(key);
  }
  if (given.empty()) section.fail_missing("ball_diameter", choices);
  if (given.size() > 1) {
    section.fail_at(given[1], fmt::format("given as well as charge.{} ({}); allowed: {}, not "
                                          "several",
                                          given[0], section.location(given[0]), choices));
  }
  if (section.has("ball_diameter")) {
    config.sizes = {{section.number("ball_diameter", std::nullopt, size_rule, fits), 1.0}};
    config.size_description = fmt::format("single size {} m", config.sizes[0].diameter);
  } else if (section.has("top_size")) {
    // Its smallest class is 0.8³ = 0.512 of it (graded_charge), and at least 0.1 mm too.
    constexpr double smallest_class = 0.512;
    constexpr double least_top = 0.0001953125;  // 1e-4 / 0.512
    const double top = section.number(
        "top_size", std::nullopt,
        fmt::format("a number of metres from {} (whose smallest class, {} of it, is 0.1 mm) to "
                    "below {} (half the mill radius)",
                    least_top, smallest_class, 0.5 * radius),
        [&](double d) { return d >= least_top && d < 0.5 * radius; });
    config.sizes = graded_charge(top);
    config.size_description = fmt::format("graded, top size {} m (Bond equilibrium charge)", top);
  } else {
    const toml::node* list = section.node("sizes");
    const std::string list_rule =
        "a non-empty array of tables {diameter = metres, mass_fraction = 0..1} whose fractions "
        "sum to 1";
    if (!list->is_array() || list->as_array()->empty()) {
      section.fail_at("sizes", fmt::format("{} is not allowed; allowed: {}",
                                           list->is_array() ? std::string("an empty array")
                                                            : describe_value(*list),
                                           list_rule));
    }
    double total = 0.0;
    int index = 0;
    for (const toml::node& entry : *list->as_array()) {
      const std::string name = fmt::format("{}[{}]", section.dotted("sizes"), index++);
      if (!entry.is_table()) {
        section.fail_at_node(entry, name,
                             fmt::format("{} is not allowed; allowed: a table {{diameter = "
                                         "metres, mass_fraction = 0..1}}",
                                         describe_value(entry)));
      }
      TableReader size(*entry.as_table(), name, section.file());
      size.allow_keys({"diameter", "mass_fraction"});
      SizeClass c;
      c.diameter = size.number("diameter", std::nullopt, size_rule, fits);
      c.mass_fraction = size.number("mass_fraction", std::nullopt, "a number > 0 and <= 1",
                                    [](double f) { return f > 0.0 && f <= 1.0; });
      total += c.mass_fraction;
      config.sizes.push_back(c);
    }
    if (std::abs(total - 1.0) > 1e-3) {
      section.fail_at("sizes", fmt::format("the mass fractions sum to {:.4g}; allowed: mass "
                                           "fractions that sum to 1 (within 0.001)",
                                           total));
    }
    config.size_description = config.sizes.size() == 1
                                  ? std::string("one size given")
                                  : fmt::format("{} sizes given", config.sizes.size());
  }
}

void read_charge(TableReader section, MillConfig& config) {
  section.allow_keys({"filling", "porosity", "density", "ball_diameter", "top_size", "sizes"},
                     belongs_elsewhere);
  config.filling =
      section.number("filling", std::nullopt, "a fraction of the mill volume > 0 and < 1",
                     [](double j) { return j > 0.0 && j < 1.0; });
  config.porosity = section.number("porosity", 0.4, "a fraction >= 0 and < 1",
                                   [](double p) { return p >= 0.0 && p < 1.0; });
  // Solids: from cork to the densest metals, with room either side.
  config.density = section.number("density", 7800.0, "a number of kg/m3 from 10 to 1e5",
                                  [](double rho) { return rho >= 10.0 && rho <= 1e5; });
  read_sizes(section, config);
}

}  // namespace

namespace config_detail {

ContactMaterial read_material(TableReader section) {
  // Wide enough for any solid's contact, narrow enough that a contact lasts a finite time.
  const std::string stiffness_rule = "a number of N/m from 1 to 1e12";
  const auto stiffness_range = [](double k) { return k >= 1.0 && k <= 1e12; };
  section.allow_keys({"normal_stiffness", "tangential_stiffness", "restitution", "friction"},
                     belongs_elsewhere);
  ContactMaterial m;
  m.normal_stiffness =
      section.number("normal_stiffness", m.normal_stiffness, stiffness_rule, stiffness_range);
  // MODEL.md §3's default: 2/3 of the normal stiffness, whichever that is.
  m.tangential_stiffness =
      section.number("tangential_stiffness", default_tangential_share * m.normal_stiffness,
                     stiffness_rule, stiffness_range);
  m.restitution = section.number("restitution", m.restitution, "a number > 0 and <= 1",
                                 [](double e) { return e > 0.0 && e <= 1.0; });
  m.friction = section.number("friction", m.friction, "a number >= 0 and <= 10",
                              [](double mu) { return mu >= 0.0 && mu <= 10.0; });
  return m;
}

std::string read_output_directory(TableReader& section) {
  const std::string directory_rule = "a directory path (a non-empty string)";
  std::string directory = section.string("directory", "out", directory_rule);
  if (directory.find('\0') != std::string::npos) {
    section.fail_at(
        "directory",
        fmt::format("a NUL character is not allowed in a path; allowed: {}", directory_rule));
  }
  if (directory.empty()) {
    section.fail_at("directory",
                    fmt::format("an empty path is not allowed; allowed: {}", directory_rule));
  }
  return directory;
}

}  // namespace config_detail

namespace {

void read_output(TableReader section, MillConfig& config) {
  section.allow_keys({"directory", "snapshot_interval", "snapshot_format"}, belongs_elsewhere);
  config.output_directory = read_output_directory(section);
  config.snapshot_interval =
      section.number("snapshot_interval", 0.05, "a number of seconds >= 0 (0 = no snapshots)",
                     [](double t) { return t >= 0.0; });
  constexpr std::string_view format_rule =
      "\"csv\" (a table a snapshot), \"vtk\" (VTK files and a ParaView collection) or \"both\"";
  const std::string format = section.string("snapshot_format", "csv", format_rule);
  if (format != "csv" && format != "vtk" && format != "both") {
    section.fail_at("snapshot_format", fmt::format("\"{}\" is not a snapshot format; allowed: {}",
                                                   format, format_rule));
  }
  config.snapshot_csv = format != "vtk";
  config.snapshot_vtk = format != "csv";
}

void read_reference(TableReader section, MillConfig& config) {
  section.allow_keys({"case", "measured_power_kw", "paper_power_kw", "tolerance"},
                     belongs_elsewhere);
  ReferencePower r;
  r.case_name = section.string("case", std::nullopt, "the case name (a string)");
  if (r.case_name.find_first_not_of(" \t\n\v\f\r") == std::string::npos) {
    // It names the case's row of validate's table. (Quoted with its escapes: a tab as \t.)
    section.fail_at("case", fmt::format("{:?} is not allowed; allowed: the case name, a string "
                                        "with more than blanks (e.g. \"2D-a\")",
                                        r.case_name));
  }
  r.measured_kw = section.number("measured_power_kw", std::nullopt, "a number of kW > 0", positive);
  r.paper_kw = section.optional_number("paper_power_kw", "a number of kW > 0", positive);
  r.tolerance = section.number("tolerance", 0.15, "a fraction > 0, at most 1 (100 %)",
                               [](double t) { return t > 0.0 && t <= 1.0; });
  config.reference = r;
}

}  // namespace

std::vector<SizeClass> graded_charge(double top_size) {
  // Bond (1958): in a mill at equilibrium, the mass fraction of balls below size d is
  // (d / top)^3.84. Four classes at top × 0.8^k; each takes the mass between its size and the
  // next smaller one, the smallest takes the rest.
  constexpr double ratio = 0.8;
  constexpr double exponent = 3.84;
  constexpr int classes = 4;
  std::vector<SizeClass> sizes;
  for (int k = 0; k < classes; ++k) {
    const double upper = std::pow(ratio, k);
    const double lower = k + 1 < classes ? std::pow(ratio, k + 1) : 0.0;
    sizes.push_back({top_size * upper, std::pow(upper, exponent) - std::pow(lower, exponent)});
  }
  return sizes;
}

std::string MillConfig::location_of(std::string_view dotted_key) const {
  const auto found = key_locations.find(dotted_key);
  // A key left at its default has no line: the message says so, lest the file be searched.
  return found != key_locations.end() ? found->second : source + " (not given: its default)";
}

namespace {

/// The TOML document of a config, with the overrides applied.
toml::table parse_document(std::string_view toml_text, const std::string& source,
                           const std::vector<std::string>& overrides) {
  if (const auto line = line_of_overlong_key(toml_text)) {
    throw InputError(fmt::format(
        "{}:{}: a dotted key or table name of more than {} parts; allowed: at most {} parts, as "
        "in mill.lifters.count",
        source, *line, max_key_parts, max_key_parts));
  }
  toml::table document;
  try {
    document = toml::parse(toml_text, std::string_view(source));
  } catch (const toml::parse_error& error) {
    throw InputError(fmt::format(
        "{}:{}: not valid TOML (column {}): {}; allowed: TOML syntax "
        "(https://toml.io), as in examples/lab-mill-2d.toml",
        source, error.source().begin.line, error.source().begin.column, error.description()));
  }
  // The keys of which a mill config gives one: a --set of one replaces the file's other.
  static const std::vector<std::vector<std::string_view>> alternatives = {
      {"mill.speed", "mill.speed_rpm"},
      {"charge.ball_diameter", "charge.top_size", "charge.sizes"}};
  apply_overrides(document, overrides, alternatives);
  return document;
}

MillConfig read_mill_config(const toml::table& document, const std::string& source) {
  MillConfig config;
  config.source = source;
  TableReader root(document, "", source, &config.key_locations);
  root.allow_keys(config_detail::mill_tables, [](std::string_view key) -> std::string {
    if (key == "particles" || key == "walls") {
      return "a scene's table; a scene config has no [mill]";
    }
    return belongs_elsewhere(key);
  });
  read_simulation(root.table("simulation", false), config);
  read_mill(root.table("mill", true,
                       "a table [mill] with diameter, length and speed or speed_rpm "
                       "([mill.lifters] optional)"),
            config);
  read_charge(root.table("charge", true,
                         "a table [charge] with filling and one of ball_diameter, top_size or "
                         "sizes"),
              config);
  TableReader materials = root.table("materials", false);
  materials.allow_keys({"ball_ball", "ball_wall"}, belongs_elsewhere);
  config.ball_ball = read_material(materials.table("ball_ball", false));
  config.ball_wall = read_material(materials.table("ball_wall", false));
  read_output(root.table("output", false), config);
  if (root.has("reference")) read_reference(root.table("reference", false), config);
  return config;
}

/// A config is a few kilobytes; a scene listing its particles one by one, some megabytes. A file
/// far larger is not a config (and toml++ would hold all of it, and more, in memory).
constexpr std::uintmax_t max_config_bytes = std::uintmax_t{64} << 20;

std::string read_config_file(const std::string& path) {
  const std::string allowed =
      "the path of a mill config file (TOML), e.g. examples/lab-mill-2d.toml";
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (!std::filesystem::exists(status)) {
    throw InputError(fmt::format("{}: no such config file; allowed: {}", path, allowed));
  }
  if (std::filesystem::is_directory(status)) {
    throw InputError(
        fmt::format("{}: is a directory, not a config file; allowed: {}", path, allowed));
  }
  // A pipe or device would be read until it ends, which it may never do (a FIFO with no writer
  // blocks; /dev/zero fills the memory).
  if (!std::filesystem::is_regular_file(status)) {
    throw InputError(fmt::format(
        "{}: is not a regular file (a device, pipe or socket); allowed: {}", path, allowed));
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (!error && size > max_config_bytes) {
    throw InputError(fmt::format("{}: is {} bytes long; allowed: {}, at most {} MiB", path, size,
                                 allowed, max_config_bytes >> 20));
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw InputError(fmt::format("{}: cannot open the config file ({}); allowed: {}", path,
                                 std::strerror(errno), allowed));
  }
  std::ostringstream text;
  text << file.rdbuf();
  if (file.bad()) {
    throw InputError(fmt::format("{}: cannot read the config file; allowed: {}", path, allowed));
  }
  return text.str();
}

/// The names of `mill`, then those of `scene` that `mill` does not have.
std::vector<std::string_view> either_kind(std::span<const std::string_view> mill,
                                          std::span<const std::string_view> scene) {
  std::vector<std::string_view> names(mill.begin(), mill.end());
  for (const std::string_view name : scene) {
    if (std::find(mill.begin(), mill.end(), name) == mill.end()) names.push_back(name);
  }
  return names;
}

/// The first key of `table` not among `names`, with its node (in toml++'s order, by name: of
/// several, not necessarily the first in the file).
std::optional<std::pair<std::string, const toml::node*>> first_unknown(
    const toml::table& table, std::span<const std::string_view> names) {
  for (const auto& [key, node] : table) {
    if (std::find(names.begin(), names.end(), key.str()) == names.end()) {
      return std::pair<std::string, const toml::node*>(std::string(key.str()), &node);
    }
  }
  return std::nullopt;
}

bool is_scene(const toml::table& document) {
  return !document.contains("mill");
}

}  // namespace

MillConfig parse_mill_config(std::string_view toml_text, const std::string& source,
                             const std::vector<std::string>& overrides) {
  const toml::table document = parse_document(toml_text, source, overrides);
  if (is_scene(document) && document.contains("particles")) {
    throw InputError(fmt::format(
        "{}: mill: missing required table [mill]: this is a scene config ([[particles]], no "
        "[mill]); allowed: a mill config here (millsim run and info take scenes; sweep and "
        "validate need a mill)",
        source));
  }
  return read_mill_config(document, source);
}

MillConfig load_mill_config(const std::string& path, const std::vector<std::string>& overrides) {
  return parse_mill_config(read_config_file(path), path, overrides);
}

JobConfig parse_config(std::string_view toml_text, const std::string& source,
                       const std::vector<std::string>& overrides) {
  const toml::table document = parse_document(toml_text, source, overrides);
  if (is_scene(document) && (document.contains("particles") || document.contains("walls"))) {
    return read_scene_config(document, source);
  }
  if (is_scene(document)) {
    // Neither kind: say so before any key of [simulation] is judged by the wrong kind's rules,
    // naming first a top-level name that neither kind has ("[[particle]]" for "[[particles]]").
    using config_detail::mill_simulation_keys;
    using config_detail::scene_simulation_keys;
    const std::vector<std::string_view> tables =
        either_kind(config_detail::mill_tables, config_detail::scene_tables);
    if (const auto unknown = first_unknown(document, tables)) {
      const auto near = closest_key(unknown->first, tables);
      throw InputError(fmt::format(
          "{}: {}: unknown table{}, and the config has neither [mill] nor [[particles]]; "
          "allowed at the top level: {}",
          source_location(*unknown->second, source), unknown->first,
          near ? fmt::format(" (did you mean {}?)", *near) : std::string(),
          fmt::join(tables, ", ")));
    }
    // Then a [simulation] key that neither kind has ("particles = 5"), with its line: a user
    // who added [mill] would be told of it next.
    const std::vector<std::string_view> keys =
        either_kind(mill_simulation_keys, scene_simulation_keys);
    const toml::table* simulation = document["simulation"].as_table();
    if (const auto unknown = simulation ? first_unknown(*simulation, keys) : std::nullopt) {
      const auto near = closest_key(unknown->first, keys);
      throw InputError(fmt::format(
          "{}: simulation.{}: unknown key{}, and the config has neither [mill] nor "
          "[[particles]]; allowed in [simulation]: {} (a mill) or {} (a scene)",
          source_location(*unknown->second, source), unknown->first,
          near ? fmt::format(" (did you mean {}?)", *near) : std::string(),
          fmt::join(mill_simulation_keys, ", "), fmt::join(scene_simulation_keys, ", ")));
    }
    throw InputError(fmt::format(
        "{}: mill: missing required table [mill], and no [[particles]] either; allowed: a mill "
        "(a table [mill] with diameter, length and speed or speed_rpm, and [charge]) or a scene "
        "([[particles]] and [[walls]], no [mill]; README, \"Scenes\")",
        source));
  }
  return read_mill_config(document, source);
}

JobConfig load_config(const std::string& path, const std::vector<std::string>& overrides) {
  return parse_config(read_config_file(path), path, overrides);
}

}  // namespace millsim
