// millsim_scene_bench: times the step of a mill scene. Reads a mill config (2D or 3D), places
// and settles the charge for simulation.settle_time, sets the shell turning at full speed,
// runs --warmup steps untimed, then times --steps steps and prints particle-steps per second.
// --save-state writes the particles and the shell angle after the timed steps; --load-state
// starts from such a file instead of settling (the contacts start afresh), so that a turning
// mill can be timed or profiled (callgrind) in a short run.
//
// --tile K (a periodic 3D slab only) times, instead of the settled slab of length L0, a slab K
// L0 long holding K copies of it, shifted by j L0 along the axis (j = 0 .. K-1), velocities and
// spins copied: the slab is invariant along the axis, so this is a settled slab too (contacts
// across the old period boundary become contacts between neighbouring copies; their springs
// start afresh, as with --load-state). The copies follow each other in memory, each in the
// base slab's order. --shuffle puts the timed particles in an order drawn at random (fixed
// seed) instead. bench/run_scaling_series.sh uses both for issue 5's scaling series.
//
//   millsim_scene_bench CONFIG [--steps N] [--warmup N] [--threads N] [--set KEY=VALUE ...]
//                       [--save-state FILE] [--load-state FILE] [--tile K] [--shuffle]
//                       [--cell-order N]
#include <fmt/format.h>
#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <optional>
#include <random>
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
  // In id order: a world loads it before its first step, while index and id are the same.
  const millsim::ParticleStore<D> p = world.particles_by_id();
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

/// What a bench run does, from the command line.
struct BenchOptions {
  long warmup = 1000;
  long steps = 2000;
  std::string load_path;
  std::string save_path;
  int tile = 1;
  bool shuffle = false;
  /// Particles renumbered into cell order every this many neighbour-list rebuilds (0: never),
  /// by default as in `millsim run`.
  int cell_order = millsim::cell_order_interval;
};

/// Seed of --shuffle's order, fixed so that every run times the same order.
constexpr std::uint64_t shuffle_seed = 20261201;

/// The order of a copied world's particles: index k of `order` names copy k / n of base
/// particle k % n (n = base_count); the copies one after another, or all shuffled at random.
std::vector<std::size_t> copy_order(std::size_t base_count, int copies, bool shuffle) {
  std::vector<std::size_t> order(base_count * static_cast<std::size_t>(copies));
  std::iota(order.begin(), order.end(), std::size_t{0});
  if (shuffle) {
    std::mt19937_64 random(shuffle_seed);
    std::shuffle(order.begin(), order.end(), random);
  }
  return order;
}

/// A new World of the base world's settings and walls (turned to the same angle) whose
/// periodic slab is `copies` times longer and holds `copies` copies of every particle, the
/// j-th shifted by j L0 along the axis; positions, velocities, spins and last forces copied,
/// contact springs started afresh.
template <int D>
millsim::World<D> copy_world(const millsim::World<D>& base, int copies, bool shuffle) {
  // A copy: lengthened in 3D (in 2D it is only read, which clang-tidy would flag).
  // NOLINTNEXTLINE(performance-unnecessary-copy-initialization)
  millsim::Walls<D> walls = base.walls();
  double period = 0.0;
  if constexpr (D == 3) {
    period = walls.mill->length;
    walls.mill->length = period * copies;
  }
  millsim::World<D> world(base.settings(), walls);
  const millsim::ParticleStore<D>& from = base.particles();
  millsim::ParticleStore<D>& to = world.particles();
  const std::vector<std::size_t> order = copy_order(from.size(), copies, shuffle);
  const auto reserve = [&](auto&... arrays) { (arrays.reserve(order.size()), ...); };
  reserve(to.position, to.velocity, to.angular_velocity, to.force, to.torque, to.radius, to.mass,
          to.inverse_mass, to.inverse_inertia);
  for (const std::size_t k : order) {
    const std::size_t i = k % from.size();
    millsim::Vec<D> at = from.position[i];
    const std::size_t copy = k / from.size();
    if constexpr (D == 3) at[2] += static_cast<double>(copy) * period;
    const std::size_t added =
        to.add(at, from.radius[i], from.mass[i], from.velocity[i], from.angular_velocity[i]);
    to.force[added] = from.force[i];
    to.torque[added] = from.torque[i];
  }
  return world;
}

/// Bytes per particle of the arrays the step keeps, from their element sizes: the particle
/// store, and World's and NeighbourList's per-particle and per-pair arrays as world.hpp and
/// neighbour_list.hpp hold them (a list to keep in step with those files), the pairs counted
/// by a neighbour list of the world's skin. Capacity slack, the search grid's cells and the
/// allocator's overhead are not in it.
struct ArrayEstimate {
  double bytes_per_particle = 0.0;
  double pairs_per_particle = 0.0;
};

template <int D>
ArrayEstimate estimate_array_bytes(const millsim::World<D>& world) {
  using millsim::ContactHistory;
  using millsim::Spin;
  using millsim::Vec;
  const millsim::ParticleStore<D>& p = world.particles();
  millsim::NeighbourList<D> list(world.neighbour_skin());
  if constexpr (D == 3) {
    if (world.walls().mill->periodic) list.set_period(world.walls().mill->length);
  }
  list.rebuild(p.position, p.radius);
  const double particles = static_cast<double>(p.size());
  const double pairs = static_cast<double>(list.pair_count());
  constexpr double index = sizeof(std::uint32_t);
  constexpr double store = 3 * sizeof(Vec<D>) + 2 * sizeof(Spin<D>) + 4 * sizeof(double);
  // u̇(n), r ω(n), r ω(n−½) where the world keeps it, the index of its wall-contact slots; per
  // wall candidate, the slots (id and history) and their rebuild copies.
  constexpr double world_per_particle =
      sizeof(Vec<D>) + (millsim::World<D>::keeps_step_rim ? 2 : 1) * sizeof(Spin<D>) + index;
  constexpr double world_per_candidate =
      2 * millsim::World<D>::max_wall_contacts * (sizeof(std::int32_t) + sizeof(ContactHistory<D>));
  const double candidates_per_particle =
      static_cast<double>(world.wall_candidate_count()) / std::max(1.0, particles);
  // Reference and cell-ordered positions, cell radii, home cells, four index arrays.
  constexpr double search_per_particle =
      2 * sizeof(Vec<D>) + sizeof(double) + sizeof(std::array<long, D>) + 4 * index;
  // An ended-collision slot (type and energy); on several threads also this step's status and
  // energy.
  const double world_per_pair =
      2 * sizeof(double) + (omp_get_max_threads() > 1 ? 1.0 + sizeof(double) : 0.0);
  // first, second and their rebuild copies, the search's found pair, the history, the
  // touching flag and the reach and their rebuild copies.
  constexpr double search_per_pair =
      4 * index + 2 * index +
      2 * (sizeof(ContactHistory<D>) + sizeof(millsim::TouchState) + sizeof(double));
  ArrayEstimate estimate;
  estimate.pairs_per_particle = pairs / std::max(1.0, particles);
  estimate.bytes_per_particle = store + world_per_particle + search_per_particle +
                                candidates_per_particle * world_per_candidate +
                                estimate.pairs_per_particle * (world_per_pair + search_per_pair);
  return estimate;
}

/// Length of the simulated mill along its axis, m (0 in 2D).
template <int D>
double axial_length(const millsim::World<D>& world) {
  if constexpr (D == 3) return world.walls().mill->length;
  return 0.0;
}

/// How the charge moves: kinetic energy per particle, J, and the fastest particle's speed, m/s
/// (whether a settled charge has come to rest).
struct Motion {
  double kinetic_energy_per_particle = 0.0;
  double fastest = 0.0;
};

template <int D>
Motion motion_of(const millsim::World<D>& world) {
  const auto& p = world.particles();
  Motion motion;
  for (const auto& v : p.velocity) {
    motion.fastest = std::max(motion.fastest, std::sqrt(millsim::dot(v, v)));
  }
  motion.kinetic_energy_per_particle =
      world.kinetic_energy() / std::max(1.0, static_cast<double>(p.size()));
  return motion;
}

/// What a run measured, for the report.
struct Measured {
  std::size_t base_particles = 0;
  Motion start;                  ///< of the timed world before it turns
  double prepare_seconds = 0.0;  ///< settling or loading, copying, warmup (wall clock)
  double wall_seconds = 0.0;     ///< of the timed steps
  double cpu_seconds = 0.0;      ///< of the timed steps, all threads
  long rebuilds = 0;             ///< neighbour-list rebuilds in the timed steps
  double resident_growth = 0.0;  ///< bytes
};

template <int D>
void report(const millsim::MillPlan& plan, const BenchOptions& options,
            const millsim::World<D>& world, const Measured& measured) {
  const double particles = static_cast<double>(world.particles().size());
  const double particle_steps = particles * static_cast<double>(options.steps);
  const bool copied = options.tile > 1 || options.shuffle;
  fmt::print("config            {}\n", plan.config.source);
  fmt::print("dimension         {}\n", D);
  if (options.tile > 1) {
    fmt::print("tiled             {} copies of the {}-particle slab: {:.4g} m long\n", options.tile,
               measured.base_particles, axial_length(world));
  }
  if (options.shuffle) {
    fmt::print("order             shuffled at random (seed {})\n", shuffle_seed);
  }
  fmt::print("particles         {}\n", world.particles().size());
  fmt::print("threads           {}\n", omp_get_max_threads());
  fmt::print("cell order        every {} neighbour-list rebuilds (0: never)\n", options.cell_order);
  fmt::print("time step         {:.4g} s\n", plan.time_step);
  fmt::print("start state       kinetic energy {:.3g} J per particle, fastest {:.3g} m/s\n",
             measured.start.kinetic_energy_per_particle, measured.start.fastest);
  if (options.load_path.empty()) {
    fmt::print("prepared in       {:.1f} s (settle {} s of mill time, then {} steps turning)\n",
               measured.prepare_seconds, plan.config.settle_time, options.warmup);
  } else {
    fmt::print("prepared in       {:.1f} s (state {}, then {} steps turning)\n",
               measured.prepare_seconds, options.load_path, options.warmup);
  }
  fmt::print("timed steps       {} in {:.2f} s at {:.4g} rpm ({:.2f} s of CPU time)\n",
             options.steps, measured.wall_seconds, plan.speed_rpm, measured.cpu_seconds);
  fmt::print("particle-steps/s  {:.4g} (wall clock); {:.4g} per CPU second\n",
             particle_steps / measured.wall_seconds, particle_steps / measured.cpu_seconds);
  fmt::print(
      "neighbour rebuilds {} ({:.1f} steps apart, skin {:.3g} mm at the end), {} contacts and {} "
      "wall candidates at the end\n",
      measured.rebuilds,
      static_cast<double>(options.steps) / static_cast<double>(std::max(1L, measured.rebuilds)),
      1e3 * world.neighbour_skin(), world.touching_contacts(), world.wall_candidate_count());
  fmt::print("real-time factor  {:.4g} (mill seconds per wall second)\n",
             static_cast<double>(options.steps) * plan.time_step / measured.wall_seconds);
  fmt::print("memory/particle   {:.0f} bytes (resident growth while building and running {})\n",
             std::max(0.0, measured.resident_growth) / particles,
             copied ? "the copied world" : "the world");
  const ArrayEstimate estimate = estimate_array_bytes(world);
  fmt::print(
      "memory estimate   {:.0f} bytes/particle from the array sizes ({:.2f} pairs listed "
      "per particle)\n",
      estimate.bytes_per_particle, estimate.pairs_per_particle);
}

template <int D>
int run(const millsim::MillPlan& plan, const BenchOptions& options) {
  Measured measured;
  const double resident_at_start = resident_bytes();
  millsim::World<D> base = millsim::build_mill_world<D>(plan);
  base.set_cell_order_interval(options.cell_order);
  const auto prepare_start = Clock::now();
  if (options.load_path.empty()) {
    while (base.time() < plan.config.settle_time) base.step();
  } else {
    load_state(base, options.load_path);
  }
  measured.base_particles = base.particles().size();
  // The copy is measured from here: the base world stays (it is small next to a tiled one).
  const bool copied = options.tile > 1 || options.shuffle;
  const double resident_before = copied ? resident_bytes() : resident_at_start;
  std::optional<millsim::World<D>> copy;
  if (copied) copy.emplace(copy_world(base, options.tile, options.shuffle));
  millsim::World<D>& world = copied ? *copy : base;
  world.set_cell_order_interval(options.cell_order);
  measured.start = motion_of(world);
  world.walls().mill->angular_speed = plan.angular_speed;
  for (long n = 0; n < options.warmup; ++n) world.step();
  measured.prepare_seconds = seconds_since(prepare_start);
  const long rebuilds_before = world.neighbour_rebuilds();
  const double cpu_start = cpu_seconds();
  const auto start = Clock::now();
  for (long n = 0; n < options.steps; ++n) world.step();
  measured.wall_seconds = seconds_since(start);
  measured.cpu_seconds = cpu_seconds() - cpu_start;
  measured.rebuilds = world.neighbour_rebuilds() - rebuilds_before;
  measured.resident_growth = resident_bytes() - resident_before;
  if (!options.save_path.empty()) save_state(world, options.save_path);
  report(plan, options, world, measured);
  return 0;
}

/// Refuses what --tile, --shuffle and --save-state cannot do together or with this config.
void check_options(const millsim::MillPlan& plan, const BenchOptions& options) {
  if (options.tile > 1 && (plan.config.dimension != 3 || !plan.config.periodic)) {
    throw millsim::InputError(
        fmt::format("--tile {}: {} is not a periodic 3D slab (needs simulation.dimension = 3 and "
                    "mill.periodic = true); only a slab invariant along its axis can be tiled",
                    options.tile, plan.config.source));
  }
  // As many particles as a mill may plan (charge.cpp): 5e7, about 55 GB at 1.1 kB a ball.
  constexpr double most_tiled = 5e7;
  const double tiled = static_cast<double>(options.tile) * static_cast<double>(plan.particle_count);
  if (tiled > most_tiled) {
    throw millsim::InputError(fmt::format(
        "--tile {}: {} copies of {} particles are {:.3g}; allowed: at most {:.0e} particles "
        "(about {:.0f} GB): --tile up to {} for this slab",
        options.tile, options.tile, plan.particle_count, tiled, most_tiled,
        most_tiled * 1.1e3 / 1e9,
        static_cast<long>(most_tiled / static_cast<double>(plan.particle_count))));
  }
  if ((options.tile > 1 || options.shuffle) && !options.save_path.empty()) {
    throw millsim::InputError(
        "--save-state: cannot be combined with --tile or --shuffle (the state would not be "
        "one of this config's)");
  }
  // A state file that cannot be written is found now, not after the settling and the timed
  // steps. (A file made for the check alone is removed again.)
  if (!options.save_path.empty()) {
    std::error_code error;
    const bool existed = std::filesystem::exists(options.save_path, error);
    const bool writable = static_cast<bool>(std::ofstream(options.save_path, std::ios::app));
    if (!existed) std::filesystem::remove(options.save_path, error);
    if (!writable) {
      throw millsim::InputError(
          fmt::format("--save-state: cannot write {}; allowed: a file path that can be written",
                      options.save_path));
    }
  }
}

/// The benchmark's command line and run; main catches what it lets through.
int run_bench(int argc, char** argv) {
  CLI::App app{"millsim_scene_bench: particle-steps per second of a mill scene"};
  std::string config_path;
  BenchOptions options;
  int threads = 0;
  std::vector<std::string> overrides;
  app.add_option("config", config_path, "mill config (TOML)")->required();
  app.add_option("--steps", options.steps, "steps to time after settling and spin-up")
      ->check(CLI::Range(1L, 1000000000L))
      ->capture_default_str();
  app.add_option("--warmup", options.warmup, "untimed steps at full speed after settling")
      ->check(CLI::Range(0L, 1000000000L))
      ->capture_default_str();
  app.add_option("-j,--threads", threads, "threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
  app.add_option("--set", overrides, "override a config key (repeatable)");
  app.add_option("--load-state", options.load_path, "start from this state instead of settling");
  app.add_option("--save-state", options.save_path, "write the state after the timed steps here");
  app.add_option("--tile", options.tile,
                 "time K copies of the settled periodic slab, end to end along the axis (a "
                 "periodic 3D slab only; at most 5e7 particles in all)")
      ->check(CLI::Range(1, 1000000));
  app.add_option("--cell-order", options.cell_order,
                 "renumber particles into cell order every N rebuilds, 0 never (default: as "
                 "millsim run, " +
                     std::to_string(millsim::cell_order_interval) + ")")
      ->check(CLI::Range(0, 1000000));
  app.add_flag("--shuffle", options.shuffle,
               "put the timed particles in an order drawn at random (fixed seed)");
  CLI11_PARSE(app, argc, argv);
  if (threads > 0) omp_set_num_threads(threads);
  try {
    const millsim::MillPlan plan =
        millsim::plan_mill(millsim::load_mill_config(config_path, overrides));
    check_options(plan, options);
    return plan.config.dimension == 2 ? run<2>(plan, options) : run<3>(plan, options);
  } catch (const millsim::InputError& error) {
    fmt::print(stderr, "millsim_scene_bench: error: {}\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "millsim_scene_bench: failed: %s\n", error.what());
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run_bench(argc, argv);
  } catch (...) {
    std::fputs("millsim_scene_bench: failed: an unknown error\n", stderr);
  }
  return 1;
}
