#include "millsim/io/config.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <utility>

#include "millsim/core/constants.hpp"
#include "millsim/core/error.hpp"
#include "millsim/io/toml_reader.hpp"

namespace millsim {
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
       {"dimension", "time_step", "settle_time", "revolutions", "measure_revolutions", "seed"}},
      {"mill",
       {"diameter", "length", "speed", "speed_rpm", "periodic", "slab_length", "cone_angle",
        "cone_length", "lifters"}},
      {"mill.lifters", {"count", "height", "width"}},
      {"charge", {"filling", "porosity", "density", "ball_diameter", "top_size", "sizes"}},
      {"materials", {"ball_ball", "ball_wall"}},
      {"materials.ball_ball] or [materials.ball_wall",
       {"normal_stiffness", "tangential_stiffness", "restitution", "friction"}},
      {"output", {"directory", "snapshot_interval"}},
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

/// simulation.time_step: "auto" (empty) or a number of seconds > 0.
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

void read_simulation(TableReader section, MillConfig& config) {
  section.allow_keys(
      {"dimension", "time_step", "settle_time", "revolutions", "measure_revolutions", "seed"},
      belongs_elsewhere);
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
  const double inner_circumference = 2.0 * pi * (radius - config.lifter_height);
  const double widest = inner_circumference / config.lifter_count;
  config.lifter_width = lifters.number(
      "width", std::nullopt,
      fmt::format("a number of metres > 0 and < {:.4g} (wider, {} lifters {} m high would "
                  "overlap at their inner faces)",
                  widest, config.lifter_count, config.lifter_height),
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
      fmt::format("a number of metres > 0 and < {:.4g} (longer, a cone at {} degrees from a mill "
                  "of {} m diameter would reach the axis)",
                  longest, config.cone_angle_degrees, config.diameter),
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
  const std::string rpm_rule = "a number of rpm > 0";
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
    const double top = section.number("top_size", std::nullopt, size_rule, fits);
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
    config.size_description = fmt::format("{} sizes given", config.sizes.size());
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

/// output.directory: a non-empty path, default "out".
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

void read_output(TableReader section, MillConfig& config) {
  section.allow_keys({"directory", "snapshot_interval"}, belongs_elsewhere);
  config.output_directory = read_output_directory(section);
  config.snapshot_interval =
      section.number("snapshot_interval", 0.05, "a number of seconds >= 0 (0 = no snapshots)",
                     [](double t) { return t >= 0.0; });
}

void read_reference(TableReader section, MillConfig& config) {
  section.allow_keys({"case", "measured_power_kw", "paper_power_kw", "tolerance"},
                     belongs_elsewhere);
  ReferencePower r;
  r.case_name = section.string("case", std::nullopt, "the case name (a string)");
  if (r.case_name.find_first_not_of(" \t") == std::string::npos) {
    // It names the case's row of validate's table.
    section.fail_at("case", fmt::format("\"{}\" is not allowed; allowed: the case name, a string "
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
  return found != key_locations.end() ? found->second : source;
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
  root.allow_keys({"simulation", "mill", "charge", "materials", "output", "reference"},
                  [](std::string_view key) -> std::string {
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

// ---- scenes ----

std::string scene_hint(std::string_view key) {
  static constexpr std::string_view mill_only[] = {
      "settle_time", "revolutions", "measure_revolutions", "seed",
      "mill",        "charge",      "reference",           "snapshot_interval",
  };
  if (std::find(std::begin(mill_only), std::end(mill_only), key) != std::end(mill_only)) {
    return "a mill key; a scene (a config without [mill]) does not use it";
  }
  return {};
}

/// "[x, y]" or "[x, y, z]" with the given names, for messages.
std::string vector_rule(int dimension, std::string_view what) {
  return dimension == 2 ? fmt::format("an array [x, y] of two numbers ({})", what)
                        : fmt::format("an array [x, y, z] of three numbers ({})", what);
}

/// A vector of `dimension` numbers, each within ±limit (so that squares and energies made of
/// them stay finite).
std::array<double, 3> read_vector(TableReader& table, std::string_view key, int dimension,
                                  std::string_view what, bool required, double limit) {
  std::optional<std::vector<double>> fallback;
  if (!required) fallback = std::vector<double>(static_cast<std::size_t>(dimension), 0.0);
  const std::vector<double> v = table.numbers(key, static_cast<std::size_t>(dimension), fallback,
                                              vector_rule(dimension, what));
  for (const double x : v) {
    if (!(std::abs(x) <= limit)) {
      table.fail_at(key, fmt::format("{} is out of range; allowed: {} with each number within "
                                     "±{:g}",
                                     x, vector_rule(dimension, what), limit));
    }
  }
  std::array<double, 3> out{};
  std::copy(v.begin(), v.end(), out.begin());
  return out;
}

void read_scene_simulation(TableReader section, SceneConfig& config) {
  section.allow_keys({"dimension", "time_step", "duration", "gravity"}, scene_hint);
  config.dimension = static_cast<int>(section.integer("dimension", 2, "2 (discs) or 3 (spheres)",
                                                      [](long d) { return d == 2 || d == 3; }));
  config.time_step = read_time_step(section);
  config.duration = section.number("duration", std::nullopt, "a number of seconds > 0, at most 1e4",
                                   [](double t) { return t > 0.0 && t <= 1e4; });
  std::vector<double> down(static_cast<std::size_t>(config.dimension), 0.0);
  down.back() = -standard_gravity;
  const std::string_view rule = "m/s2; default: -9.81 along the last axis";
  const std::vector<double> g =
      section.numbers("gravity", static_cast<std::size_t>(config.dimension), down,
                      vector_rule(config.dimension, rule));
  // About a thousand g: beyond any drop or impact test, and small enough that the energies of
  // a scene (positions within ±1e6 m, speeds within ±1e4 m/s, at most 1e4 s) stay finite.
  constexpr double most_gravity = 1e4;
  for (const double x : g) {
    if (!(std::abs(x) <= most_gravity)) {
      section.fail_at(
          "gravity", fmt::format("{} is out of range; allowed: {} with each number within ±{:g}", x,
                                 vector_rule(config.dimension, rule), most_gravity));
    }
  }
  std::copy(g.begin(), g.end(), config.gravity.begin());
}

/// The entries of the array of tables `key` ([[particles]]), each with its reader.
template <typename ReadOne>
void read_table_array(TableReader& root, std::string_view key, std::string_view allowed,
                      KeyLocations* locations, ReadOne&& read_one) {
  const toml::node* list = root.node(key);
  if (list == nullptr) return;
  if (!list->is_array()) {
    root.fail_at(key,
                 fmt::format("{} is not allowed; allowed: {}", describe_value(*list), allowed));
  }
  int index = 0;
  for (const toml::node& entry : *list->as_array()) {
    const std::string name = fmt::format("{}[{}]", key, index++);
    if (!entry.is_table()) {
      root.fail_at_node(
          entry, name,
          fmt::format("{} is not allowed; allowed: {}", describe_value(entry), allowed));
    }
    read_one(TableReader(*entry.as_table(), name, root.file(), locations));
  }
}

SceneParticle read_scene_particle(TableReader p, int dimension) {
  p.allow_keys({"position", "velocity", "angular_velocity", "diameter", "density", "material"});
  SceneParticle particle;
  particle.position = read_vector(p, "position", dimension, "m", true, 1e6);
  particle.velocity = read_vector(p, "velocity", dimension, "m/s; default [0, 0...]", false, 1e4);
  if (dimension == 2) {
    particle.angular_velocity[0] = p.number("angular_velocity", 0.0,
                                            "a number of rad/s within ±1e6 (the spin of a disc "
                                            "about the out-of-plane axis, counter-clockwise "
                                            "positive)",
                                            [](double w) { return std::abs(w) <= 1e6; });
  } else {
    particle.angular_velocity =
        read_vector(p, "angular_velocity", 3, "rad/s; default [0, 0, 0]", false, 1e6);
  }
  // At least 0.1 mm: a particle of 1e-300 m has a mass of 0 in doubles, and no contact
  // duration.
  particle.diameter = p.number("diameter", std::nullopt, "a number of metres from 0.0001 to 100",
                               [](double d) { return d >= 1e-4 && d <= 100.0; });
  particle.density = p.number("density", 7800.0, "a number of kg/m3 from 10 to 1e5 (default 7800)",
                              [](double rho) { return rho >= 10.0 && rho <= 1e5; });
  const std::string material = p.string(
      "material", "ball",
      "\"ball\" (the particle material of [materials.ball_ball] and [materials.ball_wall])");
  if (material != "ball") {
    p.fail_at("material",
              fmt::format("\"{}\" is not a material of this config; allowed: \"ball\" (the "
                          "particle material of [materials.ball_ball] and [materials.ball_wall])",
                          material));
  }
  return particle;
}

SceneWall read_scene_wall(TableReader w, int dimension) {
  w.allow_keys({"point", "normal"});
  SceneWall wall;
  wall.point = read_vector(w, "point", dimension, "a point of the plane, m", true, 1e6);
  wall.normal =
      read_vector(w, "normal", dimension, "not zero; points to the particles' side", true, 1e6);
  double largest = 0.0;
  for (const double x : wall.normal) largest = std::max(largest, std::abs(x));
  if (!(largest > 0.0)) {
    w.fail_at("normal",
              fmt::format("a zero vector is not allowed; allowed: {}",
                          vector_rule(dimension, "not zero; points to the particles' side")));
  }
  double length = 0.0;
  for (const double x : wall.normal) length += x * x;
  if (!(length > 0.0)) {
    // Components so small that their squares underflow ([1e-200, 1e-200]): scaled up first.
    for (double& x : wall.normal) x /= largest;
    length = 0.0;
    for (const double x : wall.normal) length += x * x;
  }
  length = std::sqrt(length);
  for (double& x : wall.normal) x /= length;
  return wall;
}

/// Refuses particles that start inside a wall or overlapping each other: the incremental
/// springs would start from zero at an overlap and the contact would be wrong.
void check_scene_start(const SceneConfig& config) {
  const std::size_t n = config.particles.size();
  const auto name = [&](std::size_t i) {
    return fmt::format("{}: particles[{}]",
                       config.location_of(fmt::format("particles[{}].position", i)), i);
  };
  constexpr double slack = 1e-9;  // relative to the diameter: touching is allowed
  for (std::size_t i = 0; i < n; ++i) {
    const SceneParticle& p = config.particles[i];
    const double r = 0.5 * p.diameter;
    for (std::size_t k = 0; k < config.walls.size(); ++k) {
      const SceneWall& w = config.walls[k];
      double distance = 0.0;
      for (int a = 0; a < config.dimension; ++a)
        distance += (p.position[a] - w.point[a]) * w.normal[a];
      if (distance < r * (1.0 - 2.0 * slack)) {
        throw InputError(fmt::format(
            "{}: starts {} walls[{}] (its centre is {:.6g} m from the plane, its radius {:.6g} "
            "m); allowed: particles that start clear of every wall or just touching it",
            name(i), distance < 0.0 ? "behind" : "overlapping", k, distance, r));
      }
    }
  }
  // Overlaps between particles: sweep along x.
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return config.particles[a].position[0] < config.particles[b].position[0];
  });
  double largest = 0.0;
  for (const SceneParticle& p : config.particles) largest = std::max(largest, p.diameter);
  for (std::size_t a = 0; a < n; ++a) {
    const SceneParticle& p = config.particles[order[a]];
    for (std::size_t b = a + 1; b < n; ++b) {
      const SceneParticle& q = config.particles[order[b]];
      if (q.position[0] - p.position[0] > largest) break;
      double d2 = 0.0;
      for (int k = 0; k < config.dimension; ++k)
        d2 += (q.position[k] - p.position[k]) * (q.position[k] - p.position[k]);
      const double reach = 0.5 * (p.diameter + q.diameter);
      if (std::sqrt(d2) < reach * (1.0 - 2.0 * slack)) {
        const std::size_t i = std::min(order[a], order[b]);
        const std::size_t j = std::max(order[a], order[b]);
        throw InputError(fmt::format(
            "{} and particles[{}] overlap at the start (centres {:.6g} m apart, radii sum "
            "{:.6g} m); allowed: particles that start apart or just touching",
            name(i), j, std::sqrt(d2), reach));
      }
    }
  }
}

SceneConfig read_scene_config(const toml::table& document, const std::string& source) {
  SceneConfig config;
  config.source = source;
  TableReader root(document, "", source, &config.key_locations);
  root.allow_keys({"simulation", "particles", "walls", "materials", "output"},
                  [](std::string_view key) -> std::string {
                    if (key == "charge" || key == "reference") {
                      return "a mill table; this config has no [mill], so it is a scene";
                    }
                    return {};
                  });
  read_scene_simulation(root.table("simulation", true,
                                   "a table [simulation] with duration (and dimension, "
                                   "time_step, gravity)"),
                        config);
  const int d = config.dimension;
  const std::string particle_rule = fmt::format(
      "an array of tables [[particles]], each with position ({}), diameter, and optionally "
      "velocity, angular_velocity, density, material",
      d == 2 ? "[x, y]" : "[x, y, z]");
  if (!root.has("particles")) root.fail_missing("particles", particle_rule);
  read_table_array(root, "particles", particle_rule, &config.key_locations, [&](TableReader p) {
    config.particles.push_back(read_scene_particle(std::move(p), d));
  });
  if (config.particles.empty()) {
    root.fail_at("particles", fmt::format("no particles; allowed: {}", particle_rule));
  }
  read_table_array(
      root, "walls", "an array of tables [[walls]], each with point and normal (infinite planes)",
      &config.key_locations,
      [&](TableReader w) { config.walls.push_back(read_scene_wall(std::move(w), d)); });
  TableReader materials = root.table("materials", false);
  materials.allow_keys({"ball_ball", "ball_wall"});
  config.ball_ball = read_material(materials.table("ball_ball", false));
  config.ball_wall = read_material(materials.table("ball_wall", false));
  TableReader output = root.table("output", false);
  output.allow_keys({"directory", "trajectory_interval"}, scene_hint);
  config.output_directory = read_output_directory(output);
  config.trajectory_interval =
      output.number("trajectory_interval", 0.0,
                    "a number of seconds >= 0 (0 = only the start and the end in trajectory.csv)",
                    [](double t) { return t >= 0.0; });
  check_scene_start(config);
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

bool is_scene(const toml::table& document) {
  return !document.contains("mill");
}

}  // namespace

std::string SceneConfig::location_of(std::string_view dotted_key) const {
  const auto found = key_locations.find(dotted_key);
  return found != key_locations.end() ? found->second : source;
}

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
    // Neither kind: say so before any key of [simulation] is judged by the wrong kind's rules.
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
