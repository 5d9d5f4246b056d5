#include "millsim/sim/charge.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <utility>

#include "millsim/core/constants.hpp"
#include "millsim/core/error.hpp"

namespace millsim {
namespace {

/// The fastest mill: 5 times critical, as mill.speed allows.
constexpr double most_speed_fraction = 5.0;
/// The largest charge planned: 5e7 balls, about 55 GB at the 1.1 kB a ball the scaling
/// benchmark measures (bench/results.md); far beyond it a count would also overflow an int.
constexpr double most_particles = 5e7;
/// The longest run: 1e10 steps, as for scenes (a thousand balls at 3e7 particle-steps a second
/// would take four days).
constexpr double most_steps = 1e10;

double sphere_mass(double diameter, double density) {
  return density * pi / 6.0 * diameter * diameter * diameter;
}

/// True when a ball at `centre` lies inside the shell and clear of every lifter (and end
/// plate).
template <int D>
bool clear_of_walls(const MillShape<D>& mill, const Vec<D>& centre, double radius) {
  WallContact<D> found[max_mill_contacts<D>];
  // A small margin so that no ball starts touching a wall.
  return mill_contacts(mill, centre, radius * 1.02, found) == 0;
}

}  // namespace

double circle_area_below(double radius, double level) {
  if (level <= -radius) return 0.0;
  if (level >= radius) return pi * radius * radius;
  // The segment below a chord at `level`: r² acos(−y/r) + y sqrt(r² − y²).
  return radius * radius * std::acos(-level / radius) +
         level * std::sqrt(radius * radius - level * level);
}

double cone_bed_volume(double radius, double trunnion_radius, double cone_length, double filling) {
  // The bed's level in the cylinder: circle_area_below(R, level) = J π R², by bisection.
  double low = -radius;
  double high = radius;
  for (int n = 0; n < 200 && high - low > 1e-15 * radius; ++n) {
    const double mid = 0.5 * (low + high);
    (circle_area_below(radius, mid) < filling * pi * radius * radius ? low : high) = mid;
  }
  const double level = 0.5 * (low + high);
  // The cone's cross-section, a circle whose radius falls linearly from R to r_t, integrated
  // along it by Simpson's rule (the integrand is smooth but for the level's tangency).
  constexpr int intervals = 2000;
  const double h = cone_length / intervals;
  double sum = 0.0;
  for (int k = 0; k <= intervals; ++k) {
    const double r = radius + (trunnion_radius - radius) * k / intervals;
    const double weight = k == 0 || k == intervals ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0);
    sum += weight * circle_area_below(r, level);
  }
  return sum * h / 3.0;
}

std::optional<std::string> coarse_step_warning(const std::string& where, double time_step,
                                               double shortest, double automatic) {
  if (!(time_step * fewest_steps_per_contact > shortest)) return std::nullopt;
  // "auto" is 1/20 of the contact unless a quarter of the stability limit is shorter.
  const std::string share = automatic < shortest / steps_per_contact
                                ? std::string("a quarter of the stability limit")
                                : fmt::format("1/{:.0f} of it", steps_per_contact);
  return fmt::format(
      "{}: simulation.time_step: {:.4g} s resolves the shortest contact ({:.3g} s) in {} "
      "steps, fewer than {:.0f}: the results may be inaccurate (\"auto\" takes {:.3g} s, {})",
      where, time_step, shortest, beyond_text(shortest / time_step, fewest_steps_per_contact),
      fewest_steps_per_contact, automatic, share);
}

namespace {

/// The fraction of the plane (2D) or of space (3D) that equal discs or spheres placed one by
/// one at random, each where it overlaps none before it, cover when no more fit: random
/// sequential addition's jamming limit, 0.5470735 for discs (Zhang and Torquato, Phys. Rev. E
/// 88, 053312, 2013) and 0.384130 for spheres (the same paper).
constexpr double jamming_limit_2d = 0.5470735;
constexpr double jamming_limit_3d = 0.384130;

/// A one-size charge that would cover more of the mill than placing it at random can reach is
/// refused here, before anything is placed: build_mill_world tries each ball up to 200 000
/// times, which for a few hundred thousand balls past the limit ran for tens of minutes
/// before it gave up (2.9 million discs at J = 0.95 had not finished in 15). The mill's whole
/// inside counts, lifters included, and the walls' own exclusion is left out, so that nothing
/// placeable is refused; a charge nearer the limit is left to the placement, which refuses it
/// when it cannot place a ball. A graded charge is not checked (its smaller balls fill the
/// gaps between the larger, past one size's limit).
void refuse_what_random_placement_cannot_reach(const MillPlan& plan) {
  if (plan.discs.size() != 1) return;
  const MillConfig& config = plan.config;
  const DiscClass& only = plan.discs.front();
  const double r = 0.5 * only.diameter;
  const bool flat = config.dimension == 2;
  const double cross_section = pi * plan.radius * plan.radius;
  const double space = flat ? cross_section
                            : cross_section * plan.simulated_length +
                                  (config.periodic ? 0.0 : 2.0 * plan.cone_volume);
  const double one = flat ? pi * r * r : 4.0 / 3.0 * pi * r * r * r;
  const double covered = only.count * one / space;
  const double limit = flat ? jamming_limit_2d : jamming_limit_3d;
  if (covered <= limit) return;
  // The filling at the limit: the count, and so the covered fraction, grows with J.
  const double most_filling = config.filling * limit / covered;
  throw InputError(fmt::format(
      "{}: charge.filling: {} {} of {} m would take {:.3f} of the mill's {}, more than the {} "
      "that {} of one size placed one by one at random can cover (the jamming limit of random "
      "sequential addition): the charge cannot be placed; allowed: a filling below about {:.3g} "
      "for these balls{}, or a graded charge (charge.top_size or charge.sizes)",
      config.location_of("charge.filling"), only.count, flat ? "discs" : "balls", only.diameter,
      covered, flat ? "cross-section" : "volume", limit, flat ? "discs" : "spheres", most_filling,
      flat ? "" : " and this porosity"));
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
    if (plan.speed_fraction > most_speed_fraction) {
      throw InputError(
          fmt::format("{}: mill.speed_rpm: {} rpm is {} times this mill's critical speed, {} rpm; "
                      "allowed: > 0 and at most {} times critical, {} rpm (as for mill.speed)",
                      config.location_of("mill.speed_rpm"), plan.speed_rpm,
                      limit_text(plan.speed_fraction, Allowed::above),
                      fmt::format("{:.6g}", plan.critical_speed_rpm), most_speed_fraction,
                      limit_text(most_speed_fraction * plan.critical_speed_rpm, Allowed::below)));
    }
  }
  plan.angular_speed = plan.speed_rpm * 2.0 * pi / 60.0;
  plan.revolution_period = 60.0 / plan.speed_rpm;

  if (config.lifter_count >= 4) {
    // Every lifter a ball touches must be among the three the contact search tests (the
    // nearest by angle and its two neighbours): widest_particle_for_lifters.
    const double widest = widest_particle_for_lifters(plan.radius, config.lifter_count,
                                                      config.lifter_height, config.lifter_width);
    if (plan.largest_ball > widest) {
      throw InputError(fmt::format(
          "{}: mill.lifters.count: with {} lifters {} m high and {} m wide a ball wider than "
          "{} m can touch a lifter beyond the two neighbours of its nearest one, which "
          "millsim does not test, and the largest ball is {} m; allowed: fewer, lower or "
          "narrower lifters, or smaller balls, so that the largest ball is at most that wide",
          config.location_of("mill.lifters.count"), config.lifter_count, config.lifter_height,
          config.lifter_width, limit_text(widest, Allowed::below), plan.largest_ball));
    }
  }
  if (config.periodic && config.slab_length < 3.0 * plan.largest_ball) {
    // A ball must not meet two images of another across the period.
    const double least = 3.0 * plan.largest_ball;
    throw InputError(fmt::format(
        "{}: mill.slab_length: {} m is too short for balls of {} m; allowed: at least three "
        "largest ball diameters, {} m, and at most mill.length{}",
        config.location_of("mill.slab_length"), config.slab_length, plan.largest_ball,
        limit_text(least, Allowed::above),
        least > config.length
            ? fmt::format(" ({} m, shorter than that: no slab of these balls fits this mill; "
                          "use smaller balls, a longer mill.length or a whole mill, "
                          "mill.periodic = false)",
                          config.length)
            : std::string()));
  }
  if (config.dimension == 3 && !config.periodic && config.length < 1.1 * plan.largest_ball) {
    // Shorter, a ball could touch both ends at once, and the placement, which keeps each ball
    // 2 % of its radius clear of the walls, would find almost no room between them.
    throw InputError(fmt::format(
        "{}: mill.length: {} m is too short for balls of {} m; allowed: a 3D whole mill at least "
        "1.1 largest ball diameters long, {:.4g} m",
        config.location_of("mill.length"), config.length, plan.largest_ball,
        1.1 * plan.largest_ball));
  }
  const double cross_section = pi * plan.radius * plan.radius;
  double bed_volume = config.filling * cross_section * config.length;
  if (config.cone_length > 0.0) {
    const double r = plan.radius;
    const double c = config.cone_length;
    const double tan_cone = std::tan(config.cone_angle_degrees * pi / 180.0);
    plan.trunnion_radius = r - c / tan_cone;
    const double r_t = plan.trunnion_radius;
    if (r_t < 0.5 * plan.largest_ball) {
      // The contact with a cone is found in the meridian plane of the centre, on its side of
      // the axis: a ball that could reach across the trunnion plate to the cone beyond the axis
      // would be pushed by one side only.
      throw InputError(fmt::format(
          "{}: mill.cone_length: {} m leaves a trunnion radius of {} m, less than the "
          "largest ball's radius, {} m; allowed: at most {} m with cones of {} degrees in a "
          "mill of {} m diameter (the trunnion at least the largest ball's radius), or smaller "
          "balls",
          config.location_of("mill.cone_length"), c, limit_text(r_t, Allowed::below),
          0.5 * plan.largest_ball,
          limit_text((r - 0.5 * plan.largest_ball) * tan_cone, Allowed::below),
          config.cone_angle_degrees, config.diameter));
    }
    plan.cone_volume = pi * c * (r * r + r * r_t + r_t * r_t) / 3.0;
    plan.cone_bed_volume = cone_bed_volume(r, r_t, c, config.filling);
    bed_volume += 2.0 * plan.cone_bed_volume;
  }
  plan.mill_charge_mass = config.density * (1.0 - config.porosity) * bed_volume;
  std::vector<double> counts;  // of each size class, before rounding
  if (config.dimension == 2) {
    // Discs: the bed fills J of the slice with a 2D void fraction; each size class takes its
    // mass fraction of the disc area (a section through a 3D charge shows each size with its
    // volume fraction).
    const double disc_area = config.filling * cross_section * (1.0 - disc_bed_porosity);
    for (const SizeClass& s : config.sizes) {
      const double one = pi / 4.0 * s.diameter * s.diameter;
      counts.push_back(s.mass_fraction * disc_area / one);
      plan.discs.push_back({s.diameter, sphere_mass(s.diameter, config.density), 0});
    }
  } else {
    // Spheres: the simulated length holds its share of the real charge, ρ (1 − porosity) J
    // π R² L, each size class its mass fraction of it.
    plan.simulated_length = config.periodic ? config.slab_length : config.length;
    const double charge_mass = plan.mill_charge_mass * plan.simulated_length / config.length;
    for (const SizeClass& s : config.sizes) {
      const double one = sphere_mass(s.diameter, config.density);
      counts.push_back(s.mass_fraction * charge_mass / one);
      plan.discs.push_back({s.diameter, one, 0});
    }
  }
  // Counted in doubles and checked before they become whole numbers: a 100 m mill of 5 mm balls
  // (within the reader's bounds) would ask for more memory than any machine has.
  double total = 0.0;
  for (const double n : counts) total += n;
  const std::string count_keys =
      config.dimension == 2
          ? "charge.filling, mill.diameter and the ball sizes"
          : "charge.filling, mill.diameter, the simulated length and the ball sizes";
  if (!(total <= most_particles)) {
    throw InputError(fmt::format(
        "{}: charge.filling: this charge is {:.3g} {}; allowed: at most {:.0e} (about {:.0f} GB "
        "of memory), set by {}",
        config.location_of("charge.filling"), total, config.dimension == 2 ? "discs" : "balls",
        most_particles, most_particles * 1.1e3 / 1e9, count_keys));
  }
  if (!(total >= 0.5)) {
    throw InputError(fmt::format(
        "{}: charge.filling: this charge is {} of a {}, which rounds to none; allowed: a "
        "filling, mill and ball sizes whose charge holds at least half of one (set by {})",
        config.location_of("charge.filling"), limit_text(total, Allowed::below),
        config.dimension == 2 ? "disc" : "ball", count_keys));
  }
  for (std::size_t k = 0; k < counts.size(); ++k) {
    plan.discs[k].count = std::max(1, static_cast<int>(std::lround(counts[k])));
  }
  std::sort(plan.discs.begin(), plan.discs.end(),
            [](const DiscClass& a, const DiscClass& b) { return a.diameter > b.diameter; });
  for (const DiscClass& c : plan.discs) {
    plan.particle_count += c.count;
    plan.slice_mass += c.count * c.mass;
  }
  refuse_what_random_placement_cannot_reach(plan);
  // 2D: a slice scaled by charge mass (docs/model.md). 3D: the mill itself, or a periodic
  // slab scaled by length.
  plan.power_scale = config.dimension == 2 ? plan.mill_charge_mass / plan.slice_mass
                                           : config.length / plan.simulated_length;

  // Time step from the lightest contacts: two of the smallest discs, and one against a wall.
  const double lightest = plan.discs.back().mass;
  const double pair_mass = reduced_mass(lightest, lightest);
  plan.contact_duration_ball_ball = contact_duration(config.ball_ball, pair_mass);
  plan.contact_duration_ball_wall = contact_duration(config.ball_wall, lightest);
  const double inertia = config.dimension == 2 ? inertia_factor<2> : inertia_factor<3>;
  plan.critical_time_step = std::min(
      critical_time_step(config.ball_ball, pair_mass, tangential_mass(lightest, lightest, inertia)),
      critical_time_step(config.ball_wall, lightest, tangential_mass(lightest, 0.0, inertia)));
  const double shortest =
      std::min(plan.contact_duration_ball_ball, plan.contact_duration_ball_wall);
  const double accurate = shortest / steps_per_contact;
  const double automatic = automatic_time_step(shortest, plan.critical_time_step);
  if (config.time_step) {
    if (*config.time_step >= plan.critical_time_step) {
      throw InputError(fmt::format(
          "{}: simulation.time_step: {:.4g} s is unstable for these materials and balls (the "
          "stability limit is {} s; for accuracy about {:.3g} s, 1/{} of the shortest "
          "contact); allowed: \"auto\" or a number of seconds below {}",
          config.location_of("simulation.time_step"), *config.time_step,
          limit_text(plan.critical_time_step, Allowed::below), accurate, steps_per_contact,
          limit_text(plan.critical_time_step, Allowed::below)));
    }
    plan.time_step = *config.time_step;
    if (auto warning = coarse_step_warning(config.location_of("simulation.time_step"),
                                           plan.time_step, shortest, automatic)) {
      plan.warnings.push_back(std::move(*warning));
    }
  } else {
    plan.time_step = automatic;
  }
  if (!(std::isfinite(plan.time_step) && plan.time_step > 0.0)) {
    // Only extreme stiffnesses and masses get here: the contact's frequency overflows.
    throw InputError(fmt::format(
        "{}: these materials and balls give no usable time step (shortest contact {:.3g} s, "
        "stability limit {:.3g} s); allowed: stiffnesses (materials.*.normal_stiffness, "
        "tangential_stiffness), a density and ball sizes whose contacts last a finite time",
        config.source, shortest, plan.critical_time_step));
  }
  plan.spin_up_time = 0.25 * plan.revolution_period;
  plan.total_time =
      config.settle_time + 0.5 * plan.spin_up_time + config.revolutions * plan.revolution_period;
  const double steps = plan.total_time / plan.time_step;
  if (!(steps <= most_steps)) {
    throw InputError(fmt::format(
        "{}: simulation.revolutions: {} s of settling, the spin-up and {} revolutions of {:.4g} "
        "s at a time step of {:.4g} s is {} steps; allowed: at most {:.0e} steps (fewer "
        "revolutions, a shorter settle_time, a faster mill.speed, or a longer "
        "simulation.time_step)",
        config.location_of("simulation.revolutions"), config.settle_time, config.revolutions,
        plan.revolution_period, plan.time_step, step_count_text(steps, most_steps), most_steps));
  }
  if (config.snapshot_interval > 0.0 && config.snapshot_interval < plan.time_step) {
    throw InputError(fmt::format(
        "{}: output.snapshot_interval: {} s is shorter than the time step, {:.4g} s; allowed: 0 "
        "(no snapshots) or at least the time step",
        config.location_of("output.snapshot_interval"), config.snapshot_interval, plan.time_step));
  }
  if (config.snapshot_interval == 0.0 && config.key_locations.contains("output.snapshot_format")) {
    plan.warnings.push_back(fmt::format(
        "{}: output.snapshot_format: \"{}\" is set, but output.snapshot_interval is 0 ({}): no "
        "snapshots are written",
        config.location_of("output.snapshot_format"),
        config.snapshot_csv ? (config.snapshot_vtk ? "both" : "csv") : "vtk",
        config.location_of("output.snapshot_interval")));
  }
  if (config.snapshot_interval > 0.0) {
    // The run writes a snapshot before the first step whose start is within half a step of
    // the next multiple of the interval, and its last step starts one step before the end.
    plan.snapshot_count =
        std::floor((plan.total_time - 0.5 * plan.time_step) / config.snapshot_interval) + 1.0;
    const double particles = static_cast<double>(plan.particle_count);
    double per_snapshot = 0.0;
    if (config.snapshot_csv) {
      per_snapshot += particles * snapshot_bytes_per_particle(config.dimension, false);
    }
    if (config.snapshot_vtk) {
      per_snapshot += particles * snapshot_bytes_per_particle(config.dimension, true) +
                      snapshot_mill_bytes(
                          config.dimension, config.lifter_count,
                          config.dimension == 3 && !config.periodic && config.cone_length > 0.0);
    }
    plan.snapshot_bytes = plan.snapshot_count * per_snapshot;
    if (plan.snapshot_bytes > snapshot_bytes_warned) {
      plan.warnings.push_back(fmt::format(
          "{}: output.snapshot_interval: {:.0f} snapshots of {} particles take up to about {:.0f} "
          "GB of disk; a longer interval takes less, 0 none",
          config.location_of("output.snapshot_interval"), plan.snapshot_count, plan.particle_count,
          plan.snapshot_bytes / 1e9));
    }
  }
  return plan;
}

template <int D>
World<D> build_mill_world(const MillPlan& plan) {
  const MillConfig& config = plan.config;
  WorldSettings<D> settings;
  settings.time_step = plan.time_step;
  settings.gravity[1] = -standard_gravity;
  settings.ball_ball = config.ball_ball;
  settings.ball_wall = config.ball_wall;
  Walls<D> walls;
  MillShape<D> mill;
  mill.radius = plan.radius;
  mill.lifter_count = config.lifter_count;
  mill.lifter_height = config.lifter_height;
  mill.lifter_width = config.lifter_width;
  if constexpr (D == 3) {
    mill.length = plan.simulated_length;
    mill.periodic = config.periodic;
    mill.cone_length = config.cone_length;
    mill.cone_angle = config.cone_angle_degrees * pi / 180.0;
  }
  mill.turn_to(0.0);
  walls.mill = mill;
  World<D> world(settings, walls);

  // Random sequential placement, largest first, anywhere in the free space of the mill,
  // checked against a grid of cells one largest diameter wide. Along a periodic axis, cells
  // and distances wrap round.
  std::mt19937_64 random(config.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double cell = plan.largest_ball;
  std::array<int, D> cells{};
  std::array<double, D> low{};
  std::array<double, D> span{};
  for (int a = 0; a < D; ++a) {
    // Along the axis: the cylinder, and the cones beyond its ends.
    low[a] = a < 2 ? -plan.radius : -config.cone_length;
    span[a] = a < 2 ? 2.0 * plan.radius : plan.simulated_length + 2.0 * config.cone_length;
    cells[a] = static_cast<int>(std::ceil(span[a] / cell)) + 1;
  }
  const bool periodic = D == 3 && config.periodic;
  if (periodic) cells[D - 1] = std::max(1, static_cast<int>(span[D - 1] / cell));
  const double period = periodic ? span[D - 1] : 0.0;
  std::array<double, D> side{};
  for (int a = 0; a < D; ++a) side[a] = cell;
  if (periodic) side[D - 1] = period / cells[D - 1];
  int total = 1;
  for (int a = 0; a < D; ++a) total *= cells[a];
  std::vector<std::vector<std::size_t>> grid(static_cast<std::size_t>(total));
  const auto cell_index = [&](const std::array<int, D>& at) {
    int index = 0;
    for (int a = 0; a < D; ++a) index = index * cells[a] + at[a];
    return static_cast<std::size_t>(index);
  };
  const auto separation = [&](const Vec<D>& from, const Vec<D>& to) {
    Vec<D> offset = to - from;
    if (periodic) offset[D - 1] -= period * nearest_integer(offset[D - 1] / period);
    return offset;
  };
  auto& particles = world.particles();
  const auto overlaps_another = [&](const Vec<D>& at, double r, const std::array<int, D>& home) {
    constexpr int neighbourhood = D == 2 ? 9 : 27;
    // (A fixed array: a vector here was an allocation at every attempt.)
    std::array<std::size_t, neighbourhood> visited_cells{};
    const auto visited_begin = visited_cells.begin();
    auto visited_end = visited_cells.begin();
    for (int code = 0; code < neighbourhood; ++code) {
      std::array<int, D> near{};
      bool inside = true;
      for (int a = 0, rest = code; a < D; ++a, rest /= 3) {
        near[a] = home[a] + rest % 3 - 1;
        if (periodic && a == D - 1) near[a] = (near[a] + cells[a]) % cells[a];
        inside = inside && near[a] >= 0 && near[a] < cells[a];
      }
      if (!inside) continue;
      const std::size_t index = cell_index(near);
      if (std::find(visited_begin, visited_end, index) != visited_end) continue;
      *visited_end++ = index;
      for (const std::size_t other : grid[index]) {
        const double reach = 1.01 * (r + particles.radius[other]);
        if (norm_squared(separation(particles.position[other], at)) < reach * reach) return true;
      }
    }
    return false;
  };
  constexpr long attempts_per_ball = 200000;
  for (const DiscClass& c : plan.discs) {
    const double r = 0.5 * c.diameter;
    for (int n = 0; n < c.count; ++n) {
      bool placed = false;
      for (long attempt = 0; attempt < attempts_per_ball && !placed; ++attempt) {
        Vec<D> at{};
        std::array<int, D> home{};
        for (int a = 0; a < D; ++a) {
          at[a] = low[a] + span[a] * uniform(random);
          home[a] = std::clamp(static_cast<int>((at[a] - low[a]) / side[a]), 0, cells[a] - 1);
        }
        if (!clear_of_walls(mill, at, r) || overlaps_another(at, r, home)) continue;
        grid[cell_index(home)].push_back(particles.add(at, r, c.mass));
        placed = true;
      }
      if (!placed) {
        throw InputError(fmt::format(
            "{}: charge.filling: could not place {} {} of {} m without overlap in the mill "
            "(placed {}); allowed: a filling whose balls fit the mill: lower the filling or use "
            "smaller balls{}",
            config.location_of("charge.filling"), plan.particle_count, D == 2 ? "discs" : "balls",
            c.diameter, particles.size(),
            D == 3 && !config.periodic ? ", or make the mill longer (mill.length)" : ""));
      }
    }
  }
  return world;
}

template World<2> build_mill_world<2>(const MillPlan&);
template World<3> build_mill_world<3>(const MillPlan&);

}  // namespace millsim
