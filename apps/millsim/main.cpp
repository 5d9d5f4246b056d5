// millsim: the command-line program. `millsim --help` lists the commands.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <omp.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iterator>
#include <mutex>
#include <new>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <variant>
#include <vector>

#include "millsim/builtin_example.hpp"
#include "millsim/core/error.hpp"
#include "millsim/core/version.hpp"
#include "millsim/io/config.hpp"
#include "millsim/io/output.hpp"
#include "millsim/io/partial_file.hpp"
#include "millsim/measure/empirical_power.hpp"
#include "millsim/sim/mill_run.hpp"
#include "millsim/sim/scene_run.hpp"
#include "millsim/sim/sweep.hpp"
#include "output_directory.hpp"

namespace {

using millsim::Allowed;
using millsim::limit_text;
using millsim::MillConfig;
using millsim::MillPlan;
using millsim::MillResult;
using millsim_app::check_output_directory;
using millsim_app::EarlierResults;
using millsim_app::move_results_aside;
using millsim_app::prepare_output_directory;
using millsim_app::refuse_a_file_as_directory;
using millsim_app::Snapshots;

struct JobOptions {
  std::string config_path;  // empty: the built-in example
  std::vector<std::string> overrides;
  std::string output_directory;  // empty: from the config
  bool quiet = false;
  int threads = 0;  // 0: all available cores
};

/// The config, with --out (a path as typed, not a TOML value) in place of output.directory.
MillConfig load(const JobOptions& options) {
  MillConfig config = options.config_path.empty()
                          ? millsim::parse_mill_config(millsim::builtin_example_toml,
                                                       std::string(millsim::builtin_example_name),
                                                       options.overrides)
                          : millsim::load_mill_config(options.config_path, options.overrides);
  if (!options.output_directory.empty()) config.output_directory = options.output_directory;
  return config;
}

/// A mill or a scene config (a file without [mill] is a scene).
millsim::JobConfig load_job(const JobOptions& options) {
  if (options.config_path.empty()) return load(options);
  millsim::JobConfig job = millsim::load_config(options.config_path, options.overrides);
  if (!options.output_directory.empty()) {
    std::visit([&](auto& config) { config.output_directory = options.output_directory; }, job);
  }
  return job;
}

/// A single progress line on stderr, redrawn in place; only when stderr is a terminal.
class ProgressLine {
 public:
  explicit ProgressLine(bool enabled) : enabled_(enabled && isatty(fileno(stderr)) != 0) {}
  ~ProgressLine() { clear(); }
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  void operator()(double time, double total, double revolutions) {
    if (!enabled_) return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double fraction = std::min(1.0, time / total);
    const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
    // revolutions < 0: a scene, which has none.
    const std::string turned =
        revolutions >= 0.0 ? fmt::format("  revolutions {:.2f}", revolutions) : std::string();
    fmt::print(stderr, "\r{:5.1f}%  t = {:.4g} of {:.4g} s{}  ETA {:.0f} s   ", 100.0 * fraction,
               time, total, turned, eta);
    std::fflush(stderr);
    drawn_ = true;
  }
  void clear() {
    if (drawn_) fmt::print(stderr, "\r{:80}\r", "");
    drawn_ = false;
  }

 private:
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// Where the output directory was given: --out, or the config's key (or --set).
template <typename Config>
std::string output_location(const Config& config, const JobOptions& options) {
  if (!options.output_directory.empty()) {
    return fmt::format("command line (--out {})", options.output_directory);
  }
  return config.location_of("output.directory");
}

/// Prints each warning on stderr as "millsim: warning: [CONTEXT: ]TEXT" (sweep points print
/// from several threads).
void warn(const std::vector<std::string>& warnings, std::string_view context = {}) {
  static std::mutex printing;
  for (const std::string& text : warnings) {
    const std::lock_guard lock(printing);
    fmt::print(stderr, "millsim: warning: {}{}{}\n", context, context.empty() ? "" : ": ", text);
  }
}

/// Warns, once, when more threads are asked for than there are cores: the threads that share
/// a step wait for each other at its end, and some are always waiting for a core (a 1215-ball
/// 3D mill: 2.5 s on one thread, 64 s on 64, on two cores). Called as a job starts to run, so
/// that a refused config says only why.
void warn_of_more_threads_than_cores() {
  static std::once_flag once;
  std::call_once(once, [] {
    const int threads = omp_get_max_threads();
    const int cores = omp_get_num_procs();
    if (threads <= cores) return;
    warn(
        {fmt::format("{} threads on {} core{}: the threads that share a step wait for each "
                     "other at its end, so it can run many times slower than with -j {} (the "
                     "results are the same)",
                     threads, cores, cores == 1 ? "" : "s", cores)});
  });
}

/// What a run clears in its output directory (besides snapshots/), of a mill or a scene, run
/// alone or as a sweep's point or a validation's case: the results of both kinds, so that a
/// scene run where a mill ran (or the other way round) leaves none of the other's beside its
/// own summary.json. Sweeps and validations check and clear the same names before any runs.
constexpr std::initializer_list<const char*> run_result_names = {
    "summary.json",       "power.csv",   "power_timeseries.csv", "spectrum.csv",
    "charge_profile.csv", "impacts.csv", "trajectory.csv",       "final.csv"};

/// Plans, places the charge, and only then creates the output directory, calls `started`,
/// gives the plan's warnings and runs, so that a config that cannot run writes nothing and
/// says nothing but why. The results' own warnings follow the run.
/// `context` starts each warning of the plan and of the output directory (a sweep's point).
template <int D>
MillResult run_job(const MillPlan& plan, const std::string& out_location, bool show_progress,
                   const std::function<void()>& started = {}, std::string_view context = {}) {
  const MillConfig& config = plan.config;
  millsim::World<D> world = millsim::build_mill_world<D>(plan);
  const std::filesystem::path out = config.output_directory;
  const std::vector<std::string> cleared = prepare_output_directory(
      out, out_location, run_result_names,
      config.snapshot_interval > 0.0 ? Snapshots::made : Snapshots::removed);
  if (started) started();
  warn(cleared, context);
  warn(plan.warnings, context);
  const std::filesystem::path snapshots = out / "snapshots";
  ProgressLine progress(show_progress);
  MillResult result = millsim::run_mill(plan, std::move(world), snapshots, std::ref(progress));
  progress.clear();
  millsim::write_results(out, result);
  warn(millsim::result_warnings(result), fmt::format("results in {}/", config.output_directory));
  return result;
}

MillResult run_job(const MillConfig& config, const std::string& out_location, bool show_progress,
                   const std::function<void()>& started) {
  const MillPlan plan = millsim::plan_mill(config);
  return config.dimension == 2 ? run_job<2>(plan, out_location, show_progress, started)
                               : run_job<3>(plan, out_location, show_progress, started);
}

/// Runs a scene (particles and walls, no mill): plans first so that a config that cannot run
/// writes nothing.
int run_scene_command(const millsim::SceneConfig& scene, const JobOptions& options) {
  const millsim::ScenePlan plan = millsim::plan_scene(scene);
  const std::filesystem::path out = scene.output_directory;
  const std::vector<std::string> cleared = prepare_output_directory(
      out, output_location(scene, options), run_result_names, Snapshots::removed);
  if (!options.quiet) fmt::print("millsim: running scene {}\n", scene.source);
  warn_of_more_threads_than_cores();
  warn(cleared);
  warn(plan.warnings);
  ProgressLine progress(!options.quiet);
  const millsim::SceneResult result = millsim::run_scene(
      plan, out, [&](double time, double total) { progress(time, total, -1.0); });
  progress.clear();
  warn(millsim::scene_result_warnings(result),
       fmt::format("results in {}/", scene.output_directory));
  fmt::print("{}\n", millsim::scene_summary_line(result));
  if (!options.quiet) {
    fmt::print("results in {}/ (summary.json, trajectory.csv, final.csv)\n",
               scene.output_directory);
  }
  return 0;
}

int run_command(const JobOptions& options) {
  const millsim::JobConfig job = load_job(options);
  if (const auto* scene = std::get_if<millsim::SceneConfig>(&job)) {
    return run_scene_command(*scene, options);
  }
  const MillConfig& config = std::get<MillConfig>(job);
  const MillResult result = run_job(config, output_location(config, options), !options.quiet, [&] {
    if (!options.quiet) fmt::print("millsim: running {}\n", config.source);
    warn_of_more_threads_than_cores();
  });
  fmt::print("{}\n", millsim::summary_line(result));
  if (!options.quiet) {
    fmt::print(
        "results in {}/ (summary.json, power.csv, power_timeseries.csv, spectrum.csv, "
        "charge_profile.csv, impacts.csv)\n",
        config.output_directory);
  }
  return 0;
}

int scene_info(const millsim::SceneConfig& scene) {
  const millsim::ScenePlan plan = millsim::plan_scene(scene);
  fmt::print("config                {}\n", scene.source);
  fmt::print(
      "scene                 {}D, {} {}, {} plane {}, gravity {}\n", scene.dimension,
      scene.particles.size(), scene.particles.size() == 1 ? "particle" : "particles",
      scene.walls.size(), scene.walls.size() == 1 ? "wall" : "walls",
      fmt::join(std::span(scene.gravity).first(static_cast<std::size_t>(scene.dimension)), ", "));
  if (plan.shortest_contact > 0.0) {
    fmt::print("shortest contact      {:.4g} s\n", plan.shortest_contact);
    fmt::print("time step             {:.4g} s{} (stability limit {} s)\n", plan.time_step,
               scene.time_step ? "" : " (auto)",
               limit_text(plan.critical_time_step, Allowed::below));
  } else {
    fmt::print("shortest contact      none (nothing can touch)\n");
    fmt::print("time step             {:.4g} s{}\n", plan.time_step,
               scene.time_step ? "" : " (auto: 1/1000 of the duration)");
  }
  const std::string rows = plan.trajectory_every > 0
                               ? fmt::format("every {} steps", plan.trajectory_every)
                               : std::string("start and end only");
  fmt::print("simulated time        {:.4g} s: {} steps; trajectory rows {}\n", scene.duration,
             plan.steps, rows);
  warn(plan.warnings);
  return 0;
}

/// The most particles `info` places to check that the charge fits (about a second).
constexpr double most_placed_by_info = 2e5;

int info_command(const JobOptions& options) {
  const millsim::JobConfig job = load_job(options);
  if (const auto* scene = std::get_if<millsim::SceneConfig>(&job)) return scene_info(*scene);
  const MillPlan plan = millsim::plan_mill(std::get<MillConfig>(job));
  const MillConfig& c = plan.config;
  // The charge placed as `run` places it, before anything is printed, so that a filling the
  // mill cannot hold is refused here too (InputError naming charge.filling). Not for the
  // largest plans, whose placement alone takes a while and their memory.
  const bool place = static_cast<double>(plan.particle_count) <= most_placed_by_info;
  if (place && c.dimension == 2) (void)millsim::build_mill_world<2>(plan);
  if (place && c.dimension == 3) (void)millsim::build_mill_world<3>(plan);
  warn(plan.warnings);
  fmt::print("config                {}\n", c.source);
  const std::string lifters = c.lifter_count == 0
                                  ? std::string("no lifters")
                                  : fmt::format("{} {} {} x {} m (height x width)", c.lifter_count,
                                                c.lifter_count == 1 ? "lifter" : "lifters",
                                                c.lifter_height, c.lifter_width);
  fmt::print("mill                  {} m x {} m, {}\n", c.diameter, c.length, lifters);
  fmt::print("critical speed        {:.4g} rpm (largest ball {} m)\n", plan.critical_speed_rpm,
             plan.largest_ball);
  fmt::print("speed                 {:.4g} rpm = {:.1f}% of critical, {:.4g} s per revolution\n",
             plan.speed_rpm, 100.0 * plan.speed_fraction, plan.revolution_period);
  fmt::print("charge                filling {}, porosity {}, density {} kg/m3; {}\n", c.filling,
             c.porosity, c.density, c.size_description);
  const bool flat = c.dimension == 2;
  for (const auto& d : plan.discs) {
    fmt::print("  {}               {:5d} x {:.4g} m, {:.4g} kg each\n", flat ? "discs" : "balls",
               d.count, d.diameter, d.mass);
  }
  fmt::print("particles             {}, {}\n", plan.particle_count,
             place ? "placed without overlap as run places them"
                   : fmt::format("placement not tried by info (more than {:.0f}); run places them",
                                 most_placed_by_info));
  if (flat) {
    fmt::print("model                 2D slice of discs, power scaled by charge mass\n");
  } else if (c.periodic) {
    fmt::print("model                 3D periodic slab {} m long, power scaled to the {} m mill\n",
               c.slab_length, c.length);
  } else if (c.cone_length > 0.0) {
    fmt::print(
        "model                 3D whole mill with conical ends: {} m long each at {} "
        "degrees, trunnion radius {:.4g} m; {:.4g} m3 and a bed of {:.4g} m3 in each "
        "cone\n",
        c.cone_length, c.cone_angle_degrees, plan.trunnion_radius, plan.cone_volume,
        plan.cone_bed_volume);
  } else {
    fmt::print("model                 3D whole mill with flat end plates\n");
  }
  fmt::print("{:<22}{:.4g} kg; whole mill {:.4g} kg; power scale {:.4g}\n",
             flat ? "slice charge mass" : "simulated charge mass", plan.slice_mass,
             plan.mill_charge_mass, plan.power_scale);
  fmt::print("contact duration      ball-ball {:.4g} s, ball-wall {:.4g} s (smallest balls)\n",
             plan.contact_duration_ball_ball, plan.contact_duration_ball_wall);
  fmt::print("time step             {:.4g} s{} (stability limit {} s)\n", plan.time_step,
             c.time_step ? "" : " (auto)", limit_text(plan.critical_time_step, Allowed::below));
  const double steps = plan.total_time / plan.time_step;
  fmt::print(
      "simulated time        {:.4g} s: settle {} s, then {} {} from a spin-up of {:.4g} s; "
      "{:.3g} steps\n",
      plan.total_time, c.settle_time, c.revolutions,
      c.revolutions == 1 ? "revolution" : "revolutions", plan.spin_up_time, steps);
  if (plan.snapshot_count > 0.0) {
    fmt::print("snapshots             every {} s: {:.0f} ({}), up to about {}\n",
               c.snapshot_interval, plan.snapshot_count,
               c.snapshot_csv && c.snapshot_vtk ? "CSV and VTK" : (c.snapshot_vtk ? "VTK" : "CSV"),
               plan.snapshot_bytes >= 1e9 ? fmt::format("{:.3g} GB", plan.snapshot_bytes / 1e9)
                                          : fmt::format("{:.3g} MB", plan.snapshot_bytes / 1e6));
  } else {
    fmt::print("snapshots             none (output.snapshot_interval = 0)\n");
  }
  const millsim::EmpiricalPower empirical = millsim::empirical_power(plan);
  fmt::print("empirical power       {}, Hogg-Fuerstenau {:.4g} kW, Morrell net {:.4g} kW\n",
             millsim::bond_power_text(empirical.bond), empirical.hogg_fuerstenau.power_kw,
             empirical.morrell.net_kw);
  return 0;
}

/// validate and sweep write each case or point to a directory of its own under --out: a
/// `--set output.directory` there would be ignored, so it is refused.
void refuse_output_directory_set(const JobOptions& options, const char* command) {
  for (const std::string& setting : options.overrides) {
    // Trimmed as the config reader trims a --set key (io/toml_reader.cpp).
    constexpr const char* blank = " \t\r\n";
    std::string key = setting.substr(0, setting.find('='));
    key.erase(0, key.find_first_not_of(blank));
    key.erase(key.find_last_not_of(blank) + 1);
    if (key == "output.directory") {
      throw millsim::InputError(fmt::format(
          "command line (--set {}): output.directory: {} writes each run to a directory of its "
          "own under -o/--out; allowed: -o/--out DIR",
          setting, command));
    }
  }
}

/// Runs every config of `directory` (each with a [reference] table) and prints millsim's power
/// against the measured one and the paper's. Every config is read and planned before any runs,
/// so that a bad one refuses the whole validation and writes nothing.
int validate_command(const std::string& directory, const JobOptions& options) {
  const auto refuse_directory = [&](const std::string& what) {
    return millsim::InputError(fmt::format(
        "command line (validate {}): {}; allowed: a directory of *.toml mill configs, each with "
        "a [reference] table (default examples/validation)",
        directory, what));
  };
  if (!std::filesystem::is_directory(directory)) {
    throw refuse_directory(std::filesystem::exists(directory) ? "not a directory"
                                                              : "no such directory");
  }
  std::vector<std::filesystem::path> cases;
  for (const auto& entry : std::filesystem::directory_iterator(directory)) {
    if (entry.path().extension() == ".toml") cases.push_back(entry.path());
  }
  std::sort(cases.begin(), cases.end());
  if (cases.empty()) throw refuse_directory("no *.toml configs in it");
  refuse_output_directory_set(options, "validate");
  const std::filesystem::path root =
      options.output_directory.empty() ? "runs/validation" : options.output_directory;
  const std::string root_location =
      options.output_directory.empty()
          ? std::string("the default output directory (runs/validation)")
          : fmt::format("command line (--out {})", options.output_directory);
  // The table's name, OUT/validation.csv, is checked before any case is read: a directory
  // there would fail the validation only once every case had run.
  const std::filesystem::path table_path = root / "validation.csv";
  for (const std::filesystem::path& name :
       {table_path, std::filesystem::path(table_path.string() + ".partial")}) {
    std::error_code unknown;
    if (std::filesystem::is_directory(name, unknown)) {
      throw millsim::InputError(fmt::format(
          "{}: \"{}\" is a directory, where validate writes its table; allowed: an output "
          "directory without a directory of that name (remove or rename it)",
          root_location, name.string()));
    }
  }
  // OUT itself, if it is there, as a sweep checks its own: one that cannot take files is
  // refused before any case runs (a case's directory not yet made has nothing to check).
  check_output_directory(root, root_location, {"validation.csv"});
  std::vector<MillPlan> plans;
  for (const auto& path : cases) {
    // A case's results go to OUT/<its stem>: "...toml" has the stem "..", whose results went
    // to OUT's parent and cleared what a run's results replace there (snapshots/ among them).
    if (path.stem() == "." || path.stem() == "..") {
      throw millsim::InputError(fmt::format(
          "{}: a case named \"{}\" would write its results to {}, outside {}; allowed: a case "
          "file whose name without .toml is neither . nor ..",
          path.string(), path.stem().string(), (root / path.stem()).string(), root.string()));
    }
    if (path.stem() == table_path.filename()) {
      throw millsim::InputError(fmt::format(
          "{}: a case named {} would write its results where validate writes its table, {}; "
          "allowed: any other name",
          path.string(), path.stem().string(), table_path.string()));
    }
    MillConfig config = millsim::load_mill_config(path.string(), options.overrides);
    if (!config.reference) {
      throw millsim::InputError(fmt::format(
          "{}: [reference]: missing; allowed: a validation config has a [reference] table with "
          "case, measured_power_kw, and optionally paper_power_kw and tolerance",
          path.string()));
    }
    // The table's rows are named by case: two of one name could not be told apart.
    for (std::size_t k = 0; k < plans.size(); ++k) {
      if (plans[k].config.reference->case_name == config.reference->case_name) {
        throw millsim::InputError(fmt::format(
            "{}: [reference]: case = \"{}\" is the case of {} too; allowed: a name of its own "
            "for each case",
            config.location_of("reference.case"), config.reference->case_name, cases[k].string()));
      }
    }
    config.output_directory = (root / path.stem()).string();
    refuse_a_file_as_directory(config.output_directory, root_location);
    // What clearing the case's earlier results would refuse is refused before any case runs,
    // as a sweep refuses it for its points.
    check_output_directory(config.output_directory, root_location, run_result_names,
                           config.snapshot_interval > 0.0 ? Snapshots::made : Snapshots::removed);
    MillPlan plan = millsim::plan_mill(config);
    // The charge placed as run places it (as info does), so that a filling the mill cannot
    // hold refuses the validation before any case runs.
    if (static_cast<double>(plan.particle_count) <= most_placed_by_info) {
      if (plan.config.dimension == 2) (void)millsim::build_mill_world<2>(plan);
      if (plan.config.dimension == 3) (void)millsim::build_mill_world<3>(plan);
    }
    plans.push_back(std::move(plan));
  }
  struct Row {
    std::string name;
    double measured = 0.0, predicted = 0.0, tolerance = 0.0;
    std::optional<double> paper;
    std::optional<std::string> failure;  // why the case did not finish, if it did not
  };
  std::vector<Row> rows(plans.size());
  // Every case's earlier results and the earlier table are moved aside before any case runs,
  // all put back if one cannot be (a refusal clears nothing), then removed: a validation
  // stopped half-way leaves its own cases' results and nothing of another's (each case once
  // cleared only its own directory as it started, so an interrupted validation left the cases
  // not yet run holding the earlier one's results).
  {
    std::vector<EarlierResults> aside;
    try {
      for (const MillPlan& plan : plans) {
        const std::filesystem::path out = plan.config.output_directory;
        std::error_code error;  // (a link to a directory is one too)
        if (!std::filesystem::is_directory(std::filesystem::status(out, error))) continue;
        aside.push_back(
            move_results_aside(out, root_location, run_result_names, Snapshots::removed));
      }
      std::error_code error;
      if (std::filesystem::is_directory(std::filesystem::status(root, error))) {
        aside.push_back(move_results_aside(root, root_location, {"validation.csv"}));
      }
    } catch (...) {
      for (auto back = aside.rbegin(); back != aside.rend(); ++back) (void)back->put_back("");
      throw;
    }
    for (EarlierResults& results : aside) warn(results.remove(), results.location);
  }
  std::mutex starting;
  // The cases as a sweep's points: as many at a time as there are threads (the small mills
  // gain little from a second thread), a progress line only when they run one at a time.
  const millsim::ThreadShare share = millsim::share_threads(omp_get_max_threads(), plans.size());
  warn_of_more_threads_than_cores();
  millsim::run_shared(plans.size(), share, [&](std::size_t i) {
    const MillPlan& plan = plans[i];
    const MillConfig& config = plan.config;
    const auto started = [&] {
      const std::lock_guard lock(starting);
      if (!options.quiet) fmt::print(stderr, "running {} ...\n", config.source);
    };
    const bool progress = !options.quiet && share.at_a_time <= 1;
    // Each case's warnings name it: the cases may run together.
    const std::string context = fmt::format("case {}", config.source);
    rows[i] = {config.reference->case_name, config.reference->measured_kw, 0.0,
               config.reference->tolerance, config.reference->paper_kw,    std::nullopt};
    // A case that fails while running (a full disk, a run that diverged) is reported in its
    // row, as a sweep's point is, and the others' results still make the table.
    try {
      const MillResult result = config.dimension == 2
                                    ? run_job<2>(plan, root_location, progress, started, context)
                                    : run_job<3>(plan, root_location, progress, started, context);
      rows[i].predicted = result.power_kw;
    } catch (const std::bad_alloc&) {
      rows[i].failure = "out of memory";
    } catch (const std::exception& error) {
      rows[i].failure = error.what();
    }
    if (rows[i].failure) {
      const std::lock_guard lock(starting);
      fmt::print(stderr, "millsim: {} failed: {}\n", context, *rows[i].failure);
    }
  });
  fmt::print("{:<8} {:>12} {:>12} {:>12} {:>9} {:>10}  {}\n", "case", "measured_kW", "paper_kW",
             "millsim_kW", "error_%", "paper_err%", "within");
  int failures = 0;
  int failed_runs = 0;
  std::string table = millsim::csv_line({"case", "measured_power_kw", "paper_power_kw", "power_kw",
                                         "error", "paper_error", "tolerance", "within"});
  for (const Row& r : rows) {
    const std::string paper_error_value =
        r.paper ? fmt::format("{}", (*r.paper - r.measured) / r.measured) : "";
    if (r.failure) {
      ++failed_runs;
      table += millsim::csv_line({r.name, fmt::format("{}", r.measured),
                                  r.paper ? fmt::format("{}", *r.paper) : "", "", "",
                                  paper_error_value, fmt::format("{}", r.tolerance), "failed"});
      fmt::print("{:<8} {:>12.4g} {:>12} {:>12} {:>9} {:>10}  failed (see above)\n", r.name,
                 r.measured, r.paper ? fmt::format("{:.4g}", *r.paper) : std::string("n/a"), "", "",
                 "");
      continue;
    }
    const double error = (r.predicted - r.measured) / r.measured;
    const bool ok = std::abs(error) <= r.tolerance;
    failures += ok ? 0 : 1;
    table += millsim::csv_line(
        {r.name, fmt::format("{}", r.measured), r.paper ? fmt::format("{}", *r.paper) : "",
         fmt::format("{}", r.predicted), fmt::format("{}", error), paper_error_value,
         fmt::format("{}", r.tolerance), ok ? "yes" : "no"});
    // A case without the paper's figure shows n/a in its two columns.
    const std::string paper = r.paper ? fmt::format("{:.4g}", *r.paper) : std::string("n/a");
    const std::string paper_error =
        r.paper ? fmt::format("{:+.1f}", 100.0 * (*r.paper - r.measured) / r.measured)
                : std::string("n/a");
    // One decimal, or more where one would read as within the tolerance (−15.04 % as
    // "-15.0" beside "NO (±15%)").
    std::string percent = fmt::format("{:+.1f}", 100.0 * error);
    for (int decimals = 2; !ok && decimals < 12; ++decimals) {
      double read = 0.0;
      std::from_chars(percent.data() + (percent[0] == '+' ? 1 : 0), percent.data() + percent.size(),
                      read);
      if (std::abs(read) > 100.0 * r.tolerance) break;
      percent = fmt::format("{:+.{}f}", 100.0 * error, decimals);
    }
    fmt::print("{:<8} {:>12.4g} {:>12} {:>12.4g} {:>9} {:>10}  {} (±{:.3g}%)\n", r.name, r.measured,
               paper, r.predicted, percent, paper_error, ok ? "yes" : "NO", 100.0 * r.tolerance);
  }
  millsim::write_whole_file(table_path, table);
  if (!options.quiet) fmt::print(stderr, "table in {}\n", table_path.string());
  if (failed_runs > 0) {
    fmt::print(stderr, "millsim: {} of {} cases failed to run\n", failed_runs, rows.size());
  }
  if (failures > 0) {
    fmt::print(stderr, "millsim: {} of {} cases outside their tolerance\n", failures, rows.size());
  }
  return failures > 0 || failed_runs > 0 ? 1 : 0;
}

/// Reads every point's config and plans it before running any, so that a bad key or value
/// refuses the whole sweep and writes nothing.
std::vector<MillPlan> plan_sweep(const JobOptions& options,
                                 const std::vector<millsim::SweepAxis>& axes,
                                 const std::vector<std::vector<std::string>>& points,
                                 const std::filesystem::path& root) {
  std::vector<MillPlan> plans;
  for (std::size_t i = 0; i < points.size(); ++i) {
    JobOptions point = options;
    point.output_directory.clear();
    const std::vector<std::string> settings = millsim::point_overrides(axes, points[i]);
    point.overrides.insert(point.overrides.end(), settings.begin(), settings.end());
    try {
      MillConfig config = load(point);
      config.output_directory =
          (root / millsim::point_directory_name(i, points.size(), axes, points[i])).string();
      MillPlan plan = millsim::plan_mill(config);
      // The charge placed as the run places it (as validate does), so that a filling the mill
      // cannot hold refuses the sweep before any point runs.
      if (static_cast<double>(plan.particle_count) <= most_placed_by_info) {
        if (plan.config.dimension == 2) (void)millsim::build_mill_world<2>(plan);
        if (plan.config.dimension == 3) (void)millsim::build_mill_world<3>(plan);
      }
      plans.push_back(std::move(plan));
    } catch (const millsim::InputError& error) {
      throw millsim::InputError(
          fmt::format("sweep point {} ({}): {}", i, fmt::join(settings, ", "), error.what()));
    }
  }
  return plans;
}

/// Runs every planned point, filling in its row of `rows` (made pending), and rewrites
/// sweep.csv at `table` as points finish (after each, unless writing it takes more than a
/// twentieth of the time between: a sweep of many quick points), not after the last: the
/// caller writes the whole table. The points run `share.at_a_time` at a time, each on
/// `share.threads_each` threads, with progress lines only when they run one at a time. The
/// results are the same either way (a run's results do not depend on its threads). A point
/// that fails is reported in its row.
void run_sweep(const std::vector<MillPlan>& plans, const std::vector<millsim::SweepAxis>& axes,
               std::vector<millsim::SweepRow>& rows, const std::filesystem::path& table, bool quiet,
               const millsim::ThreadShare& share) {
  using Clock = std::chrono::steady_clock;
  auto last_written = Clock::now();
  Clock::duration writing{};  // how long the last rewrite took
  std::mutex report;          // the rows, the table and the lines on stderr
  std::size_t finished = 0;   // points done so far, for those lines
  const auto run_point = [&](std::size_t i, bool show_progress) {
    millsim::SweepRow row = rows[i];
    const MillPlan& plan = plans[i];
    const std::string context = fmt::format("sweep point {}", row.directory);
    try {
      const MillResult result = plan.config.dimension == 2
                                    ? run_job<2>(plan, context, show_progress, {}, context)
                                    : run_job<3>(plan, context, show_progress, {}, context);
      row.status = "ok";
      row.scalars = millsim::summary_columns(result);
      // What the run warned of: its plan's doubts, then its results'.
      row.warnings = plan.warnings;
      const std::vector<std::string> doubts = millsim::result_warnings(result);
      row.warnings.insert(row.warnings.end(), doubts.begin(), doubts.end());
    } catch (const std::exception& error) {
      row.status = fmt::format("failed: {}", error.what());
    }
    {
      const std::lock_guard lock(report);
      rows[i] = std::move(row);
      ++finished;
      // Nothing may leave a point's thread: a table or a line that cannot be written here is
      // left for the final table, written after the points, to report.
      try {
        const auto now = Clock::now();
        if (now - last_written >= 20 * writing) {
          millsim::write_sweep_csv(table, axes, rows);
          last_written = Clock::now();
          writing = last_written - now;
        }
        if (!quiet) {
          // "point" is sweep.csv's, from 0; the count of those done, from 1.
          fmt::print(stderr, "point {} done, {} of {} ({}): {}\n", i, finished, rows.size(),
                     fmt::join(millsim::point_overrides(axes, rows[i].values), ", "),
                     rows[i].status);
        }
      } catch (...) {
      }
    }
  };
  warn_of_more_threads_than_cores();
  millsim::run_shared(rows.size(), share,
                      [&](std::size_t i) { run_point(i, !quiet && share.at_a_time <= 1); });
}

/// The largest earlier sweep.csv read for the names of its points.
constexpr std::uintmax_t most_sweep_table_bytes = 64U << 20U;

/// The whole text of a file (empty if it cannot be read).
std::string read_text(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

/// The point directories of the earlier sweep whose sweep.csv is in `root`: each row's name as
/// point_directory_name makes it from the row's index and values (the columns between `point`,
/// or `directory`, and `status` are the varied keys), where the row's `directory` cell, if the
/// table has that column, is the same name; and only those that are directories, not links.
/// So a table edited by hand, or copied from elsewhere, names nothing but point directories.
std::vector<std::string> earlier_point_directories(const std::filesystem::path& root) {
  const std::filesystem::path path = root / "sweep.csv";
  std::error_code error;
  if (!std::filesystem::is_regular_file(std::filesystem::symlink_status(path, error))) return {};
  const auto unread = [&](const std::string& why) {
    warn(
        {fmt::format("{} is not read for the points of an earlier sweep ({}): their results, if "
                     "any, stay beside this sweep's",
                     path.string(), why)});
    return std::vector<std::string>{};
  };
  // A sweep's table is a few MB at most (10 000 points); anything far larger is not one.
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) return unread(error.message());
  if (size > most_sweep_table_bytes) {
    return unread(fmt::format("{} bytes, more than a sweep's table", size));
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) return unread(std::strerror(errno));
  const std::vector<std::vector<std::string>> rows = millsim::csv_rows(read_text(path));
  if (rows.size() < 2 || rows[0].empty() || rows[0][0] != "point") return {};
  const std::vector<std::string>& header = rows[0];
  const bool listed = header.size() > 1 && header[1] == "directory";
  const std::size_t first_key = listed ? 2 : 1;
  const auto status = std::find(header.begin(), header.end(), "status");
  if (status == header.end()) return {};
  const auto end_key = static_cast<std::size_t>(status - header.begin());
  // A sweep varies at least one key, each a config key.
  if (end_key <= first_key) return {};
  for (std::size_t k = first_key; k < end_key; ++k) {
    if (!millsim::is_config_key(header[k])) return {};
  }
  std::vector<millsim::SweepAxis> axes;
  for (std::size_t k = first_key; k < end_key; ++k) axes.push_back({header[k], {}});
  const std::size_t count = rows.size() - 1;
  std::vector<std::string> names;
  for (std::size_t r = 1; r < rows.size(); ++r) {
    const std::vector<std::string>& row = rows[r];
    if (row.size() != header.size() || row[0] != fmt::format("{}", r - 1)) continue;
    const std::vector<std::string> values(row.begin() + static_cast<std::ptrdiff_t>(first_key),
                                          row.begin() + static_cast<std::ptrdiff_t>(end_key));
    const std::string name = millsim::point_directory_name(r - 1, count, axes, values);
    if (listed && row[1] != name) continue;
    if (std::filesystem::is_directory(std::filesystem::symlink_status(root / name, error))) {
      names.push_back(name);
    }
  }
  return names;
}

/// Runs the cartesian product of the --vary axes, one output directory per point, writes
/// sweep.csv and prints a table. Exit status 1 if any point failed.
int sweep_command(const JobOptions& options, const std::vector<std::string>& vary_arguments) {
  std::vector<millsim::SweepAxis> axes;
  axes.reserve(vary_arguments.size());
  for (const std::string& argument : vary_arguments) axes.push_back(millsim::parse_vary(argument));
  millsim::check_sweep_axes(axes);
  // Caught here, where both options can be named, rather than by each point's config.
  for (const millsim::SweepAxis& axis : axes) {
    for (const std::string& setting : options.overrides) {
      const std::string_view text = setting;
      std::string_view key = text.substr(0, text.find('='));
      while (!key.empty() && key.back() == ' ') key.remove_suffix(1);
      while (!key.empty() && key.front() == ' ') key.remove_prefix(1);
      if (key != axis.key) continue;
      throw millsim::InputError(fmt::format(
          "command line (--vary {}=...): {} is also given as --set {}; allowed: a key either "
          "varied or set",
          axis.key, axis.key, setting));
    }
  }
  refuse_output_directory_set(options, "sweep");
  const std::vector<std::vector<std::string>> points = millsim::cartesian_product(axes);
  const std::filesystem::path root =
      options.output_directory.empty() ? "runs/sweep" : options.output_directory;
  if (std::filesystem::exists(root) && !std::filesystem::is_directory(root)) {
    throw millsim::InputError(fmt::format(
        "command line (--out {}): exists and is not a directory; allowed: a directory path",
        root.string()));
  }
  const std::vector<MillPlan> plans = plan_sweep(options, axes, points, root);
  const millsim::ThreadShare share = millsim::share_threads(omp_get_max_threads(), points.size());
  const std::string shown = (root / "").parent_path().string();  // without a trailing '/'
  if (!options.quiet) {
    fmt::print("millsim: sweeping {} {} of {} into {}/ ({})\n", points.size(),
               points.size() == 1 ? "point" : "points", plans.front().config.source, shown,
               millsim::describe(share));
    std::fflush(stdout);
  }
  // An earlier sweep into the same directory (its sweep.csv): its points that this sweep does
  // not have lose their results, as a run's earlier results go, and so do this sweep's own
  // points' directories, so that the directory holds one sweep and a point not yet run holds
  // nothing. The earlier table goes last, so that a refusal here leaves it listing what is left.
  const std::string root_location = options.output_directory.empty()
                                        ? std::string("the default output directory")
                                        : fmt::format("command line (--out {})", root.string());
  std::vector<millsim::SweepRow> rows(points.size());
  std::set<std::string, std::less<>> current;
  for (std::size_t i = 0; i < points.size(); ++i) {
    rows[i].values = points[i];
    rows[i].status = "pending";
    rows[i].directory = std::filesystem::path(plans[i].config.output_directory).filename().string();
    current.insert(rows[i].directory);
  }
  // Everything the clearing below would refuse is refused first, so that a refusal clears
  // nothing: the earlier points', this sweep's points' and the table's names. A point's
  // directory too long for its files is refused now too, whether it is there yet or not (each
  // point is checked again as it starts, when that would fail it after others had run).
  for (const MillPlan& plan : plans) {
    millsim_app::refuse_a_path_too_long(
        plan.config.output_directory, root_location, run_result_names,
        plan.config.snapshot_interval > 0.0 ? Snapshots::made : Snapshots::removed);
  }
  std::vector<std::string> stale;
  for (const std::string& name : earlier_point_directories(root)) {
    if (current.contains(name) || std::find(stale.begin(), stale.end(), name) != stale.end()) {
      continue;
    }
    stale.push_back(name);
    check_output_directory(root / name,
                           fmt::format("{}, a point of the earlier sweep", root_location),
                           run_result_names, Snapshots::removed);
  }
  std::vector<std::string> existing;  // this sweep's point directories that are there already
  for (const std::string& name : current) {
    std::error_code error;
    const std::filesystem::file_status state = std::filesystem::symlink_status(root / name, error);
    if (std::filesystem::is_symlink(state)) {
      throw millsim::InputError(fmt::format(
          "{}: sweep point {} is a link; allowed: a directory, or no file of that name (a "
          "point's results are written in its own directory under --out)",
          root_location, (root / name).string()));
    }
    if (!std::filesystem::is_directory(state)) continue;  // a file there fails that point only
    existing.push_back(name);
    check_output_directory(root / name, root_location, run_result_names, Snapshots::removed);
  }
  check_output_directory(root, root_location, {"sweep.csv"});
  for (const char* name : {"sweep.csv", "sweep.csv.partial"}) {
    std::error_code error;
    if (std::filesystem::is_directory(std::filesystem::symlink_status(root / name, error))) {
      throw millsim::InputError(fmt::format(
          "{}: \"{}\" is a directory, where the sweep writes its table; allowed: an output "
          "directory without a directory of that name (remove or rename it)",
          root_location, (root / name).string()));
    }
  }
  // Every directory's earlier results are moved aside first, all put back if one cannot be,
  // so that a refusal clears nothing; then the new table replaces the old (a rename), and only
  // then is what was moved aside removed. A sweep stopped in between leaves the old table and
  // the results aside, which the next run or sweep there removes.
  std::vector<EarlierResults> aside;
  const auto put_all_back = [&] {
    for (auto back = aside.rbegin(); back != aside.rend(); ++back) {
      (void)back->put_back("");
    }
  };
  const std::string earlier_context =
      fmt::format("{}, a point of the earlier sweep", root_location);
  const std::filesystem::path table = root / "sweep.csv";
  try {
    for (const std::string& name : stale) {
      aside.push_back(
          move_results_aside(root / name, earlier_context, run_result_names, Snapshots::removed));
    }
    for (const std::string& name : existing) {
      aside.push_back(
          move_results_aside(root / name, root_location, run_result_names, Snapshots::removed));
    }
    aside.push_back(move_results_aside(root, root_location, {"sweep.csv.partial"}));
    // The table from the start, every point pending, so that a sweep stopped early still says
    // which directories are its own and which points finished.
    millsim::write_sweep_csv(table, axes, rows);
  } catch (...) {
    put_all_back();
    throw;
  }
  for (EarlierResults& results : aside) {
    warn(results.remove(), results.location);
  }
  for (const std::string& name : stale) {
    std::error_code error;
    std::filesystem::remove(root / name, error);  // only when nothing else is left in it
  }
  if (!stale.empty() && !options.quiet) {
    fmt::print(stderr, "millsim: removed the results of {} {} of the earlier sweep in {}/\n",
               stale.size(), stale.size() == 1 ? "point" : "points", shown);
  }
  run_sweep(plans, axes, rows, table, options.quiet, share);

  // The table on stdout first: a sweep.csv that cannot be written fails the command after the
  // results are shown.
  fmt::print("{}", millsim::sweep_table(axes, rows));
  std::fflush(stdout);
  millsim::write_sweep_csv(table, axes, rows);
  const auto failed = std::count_if(
      rows.begin(), rows.end(), [](const millsim::SweepRow& row) { return row.status != "ok"; });
  if (!options.quiet) {
    fmt::print("results in {}/ (sweep.csv, one directory per point)\n", shown);
  }
  if (failed > 0) {
    fmt::print(stderr, "millsim: {} of {} points failed\n", failed, points.size());
    return 1;
  }
  return 0;
}

/// Whether `text` is a whole number of threads from 1 to 1024, all of it.
bool is_thread_count(std::string_view text) {
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  return error == std::errc{} && stop == end && value >= 1 && value <= 1024;
}

/// What is wrong with the environment's OMP_NUM_THREADS, if anything. The OpenMP runtime reads
/// it when the first thread count is asked for or set, even under -j, and a value it cannot
/// read it does not refuse: with "abc" libomp warned and then, one run in three, hung or
/// aborted. So the value must be what OpenMP allows, a list of thread counts, one per level of
/// nesting, separated by commas (millsim's jobs use the first); under -j, whose count replaces
/// it, the counts may be any size.
std::optional<std::string> omp_num_threads_problem(bool threads_given) {
  const char* set = std::getenv("OMP_NUM_THREADS");
  if (set == nullptr) return std::nullopt;
  const std::string_view value(set);
  bool readable = true;
  bool within = true;
  std::size_t from = 0;
  while (readable) {
    const std::size_t comma = value.find(',', from);
    const std::string_view count =
        value.substr(from, comma == std::string_view::npos ? std::string_view::npos : comma - from);
    std::uint64_t number = 0;
    const auto [stop, error] = std::from_chars(count.data(), count.data() + count.size(), number);
    readable = !count.empty() && stop == count.data() + count.size() &&
               (error == std::errc{} || error == std::errc::result_out_of_range) && number >= 1;
    within = within && readable && is_thread_count(count);
    if (comma == std::string_view::npos) break;
    from = comma + 1;
  }
  if (readable && (within || threads_given)) return std::nullopt;
  return fmt::format(
      "environment: OMP_NUM_THREADS=\"{}\" is not allowed; allowed: a whole number of threads "
      "from 1 to 1024 (or such numbers separated by commas, one per level of nesting), or "
      "OMP_NUM_THREADS unset{}",
      value, readable ? " or -j/--threads N given in its place" : "");
}

/// --set, -j and -q; `quiet` says what -q leaves of the command's output.
void add_job_options(CLI::App& command, JobOptions& options, const std::string& quiet) {
  // One KEY=VALUE a --set: without allow_extra_args(false), CLI11 gives a vector option every
  // word that follows, the config's path among them ("run --set a=1 mill.toml").
  command
      .add_option("--set", options.overrides,
                  "override a config key, e.g. --set mill.speed=0.75 (repeatable)")
      ->allow_extra_args(false);
  command
      .add_option("-j,--threads", options.threads,
                  "threads to use (default: all available cores, or OMP_NUM_THREADS); results do "
                  "not depend on it")
      ->check(CLI::Validator(
          [](const std::string& text) -> std::string {
            // CLI11's own Range says "Value abc not in range" of a word that is no number.
            if (!is_thread_count(text)) {
              return fmt::format(
                  "\"{}\" is not allowed; allowed: a whole number of threads "
                  "from 1 to 1024",
                  text);
            }
            return {};
          },
          "1 to 1024"));
  command.add_flag("-q,--quiet", options.quiet, quiet);
}

/// The program: parses the command line and runs the command. Errors it foresees are reported
/// here; main catches anything else.
int run_program(int argc, char** argv) {
  CLI::App app{"millsim: discrete element simulation of tumbling mills"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "millsim " + millsim::version_text(),
                       "print the version and the source revision, and exit");
  JobOptions options;
  std::string validation_directory = "examples/validation";

  CLI::App* run = app.add_subcommand(
      "run", "simulate a mill and report its power draft, or a scene of particles and walls");
  run->add_option("config", options.config_path,
                  "mill or scene config (TOML); default: the built-in example mill");
  run->add_option("-o,--out", options.output_directory,
                  "output directory (overrides output.directory)");
  add_job_options(*run, options,
                  "print only the one-line summary (no progress line, no \"running\" and "
                  "\"results in\" lines)");

  CLI::App* info =
      app.add_subcommand("info", "print derived quantities of a mill or a scene, no simulation");
  info->add_option("config", options.config_path,
                   "mill or scene config (TOML); default: the built-in example mill");
  info->add_option("--set", options.overrides, "override a config key (repeatable)")
      ->allow_extra_args(false);

  CLI::App* validate = app.add_subcommand(
      "validate", "run every measured-mill case in a directory and compare with measurements");
  validate->add_option("directory", validation_directory, "directory of validation configs")
      ->capture_default_str();
  validate->add_option("-o,--out", options.output_directory,
                       "where the runs go (default runs/validation)");
  add_job_options(*validate, options, "print only the table (no line per case, no progress lines)");

  std::vector<std::string> vary_arguments;
  CLI::App* sweep = app.add_subcommand(
      "sweep", "run a mill at every combination of varied keys and tabulate the results");
  sweep->add_option("config", options.config_path,
                    "mill config (TOML); default: the built-in example");
  sweep
      ->add_option("--vary", vary_arguments,
                   "KEY=START:STOP:STEP or KEY=V1,V2,... (repeatable; the cartesian product runs)")
      ->required()
      ->allow_extra_args(false);
  sweep->add_option("-o,--out", options.output_directory,
                    "where the points and sweep.csv go (default runs/sweep)");
  add_job_options(*sweep, options,
                  "print only the table (no line per point, no progress or other lines)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return app.exit(error);  // --help, --version
    if (argc > 1 && argv[1][0] != '-' && app.get_subcommands().empty()) {
      // CLI11 would say only that a command is required.
      fmt::print(stderr,
                 "millsim: error: command line: \"{}\" is not a command; allowed: run, info, "
                 "validate or sweep (millsim --help)\n",
                 argv[1]);
      return 2;
    }
    if (app.get_subcommands().empty()) {
      // Nothing at all, or options before any command (they belong after it).
      fmt::print(
          stderr,
          "millsim: error: command line: {}; allowed: run, info, validate or sweep, each "
          "followed by its options (millsim --help)\n",
          argc == 1 ? std::string("no command") : fmt::format("no command before \"{}\"", argv[1]));
      return 2;
    }
    // The help of the command given, if any, lists what it takes.
    std::string help = "millsim --help";
    for (CLI::App* command : {run, info, validate, sweep}) {
      if (!command->parsed()) continue;
      help = fmt::format("millsim {} --help", command->get_name());
      // One of its options before it (millsim -q run): its help lists the option, so pointing
      // there does not help; the option's place does.
      const std::string first = argv[1];
      const std::string name = first.substr(0, first.find('='));
      if (name.size() > 1 && name[0] == '-' && command->get_option_no_throw(name) != nullptr) {
        fmt::print(stderr,
                   "millsim: error: command line: \"{}\" comes before the command; allowed: "
                   "the command first, then its options (millsim {} {} ...)\n",
                   first, command->get_name(), first);
        return 2;
      }
    }
    const std::string what = error.what();
    // A validator's message already says what is allowed.
    if (what.find("; allowed: ") != std::string::npos) {
      fmt::print(stderr, "millsim: error: command line: {}\n", what);
    } else {
      fmt::print(stderr, "millsim: error: command line: {}; allowed: see {}\n", what, help);
    }
    return 2;
  }
  if (run->parsed() || validate->parsed() || sweep->parsed()) {
    // Before any OpenMP call (omp_set_num_threads among them) reads OMP_NUM_THREADS.
    if (const auto problem = omp_num_threads_problem(options.threads > 0)) {
      fmt::print(stderr, "millsim: error: {}\n", *problem);
      return 2;
    }
  }
  if (options.threads > 0) omp_set_num_threads(options.threads);
  // An empty path is a mistake (an unset shell variable), not a request for the default.
  const auto given_empty = [](std::initializer_list<const CLI::App*> commands, const char* option,
                              const std::string& value) {
    return value.empty() && std::any_of(commands.begin(), commands.end(), [&](const CLI::App* c) {
             return c->parsed() && c->count(option) > 0;
           });
  };
  if (given_empty({run, info, sweep}, "config", options.config_path)) {
    fmt::print(stderr,
               "millsim: error: command line: config: an empty path; allowed: a config "
               "file, or none for the built-in example\n");
    return 2;
  }
  if (given_empty({run, validate, sweep}, "--out", options.output_directory)) {
    fmt::print(stderr,
               "millsim: error: command line: --out: an empty path; allowed: a directory path\n");
    return 2;
  }
  try {
    if (run->parsed()) return run_command(options);
    if (info->parsed()) return info_command(options);
    if (sweep->parsed()) return sweep_command(options, vary_arguments);
    return validate_command(validation_directory, options);
  } catch (const millsim::InputError& error) {
    fmt::print(stderr, "millsim: error: {}\n", error.what());
    return 2;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr,
               "millsim: failed: out of memory (millsim info prints the particle count; a ball "
               "takes about 1.1 kB)\n");
    return 1;
  } catch (const std::exception& error) {
    fmt::print(stderr, "millsim: failed: {}\n", error.what());
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  // Anything run_program lets through (an exception from setting up the command line, or from
  // printing an error) is still a message and exit status 1, not std::terminate's abort.
  try {
    const int status = run_program(argc, argv);
    // What was printed and not yet written (a summary line, a table, `info`'s figures) must
    // reach standard output: a full disk or a closed stream is a failure, not a success with
    // nothing to show for it.
    errno = 0;
    if (std::fflush(stdout) != 0 || std::ferror(stdout) != 0) {
      const int error = errno;
      std::fprintf(stderr, "millsim: failed: cannot write to standard output: %s\n",
                   error != 0 ? std::strerror(error) : "write error");
      return status == 0 ? 1 : status;
    }
    return status;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "millsim: failed: %s\n", error.what());
  } catch (...) {
    std::fputs("millsim: failed: an unknown error\n", stderr);
  }
  return 1;
}
