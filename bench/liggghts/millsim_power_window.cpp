// millsim_power_window: the drive power millsim predicts for a 3D mill config over a window of
// steps, starting from a settled state written by `millsim_scene_bench CONFIG --save-state FILE`
// (the state LIGGGHTS starts from in bench/run_liggghts_comparison.sh --power). The shell is
// set turning at full speed at once (as millsim_scene_bench does), LIFT steps are run, then the
// power is averaged over WINDOW steps: the work of the shell, lifters and end plates on the
// balls per second (millsim's power_kw) and, as a check, the mean shell torque times omega.
//
//   millsim_power_window CONFIG STATE LIFT WINDOW [THREADS]
//
// Built by bench/run_liggghts_comparison.sh with g++ against the millsim build it uses (not
// part of the CMake build).
#include <omp.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "millsim/io/config.hpp"
#include "millsim/sim/charge.hpp"

namespace {

template <typename T>
bool read_array(std::ifstream& file, std::vector<T>& values) {
  file.read(reinterpret_cast<char*>(values.data()),
            static_cast<std::streamsize>(values.size() * sizeof(T)));
  return static_cast<bool>(file);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s CONFIG STATE LIFT WINDOW [THREADS]\n", argv[0]);
    return 2;
  }
  const long lift = std::atol(argv[3]);
  const long window = std::atol(argv[4]);
  if (argc > 5) omp_set_num_threads(std::atoi(argv[5]));
  const millsim::MillPlan plan = millsim::plan_mill(millsim::load_mill_config(argv[1]));
  if (plan.config.dimension != 3) {
    std::fprintf(stderr, "only 3D configs\n");
    return 2;
  }
  millsim::World<3> world = millsim::build_mill_world<3>(plan);

  // The state: particle count, then position, velocity, angular velocity, force, torque (three
  // doubles each per particle), then the shell angle.
  std::ifstream file(argv[2], std::ios::binary);
  auto& p = world.particles();
  std::uint64_t count = 0;
  file.read(reinterpret_cast<char*>(&count), sizeof count);
  if (!file || count != p.size()) {
    std::fprintf(stderr, "%s is not a state of this scene (%zu particles)\n", argv[2], p.size());
    return 2;
  }
  double angle = 0.0;
  if (!read_array(file, p.position) || !read_array(file, p.velocity) ||
      !read_array(file, p.angular_velocity) || !read_array(file, p.force) ||
      !read_array(file, p.torque) || !file.read(reinterpret_cast<char*>(&angle), sizeof angle)) {
    std::fprintf(stderr, "%s is truncated\n", argv[2]);
    return 2;
  }
  world.walls().mill->turn_to(angle);
  world.walls().mill->angular_speed = plan.angular_speed;

  for (long n = 0; n < lift; ++n) world.step();
  const double t0 = world.time();
  const double work0 = world.energy_account().shell_work;
  double torque_time = 0.0;
  for (long n = 0; n < window; ++n) {
    world.step();
    torque_time += world.shell_torque() * plan.time_step;
  }
  const double duration = world.time() - t0;
  const double power = (world.energy_account().shell_work - work0) / duration;
  const double torque = torque_time / duration;
  std::printf("particles %zu, omega %.6g rad/s, dt %.3g s\n", p.size(), plan.angular_speed,
              plan.time_step);
  std::printf("window %ld steps (%.4g s) after %ld steps at full speed (%.4g s)\n", window,
              duration, lift, static_cast<double>(lift) * plan.time_step);
  std::printf("power_kw %.5f\n", power / 1000.0);
  std::printf("torque_nm %.5f (x omega: %.5f kW)\n", torque, torque * plan.angular_speed / 1000.0);
  return 0;
}
