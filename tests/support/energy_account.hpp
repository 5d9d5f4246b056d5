// The energy account of a running mill over its measured window (MODEL.md §7, issue 2's
// physics test 7): the shell's work equals the change of kinetic, potential and stored spring
// energy plus what the contacts dissipated, within 1 %, and the power by torque and the power
// by dissipation agree within 3 %.
#pragma once

#include <gtest/gtest.h>

#include <cmath>

#include "millsim/sim/mill_run.hpp"

namespace millsim::testing {

inline void expect_energy_account_closes(const MillResult& r) {
  const double work = r.window_end.shell_work - r.window_start.shell_work;
  const double change = (r.window_end.kinetic - r.window_start.kinetic) +
                        (r.window_end.potential - r.window_start.potential) +
                        (r.window_end.stored - r.window_start.stored);
  const double dissipated = r.window_end.dissipated - r.window_start.dissipated;
  EXPECT_GT(work, 0.0);
  EXPECT_NEAR(change + dissipated, work, 0.01 * work) << "shell work = Δenergy + dissipated";
  // The figure the run reports (summary.json) is this account.
  EXPECT_NEAR(r.energy_balance_error, std::abs(work - change - dissipated) / work, 1e-12);
  // Over a steady window the charge's energy hardly changes, so the drive's power (torque × ω)
  // and the power dissipated in the contacts agree.
  EXPECT_NEAR(r.power_dissipation_kw, r.power_kw, 0.03 * r.power_kw);
}

}  // namespace millsim::testing
