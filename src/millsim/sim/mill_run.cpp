#include "millsim/sim/mill_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "millsim/core/constants.hpp"
#include "millsim/io/output.hpp"

namespace millsim {
namespace {

template <int D>
EnergySample sample(const World<D>& world) {
  EnergySample s;
  s.time = world.time();
  s.shell_work = world.energy_account().shell_work;
  s.dissipated = world.energy_account().dissipated;
  s.kinetic = world.kinetic_energy();
  s.potential = world.potential_energy();
  s.stored = world.stored_spring_energy();
  return s;
}

PowerInterval interval(const EnergySample& from, const EnergySample& to, double torque_time,
                       double scale) {
  PowerInterval p;
  p.start_time = from.time;
  p.end_time = to.time;
  const double duration = to.time - from.time;
  p.power = scale * (to.shell_work - from.shell_work) / duration;
  p.dissipation_power = scale * (to.dissipated - from.dissipated) / duration;
  p.torque = scale * torque_time / duration;
  p.kinetic_energy = to.kinetic;
  return p;
}

}  // namespace

template <int D>
std::pair<Vec2, double> charge_motion(const ParticleStore<D>& p) {
  Vec2 moment{};
  double mass = 0.0;
  double angular_momentum = 0.0;
  double inertia = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2 at{{p.position[i][0], p.position[i][1]}};
    const Vec2 velocity{{p.velocity[i][0], p.velocity[i][1]}};
    moment += p.mass[i] * at;
    mass += p.mass[i];
    angular_momentum += p.mass[i] * cross(at, velocity);
    inertia += p.mass[i] * norm_squared(at);
  }
  return {moment * (1.0 / mass), inertia > 0.0 ? angular_momentum / inertia : 0.0};
}

template std::pair<Vec2, double> charge_motion<2>(const ParticleStore<2>&);
template std::pair<Vec2, double> charge_motion<3>(const ParticleStore<3>&);

double spin_up_time(const MillPlan& plan) {
  return plan.spin_up_time;
}

double least_drive_power(const MillPlan& plan) {
  return 1e-3 * plan.power_scale * plan.slice_mass * standard_gravity * plan.radius *
         plan.angular_speed;
}

template <int D>
MillResult run_mill(const MillPlan& plan, World<D> world,
                    const std::filesystem::path& snapshot_directory,
                    const ProgressCallback& progress) {
  const auto started = std::chrono::steady_clock::now();
  world.set_cell_order_interval(cell_order_interval);
  MillResult result;
  result.plan = plan;
  const double dt = plan.time_step;
  const double settle = plan.config.settle_time;
  const double ramp = spin_up_time(plan);
  const double full_angle = 2.0 * pi * plan.config.revolutions;
  const double measure_from =
      2.0 * pi * (plan.config.revolutions - plan.config.measure_revolutions);
  const double snapshot_interval = plan.config.snapshot_interval;
  const double series_angle = 2.0 * pi / 50.0;

  double next_snapshot = 0.0;
  SnapshotWriter snapshots(snapshot_directory, plan.config.snapshot_csv, plan.config.snapshot_vtk);
  const auto write_snapshot_if_due = [&] {
    if (snapshot_interval <= 0.0 || world.time() + 0.5 * dt < next_snapshot) return;
    snapshots.write(world);
    next_snapshot += snapshot_interval;
  };

  // Settle with the shell still.
  while (world.time() + 0.5 * dt < settle) {
    write_snapshot_if_due();
    world.step();
    if (progress && world.steps() % 2000 == 0) progress(world.time(), plan.total_time, 0.0);
  }
  result.settled_kinetic_energy = world.kinetic_energy();
  result.largest_overlap_fraction = world.largest_overlap_fraction();
  result.settle_wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  // Turn: ω ramps up linearly over spin_up_time, then stays. Revolutions are counted by the
  // angle the shell has turned.
  auto& mill = *world.walls().mill;
  const double start_angle = mill.angle;
  const double rotation_start = world.time();
  EnergySample revolution_start = sample(world);
  EnergySample series_start = revolution_start;
  double revolution_torque_time = 0.0;
  double series_torque_time = 0.0;
  double window_torque_time = 0.0;
  int next_revolution = 1;
  bool measuring = false;
  int motion_samples = 0;
  for (;;) {
    const double turned = mill.angle - start_angle;
    if (!measuring && turned >= measure_from - 1e-12) {
      measuring = true;
      result.window_start = sample(world);
      world.record_collisions_in(&result.spectrum);
      const MillConfig& c = plan.config;
      result.charge_profile.emplace(plan.radius, c.lifter_count > 0 ? c.lifter_height : 0.0,
                                    plan.angular_speed >= 0.0);
      result.shell_impacts.emplace(plan.angular_speed >= 0.0);
      world.record_impacts_in(&*result.shell_impacts);
    }
    if (turned >= full_angle) break;
    const double since = world.time() - rotation_start;
    mill.angular_speed = plan.angular_speed * std::min(1.0, (since + 0.5 * dt) / ramp);
    write_snapshot_if_due();
    world.step();
    revolution_torque_time += world.shell_torque() * dt;
    series_torque_time += world.shell_torque() * dt;
    if (measuring) window_torque_time += world.shell_torque() * dt;
    const double now_turned = mill.angle - start_angle;
    if (now_turned >= series_angle * static_cast<double>(result.series.size() + 1)) {
      const EnergySample now = sample(world);
      result.series.push_back(interval(series_start, now, series_torque_time, plan.power_scale));
      result.largest_overlap_fraction =
          std::max(result.largest_overlap_fraction, world.largest_overlap_fraction());
      if (measuring) {
        // (Read only: the non-const particles() would mark the step's velocity estimates
        // stale, and the next step would make them again.)
        const ParticleStore<D>& particles = std::as_const(world).particles();
        const auto [centre, angular_speed] = charge_motion(particles);
        result.charge_centre += centre;
        result.orbital_speed_ratio += angular_speed / plan.angular_speed;
        result.charge_profile->add(particles.position, particles.radius);
        ++motion_samples;
      }
      series_start = now;
      series_torque_time = 0.0;
    }
    if (now_turned >= 2.0 * pi * next_revolution) {
      const EnergySample now = sample(world);
      result.revolutions.push_back(
          interval(revolution_start, now, revolution_torque_time, plan.power_scale));
      revolution_start = now;
      revolution_torque_time = 0.0;
      ++next_revolution;
    }
    if (progress && world.steps() % 2000 == 0) {
      progress(world.time(), plan.total_time, now_turned / (2.0 * pi));
    }
  }
  world.record_collisions_in(nullptr);
  world.record_impacts_in(nullptr);
  result.window_end = sample(world);
  if (motion_samples > 0) {
    result.charge_centre *= 1.0 / motion_samples;
    result.orbital_speed_ratio /= motion_samples;
  }

  // Means over the measured window, spread between its revolutions.
  const EnergySample& a = result.window_start;
  const EnergySample& b = result.window_end;
  const double window = b.time - a.time;
  const double work = b.shell_work - a.shell_work;
  const double dissipated = b.dissipated - a.dissipated;
  result.power_kw = plan.power_scale * work / window / 1000.0;
  result.power_dissipation_kw = plan.power_scale * dissipated / window / 1000.0;
  // The mean torque, as power.csv's rows have it: T ω = P only while ω is steady (a window that
  // takes in the spin-up has a mean torque above P / ω).
  result.torque_nm = plan.power_scale * window_torque_time / window;
  const double change =
      (b.kinetic - a.kinetic) + (b.potential - a.potential) + (b.stored - a.stored);
  // Relative to the shell's work, or, where the drive does next to no work, to the least
  // drive power's over the window (least_drive_power): against rounding a ratio says nothing.
  result.energy_balance_error =
      std::abs(work - (change + dissipated)) /
      std::max(std::abs(work), least_drive_power(plan) / plan.power_scale * window);
  const auto measured = static_cast<std::size_t>(plan.config.measure_revolutions);
  const std::size_t first =
      result.revolutions.size() - std::min(measured, result.revolutions.size());
  double sum = 0.0;
  double sum_squares = 0.0;
  for (std::size_t k = first; k < result.revolutions.size(); ++k) {
    sum += result.revolutions[k].power;
    sum_squares += result.revolutions[k].power * result.revolutions[k].power;
  }
  const double n = static_cast<double>(result.revolutions.size() - first);
  if (n > 1) {
    const double mean = sum / n;
    result.power_std_kw =
        std::sqrt(std::max(0.0, (sum_squares - n * mean * mean) / (n - 1))) / 1000.0;
  }

  result.steps = world.steps();
  result.dropped_wall_contacts = world.dropped_wall_contacts();
  result.simulated_seconds = world.time();
  result.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  result.particle_steps_per_second =
      static_cast<double>(result.steps) * plan.particle_count / result.wall_seconds;
  return result;
}

template MillResult run_mill<2>(const MillPlan&, World<2>, const std::filesystem::path&,
                                const ProgressCallback&);
template MillResult run_mill<3>(const MillPlan&, World<3>, const std::filesystem::path&,
                                const ProgressCallback&);

}  // namespace millsim
