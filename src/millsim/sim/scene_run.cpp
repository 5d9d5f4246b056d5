#include "millsim/sim/scene_run.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "millsim/core/constants.hpp"
#include "millsim/core/error.hpp"
#include "millsim/core/version.hpp"
#include "millsim/io/output.hpp"
#include "millsim/io/partial_file.hpp"
#include "millsim/sim/charge.hpp"

namespace millsim {
namespace {

/// "auto" for a scene whose particles can touch nothing: this many steps over the duration.
constexpr double steps_without_contacts = 1000.0;

double particle_mass(const SceneParticle& p) {
  return p.density * pi * p.diameter * p.diameter * p.diameter / 6.0;
}

template <int D>
Vec<D> to_vec(const std::array<double, 3>& a) {
  Vec<D> v{};
  for (int k = 0; k < D; ++k) v[k] = a[k];
  return v;
}

template <int D>
Spin<D> to_spin(const std::array<double, 3>& a) {
  if constexpr (D == 2) {
    return a[0];
  } else {
    return Vec3{a[0], a[1], a[2]};
  }
}

/// One row of trajectory.csv or final.csv.
template <int D>
void write_row(PartialFile& file, double time, std::size_t id, const Vec<D>& x, const Vec<D>& v,
               const Spin<D>& w) {
  fmt::memory_buffer row;
  fmt::format_to(std::back_inserter(row), "{},{}", time, id);
  for (int k = 0; k < D; ++k) fmt::format_to(std::back_inserter(row), ",{}", x[k]);
  for (int k = 0; k < D; ++k) fmt::format_to(std::back_inserter(row), ",{}", v[k]);
  if constexpr (D == 2) {
    fmt::format_to(std::back_inserter(row), ",{}\n", w);
  } else {
    fmt::format_to(std::back_inserter(row), ",{},{},{}\n", w[0], w[1], w[2]);
  }
  file.write({row.data(), row.size()});
}

/// Every particle's row, in the order of their ids (the order of the config).
template <int D>
void write_state(PartialFile& file, const World<D>& world) {
  for (std::size_t id = 0; id < world.particles().size(); ++id) {
    const std::size_t i = world.particle_index(id);
    const auto [v, w] = motion_at_positions(world, i);
    write_row<D>(file, world.time(), id, world.particles().position[i], v, w);
  }
}

template <int D>
double kinetic_energy(const ParticleStore<D>& p, std::size_t i, const Vec<D>& v, const Spin<D>& w) {
  if constexpr (D == 2) {
    return 0.5 * p.mass[i] * dot(v, v) + 0.5 * w * w / p.inverse_inertia[i];
  } else {
    return 0.5 * p.mass[i] * dot(v, v) + 0.5 * dot(w, w) / p.inverse_inertia[i];
  }
}

template <int D>
std::string header() {
  return D == 2 ? "time_s,id,x,y,vx,vy,omega\n" : "time_s,id,x,y,z,vx,vy,vz,wx,wy,wz\n";
}

std::string summary_json(const SceneResult& r) {
  const SceneConfig& c = r.plan.config;
  // JSON has no infinity or NaN: a run whose figures are not finite has diverged, and is
  // reported as failed rather than written.
  const auto number = [](double x) {
    if (!std::isfinite(x)) {
      throw std::runtime_error(fmt::format(
          "the run diverged: a figure of its summary is {} (summary.json not written)", x));
    }
    return x;
  };
  const auto whole = [](auto n) { return static_cast<std::int64_t>(n); };
  // Written as the mill's summary is (io/output.cpp): toml++'s JSON writer, which escapes the
  // strings (a config's path may hold quotes) and orders the keys.
  toml::table summary{
      {"kind", "scene"},
      {"millsim_version", version_text()},
      {"config", c.source},
      {"dimension", c.dimension},
      {"particle_count", whole(c.particles.size())},
      {"wall_count", whole(c.walls.size())},
      {"time_step_s", number(r.plan.time_step)},
      {"steps", whole(r.steps)},
      {"simulated_seconds", number(r.simulated_seconds)},
      {"wall_seconds", number(r.wall_seconds)},
      {"kinetic_energy_start_j", number(r.kinetic_start)},
      {"kinetic_energy_end_j", number(r.kinetic_end)},
      {"potential_energy_start_j", number(r.potential_start)},
      {"potential_energy_end_j", number(r.potential_end)},
      {"dissipated_j", number(r.dissipated)},
      {"ball_ball_collisions", whole(r.ball_ball_collisions)},
      {"ball_wall_collisions", whole(r.ball_wall_collisions)},
      {"dropped_wall_contacts", whole(r.dropped_wall_contacts)},
  };
  // A scene whose particles can touch nothing has neither (the plan holds 0 for them).
  if (r.plan.shortest_contact > 0.0) {
    summary.insert("critical_time_step_s", number(r.plan.critical_time_step));
    summary.insert("shortest_contact_duration_s", number(r.plan.shortest_contact));
  }
  std::ostringstream text;
  text << toml::json_formatter{summary} << "\n";
  return shortest_json_numbers(text.str());
}

}  // namespace

ScenePlan plan_scene(const SceneConfig& config) {
  ScenePlan plan;
  plan.config = config;
  const double inertia = config.dimension == 2 ? 0.5 : 0.4;
  std::vector<double> masses;
  for (const SceneParticle& p : config.particles) masses.push_back(particle_mass(p));
  std::sort(masses.begin(), masses.end());
  double critical = std::numeric_limits<double>::infinity();
  double shortest = std::numeric_limits<double>::infinity();
  if (masses.size() >= 2) {
    const double pair = reduced_mass(masses[0], masses[1]);
    critical = std::min(
        critical,
        critical_time_step(config.ball_ball, pair, tangential_mass(masses[0], masses[1], inertia)));
    shortest = std::min(shortest, contact_duration(config.ball_ball, pair));
  }
  if (!config.walls.empty()) {
    critical = std::min(critical, critical_time_step(config.ball_wall, masses[0],
                                                     tangential_mass(masses[0], 0.0, inertia)));
    shortest = std::min(shortest, contact_duration(config.ball_wall, masses[0]));
  }
  plan.shortest_contact = std::isfinite(shortest) ? shortest : 0.0;
  plan.critical_time_step = std::isfinite(critical) ? critical : 0.0;
  if (config.time_step) {
    if (std::isfinite(critical) && *config.time_step >= critical) {
      throw InputError(fmt::format(
          "{}: simulation.time_step: {:.4g} s is unstable for these particles and materials "
          "(the shortest contact lasts {:.4g} s); allowed: a time step below the stability "
          "limit {} s, and for accuracy about {:.4g} s (1/{} of the contact), or \"auto\"",
          config.location_of("simulation.time_step"), *config.time_step, shortest,
          limit_text(critical, Allowed::below), shortest / steps_per_contact, steps_per_contact));
    }
    plan.time_step = *config.time_step;
    // (Particles that can touch nothing have an infinite shortest contact: no warning.)
    if (auto warning =
            coarse_step_warning(config.location_of("simulation.time_step"), plan.time_step,
                                shortest, automatic_time_step(shortest, critical))) {
      plan.warnings.push_back(std::move(*warning));
    }
  } else {
    plan.time_step = std::isfinite(shortest) ? automatic_time_step(shortest, critical)
                                             : config.duration / steps_without_contacts;
  }
  if (!(std::isfinite(plan.time_step) && plan.time_step > 0.0)) {
    throw InputError(fmt::format(
        "{}: these particles and materials give no usable time step (shortest contact {:.3g} s, "
        "stability limit {:.3g} s); allowed: stiffnesses, densities and diameters whose contacts "
        "last a finite time",
        config.source, shortest, critical));
  }
  const double exact = config.duration / plan.time_step;
  constexpr double most_steps = 1e10;
  if (!(exact <= most_steps)) {
    throw InputError(fmt::format(
        "{}: simulation.duration: {} s at a time step of {:.4g} s is {} steps; allowed: at "
        "most {:.0e} steps (shorten the duration or lengthen the time step)",
        config.location_of("simulation.duration"), config.duration, plan.time_step,
        step_count_text(exact, most_steps), most_steps));
  }
  if (exact < 1.0) {
    // One step would run past the end by more than the duration itself: two balls of 100 m at
    // the auto step (11.4 s) ran 11.4 s of a 0.01 s scene.
    throw InputError(fmt::format(
        "{}: simulation.duration: {} s is shorter than one time step, {} s ({}); allowed: a "
        "duration of at least one time step",
        config.location_of("simulation.duration"), config.duration, plan.time_step,
        config.time_step ? "simulation.time_step"
                         : "the auto step, 1/20 of the shortest contact: a smaller time_step "
                           "gives a shorter one"));
  }
  const double whole = std::round(exact);
  plan.steps =
      static_cast<long>(std::abs(exact - whole) <= 1e-9 * exact ? whole : std::ceil(exact));
  // An interval as long as the run or longer leaves no row between the start and the end (and
  // would overflow a long as a step count from about 9e18 steps on).
  const double interval_steps = config.trajectory_interval / plan.time_step;
  if (config.trajectory_interval > 0.0 && interval_steps < static_cast<double>(plan.steps)) {
    plan.trajectory_every = std::max(1L, static_cast<long>(std::llround(interval_steps)));
  }
  return plan;
}

template <int D>
World<D> build_scene_world(const ScenePlan& plan) {
  const SceneConfig& c = plan.config;
  WorldSettings<D> settings;
  settings.time_step = plan.time_step;
  settings.gravity = to_vec<D>(c.gravity);
  settings.ball_ball = c.ball_ball;
  settings.ball_wall = c.ball_wall;
  Walls<D> walls;
  for (const SceneWall& w : c.walls)
    walls.planes.push_back({to_vec<D>(w.point), to_vec<D>(w.normal)});
  World<D> world(settings, walls);
  world.set_cell_order_interval(cell_order_interval);
  for (const SceneParticle& p : c.particles) {
    // u̇(−½) = u̇(0) − ½ g Δt: no contact force acts at the start (nothing overlaps).
    const Vec<D> half_step_back = to_vec<D>(p.velocity) - (0.5 * plan.time_step) * settings.gravity;
    world.particles().add(to_vec<D>(p.position), 0.5 * p.diameter, particle_mass(p), half_step_back,
                          to_spin<D>(p.angular_velocity));
  }
  return world;
}

template <int D>
SceneResult run_scene_in(const ScenePlan& plan, const std::filesystem::path& directory,
                         const SceneProgress& progress) {
  World<D> world = build_scene_world<D>(plan);
  ImpactSpectrum spectrum;
  world.record_collisions_in(&spectrum);
  SceneResult result;
  result.plan = plan;
  const auto start_clock = std::chrono::steady_clock::now();
  const ParticleStore<D>& p = world.particles();
  const std::size_t n = p.size();

  PartialFile trajectory(directory / "trajectory.csv");
  trajectory.write(header<D>());
  // At t = 0 the state of the config (the stored half-step velocities are set back by half a
  // step of gravity).
  for (std::size_t i = 0; i < n; ++i) {
    const SceneParticle& sp = plan.config.particles[i];
    const Vec<D> v = to_vec<D>(sp.velocity);
    const Spin<D> w = to_spin<D>(sp.angular_velocity);
    write_row<D>(trajectory, 0.0, i, p.position[i], v, w);
    result.kinetic_start += kinetic_energy(p, i, v, w);
  }
  result.potential_start = world.potential_energy();

  const long report_every = std::max(1L, plan.steps / 200);
  for (long step = 1; step <= plan.steps; ++step) {
    world.step();
    const bool last = step == plan.steps;
    if (last || (plan.trajectory_every > 0 && step % plan.trajectory_every == 0)) {
      write_state(trajectory, world);
    }
    if (progress && step % report_every == 0) progress(world.time(), plan.config.duration);
  }
  PartialFile final_state(directory / "final.csv");
  final_state.write(header<D>());
  write_state(final_state, world);

  result.steps = world.steps();
  result.simulated_seconds = world.time();
  result.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_clock).count();
  for (std::size_t id = 0; id < n; ++id) {
    const std::size_t i = world.particle_index(id);
    const auto [v, w] = motion_at_positions(world, i);
    result.kinetic_end += kinetic_energy(p, i, v, w);
  }
  result.potential_end = world.potential_energy();
  result.dissipated = world.energy_account().dissipated;
  result.ball_ball_collisions = spectrum.total_count(ContactType::ball_ball);
  result.ball_wall_collisions = spectrum.total_count(ContactType::ball_plane);
  result.dropped_wall_contacts = world.dropped_wall_contacts();

  const std::string summary_text = summary_json(result);  // throws before anything is kept
  trajectory.commit();
  final_state.commit();
  PartialFile summary(directory / "summary.json");
  summary.write(summary_text);
  summary.commit();
  return result;
}

std::vector<std::string> scene_result_warnings(const SceneResult& result) {
  if (result.dropped_wall_contacts == 0) return {};
  const int most =
      result.plan.config.dimension == 2 ? World<2>::max_wall_contacts : World<3>::max_wall_contacts;
  return {fmt::format(
      "{} wall contacts were left out (the force of a wall a particle overlapped, for a step "
      "each): a particle pressed into more than {} walls at once, the most millsim keeps a "
      "contact history for; the results are doubtful where walls meet so closely (planes "
      "nearly parallel, or more than {} through one corner)",
      result.dropped_wall_contacts, most, most)};
}

SceneResult run_scene(const ScenePlan& plan, const std::filesystem::path& directory,
                      const SceneProgress& progress) {
  return plan.config.dimension == 2 ? run_scene_in<2>(plan, directory, progress)
                                    : run_scene_in<3>(plan, directory, progress);
}

std::string scene_summary_line(const SceneResult& r) {
  return fmt::format(
      "scene: {} particle{}, {} wall{}, {:.4g} s in {} steps of {:.4g} s; collisions ball-ball "
      "{}, ball-wall {}; kinetic energy {:.4g} J -> {:.4g} J, dissipated {:.4g} J; {:.2f} s wall",
      r.plan.config.particles.size(), r.plan.config.particles.size() == 1 ? "" : "s",
      r.plan.config.walls.size(), r.plan.config.walls.size() == 1 ? "" : "s", r.simulated_seconds,
      r.steps, r.plan.time_step, r.ball_ball_collisions, r.ball_wall_collisions, r.kinetic_start,
      r.kinetic_end, r.dissipated, r.wall_seconds);
}

template World<2> build_scene_world<2>(const ScenePlan&);
template World<3> build_scene_world<3>(const ScenePlan&);

}  // namespace millsim
