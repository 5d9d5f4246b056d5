// Micro-benchmarks (Google Benchmark): one stage of the step at a time on a settled charge,
// for work on that stage, where scene_bench.cpp times whole steps (results in
// bench/results.md). So far the neighbour-list rebuild, on one and on two threads.
//
//   millsim_micro_bench [--config FILE] [--set KEY=VALUE ...] [--settle-seconds S]
//                       [Google Benchmark's flags: --benchmark_filter=...,
//                       --benchmark_repetitions=N]
//
// The charge is the config's mill (default: the 2D SAG scene, bench/sag-12m-2d.toml) settled
// for the config's settle_time, or S seconds of mill time (0: as placed, after the one step
// that chooses the skin).

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <omp.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <variant>
#include <vector>

#include "millsim/core/error.hpp"
#include "millsim/io/config.hpp"
#include "millsim/search/neighbour_list.hpp"
#include "millsim/sim/charge.hpp"
#include "millsim/sim/world_detail.hpp"

namespace {

/// What the benchmarks start from: the settled charge's positions and radii, the skin the
/// world chose at its last rebuild, and the period of a periodic slab's axis (0: none).
template <int D>
struct Charge {
  std::vector<millsim::Vec<D>> position;
  std::vector<double> radius;
  double skin = 0.0;
  double period = 0.0;
};

template <int D>
Charge<D> settled_charge(const millsim::MillPlan& plan, double settle_seconds) {
  millsim::World<D> world = millsim::build_mill_world<D>(plan);
  while (world.time() < settle_seconds) world.step();
  if (world.neighbour_rebuilds() == 0) world.step();  // a skin chosen for this charge
  double period = 0.0;
  if constexpr (D == 3) {
    const auto& mill = world.walls().mill;
    if (mill && mill->periodic) period = mill->length;  // as World sets its list's
  }
  return {world.particles().position, world.particles().radius, world.neighbour_skin(), period};
}

/// The charge the benchmarks time: settled in main before they run.
std::variant<std::monostate, Charge<2>, Charge<3>> the_charge;

/// A rebuild of the charge's list, the particles where they are (the histories carried from
/// the list before, which holds the same pairs) and not renumbered: NeighbourList::rebuild as
/// World calls it between cell orderings, on as many threads (state.range(0)) and asked to run
/// on them where World would be, but with the particles shared evenly among them (World shares
/// them as its step's runs).
template <int D>
void rebuild_list(benchmark::State& state, const Charge<D>& charge) {
  const int threads = static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  millsim::NeighbourList<D> list(charge.skin);
  list.set_period(charge.period);
  list.rebuild(charge.position, charge.radius, false);
  list.set_parallel(millsim::world_detail::splits_among_threads(list.pair_count(), threads));
  for (auto _ : state) {
    list.rebuild(charge.position, charge.radius, false);
    benchmark::DoNotOptimize(list.pair_count());
  }
  state.counters["dimension"] = D;
  state.counters["particles"] = static_cast<double>(charge.position.size());
  state.counters["pairs"] = static_cast<double>(list.pair_count());
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(charge.position.size()));
}

void neighbour_rebuild(benchmark::State& state) {
  if (const auto* discs = std::get_if<Charge<2>>(&the_charge)) {
    rebuild_list(state, *discs);
  } else if (const auto* balls = std::get_if<Charge<3>>(&the_charge)) {
    rebuild_list(state, *balls);
  } else {
    state.SkipWithError("no charge");
  }
}
BENCHMARK(neighbour_rebuild)
    ->Arg(1)
    ->Arg(2)
    ->ArgName("threads")
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);

/// This program's own flags (CLI11); the others go to Google Benchmark.
struct Options {
  std::string config = MILLSIM_SOURCE_DIR "/bench/sag-12m-2d.toml";
  std::vector<std::string> overrides;
  double settle_seconds = -1.0;  // < 0: the config's settle_time
};

int run(int argc, char** argv) {
  CLI::App app{"millsim_micro_bench: one stage of the step at a time on a settled charge"};
  Options options;
  app.add_option("--config", options.config, "mill config (TOML)")->capture_default_str();
  app.add_option("--set", options.overrides, "override a config key (repeatable)");
  app.add_option("--settle-seconds", options.settle_seconds,
                 "settle the charge for this many seconds of mill time (default: the config's "
                 "settle_time; 0: as placed, after the one step that chooses the skin)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            char* end = nullptr;
            const double seconds = std::strtod(text.c_str(), &end);
            const bool allowed =
                end != text.c_str() && *end == '\0' && std::isfinite(seconds) && seconds >= 0.0;
            return allowed ? "" : "must be a finite number of seconds >= 0, not '" + text + "'";
          },
          "SECONDS >= 0"));
  app.allow_extras();
  app.footer(
      "Other flags go to Google Benchmark: --benchmark_filter=REGEX, "
      "--benchmark_repetitions=N, --benchmark_min_time=SECONDS, "
      "--benchmark_format=console|json|csv, --benchmark_out=FILE, ...");
  CLI11_PARSE(app, argc, argv);
  // Google Benchmark's flags read (an unknown flag refused) before the charge settles.
  std::vector<std::string> passed{argv[0]};
  for (const std::string& flag : app.remaining()) passed.push_back(flag);
  std::vector<char*> passed_argv;
  passed_argv.reserve(passed.size());
  for (std::string& flag : passed) passed_argv.push_back(flag.data());
  int passed_argc = static_cast<int>(passed_argv.size());
  benchmark::Initialize(&passed_argc, passed_argv.data());
  if (benchmark::ReportUnrecognizedArguments(passed_argc, passed_argv.data())) {
    std::fputs("millsim_micro_bench: see --help for the flags allowed\n", stderr);
    return 2;
  }
  try {
    const millsim::MillPlan plan =
        millsim::plan_mill(millsim::load_mill_config(options.config, options.overrides));
    const double settle =
        options.settle_seconds >= 0.0 ? options.settle_seconds : plan.config.settle_time;
    if (plan.config.dimension == 2) {
      the_charge = settled_charge<2>(plan, settle);
    } else {
      the_charge = settled_charge<3>(plan, settle);
    }
  } catch (const millsim::InputError& error) {
    fmt::print(stderr, "millsim_micro_bench: error: {}\n", error.what());
    return 2;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "millsim_micro_bench: failed: %s\n", error.what());
  } catch (...) {
    std::fputs("millsim_micro_bench: failed: an unknown error\n", stderr);
  }
  return 1;
}
