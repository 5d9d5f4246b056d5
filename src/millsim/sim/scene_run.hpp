// A scene job: particles and plane walls without a mill (README "Scenes"), run for a fixed
// duration, writing every particle's state to trajectory.csv and the end state to final.csv.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "millsim/io/config.hpp"
#include "millsim/sim/world.hpp"

namespace millsim {

/// What follows from a scene config before anything runs.
struct ScenePlan {
  SceneConfig config;
  double time_step = 0.0;           ///< s, the one used
  double critical_time_step = 0.0;  ///< s, the stability limit for these particles
  /// Shortest normal-impact duration among the contacts the scene can have (ball–ball for the
  /// two lightest particles, ball–wall for the lightest), s; 0 when it can have none.
  double shortest_contact = 0.0;
  long steps = 0;             ///< whole steps of time_step that reach the duration
  long trajectory_every = 0;  ///< steps between trajectory rows; 0: only start and end
  /// Doubts about the plan that do not stop the run (a given time step coarser than 1/10 of the
  /// shortest contact), each naming the file, line and key.
  std::vector<std::string> warnings;
};

/// Checks the time step against the stability limit (refusing an unstable one with the limit)
/// and picks "auto": a twentieth of the shortest contact, as for mills. Throws InputError.
ScenePlan plan_scene(const SceneConfig& config);

/// A world holding the scene's particles and walls, ready to step. In 2D a disc carries the
/// mass of its sphere, ρ π d³ / 6, as in mills. The initial velocities are taken as the
/// velocities at t = 0: the leapfrog's half-step velocities are set back by half a step of
/// gravity, so free flight is exact.
template <int D>
World<D> build_scene_world(const ScenePlan& plan);

struct SceneResult {
  ScenePlan plan;
  long steps = 0;
  double simulated_seconds = 0.0;
  double wall_seconds = 0.0;
  double kinetic_start = 0.0, kinetic_end = 0.0;      ///< J
  double potential_start = 0.0, potential_end = 0.0;  ///< J
  double dissipated = 0.0;                            ///< J
  long ball_ball_collisions = 0;                      ///< collisions that ended during the run
  long ball_wall_collisions = 0;
  long dropped_wall_contacts = 0;  ///< World::dropped_wall_contacts at the end
};

/// Called now and then with (simulated time, duration).
using SceneProgress = std::function<void(double, double)>;

/// Runs the scene, writing trajectory.csv, final.csv and summary.json into `directory` (which
/// must exist). Files are written under a temporary name and renamed when complete.
SceneResult run_scene(const ScenePlan& plan, const std::filesystem::path& directory,
                      const SceneProgress& progress = {});

/// What makes the results doubtful: wall contacts left out (World::dropped_wall_contacts).
std::vector<std::string> scene_result_warnings(const SceneResult& result);

/// The one-line summary printed at the end of a scene run.
std::string scene_summary_line(const SceneResult& result);

}  // namespace millsim
