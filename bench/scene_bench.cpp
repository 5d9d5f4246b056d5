// millsim_scene_bench: times the step of a mill scene. Reads a mill config (2D or 3D), places
// and settles the charge for simulation.settle_time, sets the shell turning at full speed,
// runs --warmup steps untimed, then times --steps steps and prints particle-steps per second.
// --save-state writes the particles and the shell angle after the timed steps; --load-state
// starts from such a file instead of settling (the contacts start afresh), so that a turning
// mill can be timed or profiled (callgrind) in a short run.
//
//   millsim_scene_bench CONFIG [--steps N] [--warmup N] [--threads N] [--set KEY=VALUE ...]
//                       [--save-state FILE] [--load-state FILE]
#include <fmt/format.h>
#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

#include "millsim/core/error.hpp"
#include "millsim/io/config.hpp"
#include "millsim/sim/charge.hpp"
#include "millsim/sim/mill_run.hpp"

namespace {

using Clock = std::chrono::steady_clock;

/// CPU time this process has used, s (all threads): on a busy machine it shows the work done
/// better than the wall clock does.
double cpu_seconds() {
  return static_cast<double>(std::clock()) / CLOCKS_PER_SEC;
}

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Resident memory of this process, bytes (from /proc/self/status; 0 if unknown).
double resident_bytes() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmRSS:") {
      double kilobytes = 0.0;
      status >> kilobytes;
      return kilobytes * 1024.0;
    }
    status.ignore(4096, '\n');
  }
  return 0.0;
}

/// The state a bench run can start from: every particle array, then the shell angle, as raw
/// doubles after a particle count (a file for this machine's builds, not an exchange format).
template <typename T>
void write_array(std::ofstream& file, const std::vector<T>& values) {
  file.write(reinterpret_cast<const char*>(values.data()),
             static_cast<std::streamsize>(values.size() * sizeof(T)));
}
template <typename T>
void read_array(std::ifstream& file, std::vector<T>& values) {
  file.read(reinterpret_cast<char*>(values.data()),
            static_cast<std::streamsize>(values.size() * sizeof(T)));
}

template <int D>
void save_state(const millsim::World<D>& world, const std::string& path) {
  std::ofstream file(path, std::ios::binary);
  const auto& p = world.particles();
  const std::uint64_t count = p.size();
  file.write(reinterpret_cast<const char*>(&count), sizeof count);
  write_array(file, p.position);
  write_array(file, p.velocity);
  write_array(file, p.angular_velocity);
  write_array(file, p.force);
  write_array(file, p.torque);
  const double angle = world.walls().mill->angle;
  file.write(reinterpret_cast<const char*>(&angle), sizeof angle);
  if (!file) throw millsim::InputError(fmt::format("--save-state: cannot write {}", path));
}

template <int D>
void load_state(millsim::World<D>& world, const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  auto& p = world.particles();
  std::uint64_t count = 0;
  file.read(reinterpret_cast<char*>(&count), sizeof count);
  if (!file || count != p.size()) {
    throw millsim::InputError(fmt::format(
        "--load-state: {} is not a state of this scene ({} particles)", path, p.size()));
  }
  read_array(file, p.position);
  read_array(file, p.velocity);
  read_array(file, p.angular_velocity);
  read_array(file, p.force);
  read_array(file, p.torque);
  double angle = 0.0;
  file.read(reinterpret_cast<char*>(&angle), sizeof angle);
  if (!file) throw millsim::InputError(fmt::format("--load-state: {} is truncated", path));
  world.walls().mill->turn_to(angle);
}

template <int D>
int run(const millsim::MillPlan& plan, long warmup, long steps, const std::string& load_path,
        const std::string& save_path) {
  const double before = resident_bytes();
  millsim::World<D> world = millsim::build_mill_world<D>(plan);
  const auto settle_start = Clock::now();
  if (load_path.empty()) {
    while (world.time() < plan.config.settle_time) world.step();
  } else {
    load_state(world, load_path);
  }
  world.walls().mill->angular_speed = plan.angular_speed;
  for (long n = 0; n < warmup; ++n) world.step();
  const double prepare_seconds = seconds_since(settle_start);
  const long rebuilds_before = world.neighbour_rebuilds();
  const double cpu_start = cpu_seconds();
  const auto start = Clock::now();
  for (long n = 0; n < steps; ++n) world.step();
  const double wall = seconds_since(start);
  const double cpu = cpu_seconds() - cpu_start;
  if (!save_path.empty()) save_state(world, save_path);
  const double particles = static_cast<double>(world.particles().size());
  const double rate = particles * static_cast<double>(steps) / wall;
  fmt::print("config            {}\n", plan.config.source);
  fmt::print("dimension         {}\n", D);
  fmt::print("particles         {}\n", world.particles().size());
  fmt::print("threads           {}\n", omp_get_max_threads());
  fmt::print("time step         {:.4g} s\n", plan.time_step);
  if (load_path.empty()) {
    fmt::print("prepared in       {:.1f} s (settle {} s of mill time, then {} steps turning)\n",
               prepare_seconds, plan.config.settle_time, warmup);
  } else {
    fmt::print("prepared in       {:.1f} s (state {}, then {} steps turning)\n", prepare_seconds,
               load_path, warmup);
  }
  fmt::print("timed steps       {} in {:.2f} s at {:.4g} rpm ({:.2f} s of CPU time)\n", steps, wall,
             plan.speed_rpm, cpu);
  fmt::print("particle-steps/s  {:.4g}\n", rate);
  const long rebuilds = world.neighbour_rebuilds() - rebuilds_before;
  fmt::print("neighbour rebuilds {} ({:.1f} steps apart), {} contacts at the end\n", rebuilds,
             static_cast<double>(steps) / static_cast<double>(std::max(1L, rebuilds)),
             world.touching_contacts());
  fmt::print("real-time factor  {:.4g} (mill seconds per wall second)\n",
             static_cast<double>(steps) * plan.time_step / wall);
  fmt::print("memory/particle   {:.0f} bytes (resident growth while building and running)\n",
             std::max(0.0, resident_bytes() - before) / particles);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"millsim_scene_bench: particle-steps per second of a mill scene"};
  std::string config_path;
  long steps = 2000;
  long warmup = 1000;
  int threads = 0;
  std::vector<std::string> overrides;
  std::string load_path;
  std::string save_path;
  app.add_option("config", config_path, "mill config (TOML)")->required();
  app.add_option("--steps", steps, "steps to time after settling and spin-up")
      ->check(CLI::Range(1L, 1000000000L));
  app.add_option("--warmup", warmup, "untimed steps at full speed after settling")
      ->check(CLI::Range(0L, 1000000000L));
  app.add_option("-j,--threads", threads, "threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
  app.add_option("--set", overrides, "override a config key (repeatable)");
  app.add_option("--load-state", load_path, "start from this state instead of settling");
  app.add_option("--save-state", save_path, "write the state after the timed steps here");
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  try {
    const millsim::MillPlan plan =
        millsim::plan_mill(millsim::load_mill_config(config_path, overrides));
    return plan.config.dimension == 2 ? run<2>(plan, warmup, steps, load_path, save_path)
                                      : run<3>(plan, warmup, steps, load_path, save_path);
  } catch (const millsim::InputError& error) {
    fmt::print(stderr, "millsim_scene_bench: error: {}\n", error.what());
    return 2;
  }
}
