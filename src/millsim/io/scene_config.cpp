// Reading a scene config: particles and walls with no mill ([[particles]], [[walls]]), each value
// checked as a mill's are (toml_reader.hpp), and the particles' start checked against the walls
// and each other.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "millsim/core/constants.hpp"
#include "millsim/core/error.hpp"
#include "millsim/io/config.hpp"
#include "millsim/io/config_detail.hpp"
#include "millsim/io/toml_reader.hpp"

namespace millsim {
namespace config_detail {
namespace {

std::string scene_hint(std::string_view key) {
  static constexpr std::string_view mill_only[] = {
      "settle_time", "revolutions",       "measure_revolutions", "seed", "mill", "charge",
      "reference",   "snapshot_interval", "snapshot_format",
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
  section.allow_keys(scene_simulation_keys, scene_hint);
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

}  // namespace

SceneConfig read_scene_config(const toml::table& document, const std::string& source) {
  SceneConfig config;
  config.source = source;
  TableReader root(document, "", source, &config.key_locations);
  root.allow_keys(scene_tables, [](std::string_view key) -> std::string {
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

}  // namespace config_detail

std::string SceneConfig::location_of(std::string_view dotted_key) const {
  const auto found = key_locations.find(dotted_key);
  // A key left at its default has no line: the message says so, lest the file be searched.
  return found != key_locations.end() ? found->second : source + " (not given: its default)";
}

}  // namespace millsim
