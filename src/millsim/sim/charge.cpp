#include "millsim/sim/charge.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "millsim/core/constants.hpp"
#include "millsim/core/error.hpp"

namespace millsim {
namespace {

double sphere_mass(double diameter, double density) {
  return density * pi / 6.0 * diameter * diameter * diameter;
}

/// True when a disc at `centre` lies inside the shell and clear of every lifter.
bool clear_of_walls(const Mill2D& mill, const Vec2& centre, double radius) {
  WallContact<2> found[4];
  // A small margin so that no disc starts touching a wall.
  return mill_contacts(mill, centre, radius * 1.02, found) == 0;
}

}  // namespace

MillPlan plan_mill(const MillConfig& config) {
  MillPlan plan;
  plan.config = config;
  plan.radius = 0.5 * config.diameter;
  for (const SizeClass& s : config.sizes)
    plan.largest_ball = std::max(plan.largest_ball, s.diameter);
  // N_c = (1 / 2π) sqrt(2 g / (D − d)) rev/s (MODEL.md §1).
  plan.critical_speed_rpm =
      60.0 / (2.0 * pi) * std::sqrt(2.0 * standard_gravity / (config.diameter - plan.largest_ball));
  if (config.speed_fraction) {
    plan.speed_fraction = *config.speed_fraction;
    plan.speed_rpm = plan.speed_fraction * plan.critical_speed_rpm;
  } else {
    plan.speed_rpm = *config.speed_rpm;
    plan.speed_fraction = plan.speed_rpm / plan.critical_speed_rpm;
  }
  plan.angular_speed = plan.speed_rpm * 2.0 * pi / 60.0;
  plan.revolution_period = 60.0 / plan.speed_rpm;

  // Discs: the bed fills J of the slice with a 2D void fraction; each size class takes its
  // mass fraction of the disc area (a section through a 3D charge shows each size with its
  // volume fraction).
  const double slice_area = pi * plan.radius * plan.radius;
  const double disc_area = config.filling * slice_area * (1.0 - disc_bed_porosity);
  for (const SizeClass& s : config.sizes) {
    DiscClass c;
    c.diameter = s.diameter;
    c.mass = sphere_mass(s.diameter, config.density);
    const double one = pi / 4.0 * s.diameter * s.diameter;
    c.count = std::max(1, static_cast<int>(std::lround(s.mass_fraction * disc_area / one)));
    plan.particle_count += c.count;
    plan.slice_mass += c.count * c.mass;
    plan.discs.push_back(c);
  }
  std::sort(plan.discs.begin(), plan.discs.end(),
            [](const DiscClass& a, const DiscClass& b) { return a.diameter > b.diameter; });
  plan.mill_charge_mass =
      config.density * (1.0 - config.porosity) * config.filling * slice_area * config.length;
  plan.power_scale = plan.mill_charge_mass / plan.slice_mass;

  // Time step from the lightest contacts: two of the smallest discs, and one against a wall.
  const double lightest = plan.discs.back().mass;
  const double pair_mass = reduced_mass(lightest, lightest);
  plan.contact_duration_ball_ball = contact_duration(config.ball_ball, pair_mass);
  plan.contact_duration_ball_wall = contact_duration(config.ball_wall, lightest);
  constexpr double disc_inertia = 0.5;
  plan.critical_time_step = std::min(
      critical_time_step(config.ball_ball, pair_mass,
                         tangential_mass(lightest, lightest, disc_inertia)),
      critical_time_step(config.ball_wall, lightest, tangential_mass(lightest, 0.0, disc_inertia)));
  const double accurate =
      std::min(plan.contact_duration_ball_ball, plan.contact_duration_ball_wall) /
      steps_per_contact;
  if (config.time_step) {
    if (*config.time_step >= plan.critical_time_step) {
      throw InputError(fmt::format(
          "{}: simulation.time_step: {:.4g} s is unstable for these materials and balls (the "
          "stability limit is {:.4g} s; for accuracy about {:.3g} s, 1/{} of the shortest "
          "contact); allowed: \"auto\" or a number of seconds below {:.4g}",
          config.location_of("simulation.time_step"), *config.time_step, plan.critical_time_step,
          accurate, steps_per_contact, plan.critical_time_step));
    }
    plan.time_step = *config.time_step;
  } else {
    plan.time_step = accurate;
  }
  plan.total_time = config.settle_time + config.revolutions * plan.revolution_period;
  return plan;
}

World<2> build_mill_world(const MillPlan& plan) {
  const MillConfig& config = plan.config;
  WorldSettings<2> settings;
  settings.time_step = plan.time_step;
  settings.gravity = Vec2{{0.0, -standard_gravity}};
  settings.ball_ball = config.ball_ball;
  settings.ball_wall = config.ball_wall;
  Walls<2> walls;
  Mill2D mill;
  mill.radius = plan.radius;
  mill.lifter_count = config.lifter_count;
  mill.lifter_height = config.lifter_height;
  mill.lifter_width = config.lifter_width;
  mill.turn_to(0.0);
  walls.mill = mill;
  World<2> world(settings, walls);

  // Random sequential placement, largest first, checked against a grid of cells one largest
  // diameter wide.
  std::mt19937_64 random(config.seed);
  std::uniform_real_distribution<double> uniform(-plan.radius, plan.radius);
  const double cell = plan.largest_ball;
  const int cells = static_cast<int>(std::ceil(2.0 * plan.radius / cell)) + 1;
  std::vector<std::vector<std::size_t>> grid(static_cast<std::size_t>(cells * cells));
  const auto cell_of = [&](double coordinate) {
    return std::clamp(static_cast<int>((coordinate + plan.radius) / cell), 0, cells - 1);
  };
  auto& particles = world.particles();
  constexpr long attempts_per_disc = 200000;
  for (const DiscClass& c : plan.discs) {
    const double r = 0.5 * c.diameter;
    for (int n = 0; n < c.count; ++n) {
      bool placed = false;
      for (long attempt = 0; attempt < attempts_per_disc && !placed; ++attempt) {
        const Vec2 at{{uniform(random), uniform(random)}};
        if (!clear_of_walls(mill, at, r)) continue;
        const int cx = cell_of(at[0]);
        const int cy = cell_of(at[1]);
        bool free = true;
        for (int gx = std::max(0, cx - 1); gx <= std::min(cells - 1, cx + 1) && free; ++gx) {
          for (int gy = std::max(0, cy - 1); gy <= std::min(cells - 1, cy + 1) && free; ++gy) {
            for (const std::size_t other : grid[static_cast<std::size_t>(gx * cells + gy)]) {
              const double reach = 1.01 * (r + particles.radius[other]);
              if (norm_squared(particles.position[other] - at) < reach * reach) {
                free = false;
                break;
              }
            }
          }
        }
        if (!free) continue;
        grid[static_cast<std::size_t>(cx * cells + cy)].push_back(particles.add(at, r, c.mass));
        placed = true;
      }
      if (!placed) {
        throw InputError(fmt::format(
            "{}: charge.filling: could not place {} discs of {} m without overlap in the mill "
            "(placed {}); lower the filling or use smaller balls",
            config.location_of("charge.filling"), plan.particle_count, c.diameter,
            particles.size()));
      }
    }
  }
  return world;
}

}  // namespace millsim
