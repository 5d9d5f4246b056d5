// millsim_scene_bench: times the step of a mill scene. Reads a mill config (2D or 3D), places
// and settles the charge for simulation.settle_time, sets the shell turning at full speed,
// runs --warmup steps untimed, then times --steps steps and prints particle-steps per second.
//
//   millsim_scene_bench CONFIG [--steps N] [--threads N] [--set KEY=VALUE ...]
#include <fmt/format.h>
#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <fstream>
#include <string>
#include <vector>

#include "millsim/core/error.hpp"
#include "millsim/io/config.hpp"
#include "millsim/sim/charge.hpp"
#include "millsim/sim/mill_run.hpp"

namespace {

using Clock = std::chrono::steady_clock;

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

template <int D>
int run(const millsim::MillPlan& plan, long warmup, long steps) {
  const double before = resident_bytes();
  millsim::World<D> world = millsim::build_mill_world<D>(plan);
  const auto settle_start = Clock::now();
  while (world.time() < plan.config.settle_time) world.step();
  world.walls().mill->angular_speed = plan.angular_speed;
  for (long n = 0; n < warmup; ++n) world.step();
  const double prepare_seconds = seconds_since(settle_start);
  const auto start = Clock::now();
  for (long n = 0; n < steps; ++n) world.step();
  const double wall = seconds_since(start);
  const double particles = static_cast<double>(world.particles().size());
  const double rate = particles * static_cast<double>(steps) / wall;
  fmt::print("config            {}\n", plan.config.source);
  fmt::print("dimension         {}\n", D);
  fmt::print("particles         {}\n", world.particles().size());
  fmt::print("threads           {}\n", omp_get_max_threads());
  fmt::print("time step         {:.4g} s\n", plan.time_step);
  fmt::print("prepared in       {:.1f} s (settle {} s of mill time, then {} steps turning)\n",
             prepare_seconds, plan.config.settle_time, warmup);
  fmt::print("timed steps       {} in {:.2f} s at {:.4g} rpm\n", steps, wall, plan.speed_rpm);
  fmt::print("particle-steps/s  {:.4g}\n", rate);
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
  app.add_option("config", config_path, "mill config (TOML)")->required();
  app.add_option("--steps", steps, "steps to time after settling and spin-up")
      ->check(CLI::Range(1L, 1000000000L));
  app.add_option("--warmup", warmup, "untimed steps at full speed after settling")
      ->check(CLI::Range(0L, 1000000000L));
  app.add_option("-j,--threads", threads, "threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
  app.add_option("--set", overrides, "override a config key (repeatable)");
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  try {
    const millsim::MillPlan plan =
        millsim::plan_mill(millsim::load_mill_config(config_path, overrides));
    return plan.config.dimension == 2 ? run<2>(plan, warmup, steps) : run<3>(plan, warmup, steps);
  } catch (const millsim::InputError& error) {
    fmt::print(stderr, "millsim_scene_bench: error: {}\n", error.what());
    return 2;
  }
}
