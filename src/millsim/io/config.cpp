#include "millsim/io/config.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "millsim/core/constants.hpp"
#include "millsim/core/error.hpp"
#include "millsim/io/toml_reader.hpp"

namespace millsim {
namespace {

bool positive(double x) {
  return x > 0.0;
}

void read_simulation(TableReader section, MillConfig& config) {
  config.dimension = static_cast<int>(section.integer(
      "dimension", 2, "2 (3D comes in a later version)", [](long d) { return d == 2 || d == 3; }));
  if (config.dimension == 3) {
    section.fail_at("dimension", "3D mills are not available yet in this version; allowed: 2");
  }
  if (const toml::node* step = section.node("time_step")) {
    if (step->is_string()) {
      if (step->as_string()->get() != "auto") {
        section.fail_at("time_step", fmt::format("\"{}\" is not allowed; allowed: \"auto\" or a "
                                                 "number of seconds > 0",
                                                 step->as_string()->get()));
      }
    } else {
      config.time_step = section.number("time_step", std::nullopt,
                                        "\"auto\" or a number of seconds > 0", positive);
    }
  }
  config.settle_time = section.number("settle_time", 1.0, "a number of seconds >= 0",
                                      [](double t) { return t >= 0.0 && t <= 1e4; });
  config.revolutions =
      section.number("revolutions", 6.0, "a number of revolutions > 0, at most 1e5",
                     [](double n) { return n > 0.0 && n <= 1e5; });
  config.measure_revolutions = static_cast<int>(section.integer(
      "measure_revolutions", 4,
      "a whole number of revolutions >= 1, at most simulation.revolutions",
      [&](long n) { return n >= 1 && static_cast<double>(n) <= config.revolutions; }));
  config.seed = static_cast<std::uint64_t>(
      section.integer("seed", 1, "a whole number >= 0", [](long s) { return s >= 0; }));
  section.refuse_unknown_keys(
      "dimension, time_step, settle_time, revolutions, measure_revolutions, seed");
}

void read_mill(TableReader section, MillConfig& config) {
  config.diameter = section.number("diameter", std::nullopt, "a number of metres > 0", positive);
  config.length = section.number("length", std::nullopt, "a number of metres > 0", positive);
  config.speed_fraction =
      section.optional_number("speed", "a fraction of critical speed > 0, at most 5",
                              [](double s) { return s > 0.0 && s <= 5.0; });
  config.speed_rpm = section.optional_number("speed_rpm", "a number of rpm > 0", positive);
  if (config.speed_fraction && config.speed_rpm) {
    section.fail_at("speed_rpm",
                    "give either mill.speed (fraction of critical) or "
                    "mill.speed_rpm, not both");
  }
  if (!config.speed_fraction && !config.speed_rpm) {
    section.fail_missing("speed", "mill.speed (fraction of critical speed) or mill.speed_rpm");
  }
  TableReader lifters = section.table("lifters", false);
  const double radius = 0.5 * config.diameter;
  config.lifter_count = static_cast<int>(lifters.integer(
      "count", 0, "a whole number from 0 to 360", [](long n) { return n >= 0 && n <= 360; }));
  if (config.lifter_count > 0) {
    config.lifter_height = lifters.number(
        "height", std::nullopt, fmt::format("a number of metres > 0 and < {} (the radius)", radius),
        [&](double h) { return h > 0.0 && h < radius; });
    const double inner_circumference = 2.0 * pi * (radius - config.lifter_height);
    const double widest = inner_circumference / config.lifter_count;
    config.lifter_width = lifters.number(
        "width", std::nullopt,
        fmt::format("a number of metres > 0 and < {:.4g} ({} lifters must not touch at their "
                    "faces)",
                    widest, config.lifter_count),
        [&](double w) { return w > 0.0 && w < widest; });
  }
  lifters.refuse_unknown_keys("count, height, width");
  section.refuse_unknown_keys("diameter, length, speed, speed_rpm, lifters");
}

void read_sizes(TableReader& section, MillConfig& config) {
  const double radius = 0.5 * config.diameter;
  const std::string size_rule =
      fmt::format("a number of metres > 0 and < {} (half the mill radius)", 0.5 * radius);
  const auto fits = [&](double d) { return d > 0.0 && d < 0.5 * radius; };
  const int given = (section.has("ball_diameter") ? 1 : 0) + (section.has("top_size") ? 1 : 0) +
                    (section.has("sizes") ? 1 : 0);
  const std::string choices = "one of ball_diameter (one size), top_size (graded) or sizes (list)";
  if (given == 0) section.fail_missing("ball_diameter", choices);
  if (given > 1) {
    section.fail_at(section.has("sizes") ? "sizes" : "top_size",
                    "give " + choices + ", not several");
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
    if (!list->is_array() || list->as_array()->empty())
      section.fail_at("sizes", "expected " + list_rule);
    double total = 0.0;
    int index = 0;
    for (const toml::node& entry : *list->as_array()) {
      if (!entry.is_table()) section.fail_at("sizes", "expected " + list_rule);
      TableReader size(*entry.as_table(), fmt::format("{}.sizes[{}]", section.path(), index++),
                       section.file());
      SizeClass c;
      c.diameter = size.number("diameter", std::nullopt, size_rule, fits);
      c.mass_fraction = size.number("mass_fraction", std::nullopt, "a number > 0 and <= 1",
                                    [](double f) { return f > 0.0 && f <= 1.0; });
      size.refuse_unknown_keys("diameter, mass_fraction");
      total += c.mass_fraction;
      config.sizes.push_back(c);
    }
    if (std::abs(total - 1.0) > 1e-3) {
      section.fail_at("sizes",
                      fmt::format("mass fractions sum to {:.4g}; they must sum to 1", total));
    }
    config.size_description = fmt::format("{} sizes given", config.sizes.size());
  }
}

void read_charge(TableReader section, MillConfig& config) {
  config.filling = section.number("filling", std::nullopt, "a fraction > 0 and < 1",
                                  [](double j) { return j > 0.0 && j < 1.0; });
  config.porosity = section.number("porosity", 0.4, "a fraction >= 0 and < 1",
                                   [](double p) { return p >= 0.0 && p < 1.0; });
  config.density = section.number("density", 7800.0, "a number of kg/m3 > 0", positive);
  read_sizes(section, config);
  section.refuse_unknown_keys("filling, porosity, density, ball_diameter, top_size, sizes");
}

ContactMaterial read_material(TableReader section) {
  ContactMaterial m;
  m.normal_stiffness =
      section.number("normal_stiffness", m.normal_stiffness, "a number of N/m > 0", positive);
  m.tangential_stiffness = section.number("tangential_stiffness", m.tangential_stiffness,
                                          "a number of N/m > 0", positive);
  m.restitution = section.number("restitution", m.restitution, "a number > 0 and <= 1",
                                 [](double e) { return e > 0.0 && e <= 1.0; });
  m.friction = section.number("friction", m.friction, "a number >= 0 and <= 10",
                              [](double mu) { return mu >= 0.0 && mu <= 10.0; });
  section.refuse_unknown_keys("normal_stiffness, tangential_stiffness, restitution, friction");
  return m;
}

void read_output(TableReader section, MillConfig& config) {
  config.output_directory = section.string("directory", "out", "a directory path (string)");
  if (config.output_directory.empty()) section.fail_at("directory", "must not be empty");
  config.snapshot_interval =
      section.number("snapshot_interval", 0.05, "a number of seconds >= 0 (0 = no snapshots)",
                     [](double t) { return t >= 0.0; });
  section.refuse_unknown_keys("directory, snapshot_interval");
}

void read_reference(TableReader section, MillConfig& config) {
  ReferencePower r;
  r.case_name = section.string("case", std::nullopt, "the case name (string)");
  r.measured_kw = section.number("measured_power_kw", std::nullopt, "a number of kW > 0", positive);
  r.paper_kw = section.optional_number("paper_power_kw", "a number of kW > 0", positive);
  r.tolerance = section.number("tolerance", 0.15, "a fraction > 0", positive);
  section.refuse_unknown_keys("case, measured_power_kw, paper_power_kw, tolerance");
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

MillConfig parse_mill_config(std::string_view toml_text, const std::string& source,
                             const std::vector<std::string>& overrides) {
  toml::table document;
  try {
    document = toml::parse(toml_text, std::string_view(source));
  } catch (const toml::parse_error& error) {
    throw InputError(fmt::format("{}:{}: not valid TOML: {}", source, error.source().begin.line,
                                 error.description()));
  }
  apply_overrides(document, overrides);

  MillConfig config;
  config.source = source;
  TableReader root(document, "", source);
  read_simulation(root.table("simulation", false), config);
  read_mill(root.table("mill", true), config);
  read_charge(root.table("charge", true), config);
  TableReader materials = root.table("materials", false);
  config.ball_ball = read_material(materials.table("ball_ball", false));
  config.ball_wall = read_material(materials.table("ball_wall", false));
  materials.refuse_unknown_keys("ball_ball, ball_wall");
  read_output(root.table("output", false), config);
  if (root.has("reference")) read_reference(root.table("reference", false), config);
  root.refuse_unknown_keys("simulation, mill, charge, materials, output, reference");
  return config;
}

MillConfig load_mill_config(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream file(path);
  if (!file) throw InputError(fmt::format("{}: cannot open the config file", path));
  std::ostringstream text;
  text << file.rdbuf();
  return parse_mill_config(text.str(), path, overrides);
}

}  // namespace millsim
