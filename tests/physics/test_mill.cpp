// Whole-mill physics: a charge at rest stays at rest, a mill above critical speed centrifuges
// its charge, and a running mill keeps its energy account (issue tests 5, 6, 7).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "millsim/builtin_example.hpp"
#include "millsim/core/constants.hpp"
#include "millsim/sim/mill_run.hpp"
#include "support/energy_account.hpp"

namespace millsim {
namespace {

MillConfig lab_mill(std::vector<std::string> overrides = {}) {
  overrides.push_back("output.snapshot_interval=0");
  return parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", overrides);
}

MillResult run(const MillConfig& config) {
  const MillPlan plan = plan_mill(config);
  return run_mill(plan, build_mill_world<2>(plan), {});
}

TEST(Mill, SettledChargeComesToRestAndStays) {
  const MillPlan plan = plan_mill(lab_mill());
  World<2> world = build_mill_world<2>(plan);
  const double reference_energy =
      plan.slice_mass * standard_gravity * plan.largest_ball;  // m g d of the whole charge
  while (world.time() < 2.0) world.step();
  const double settled = world.kinetic_energy();
  EXPECT_LT(settled, 1e-6 * reference_energy) << "kinetic energy after 2 s of settling";

  const std::vector<Vec2> at_rest = world.particles().position;
  while (world.time() < 3.0) world.step();
  double largest_move = 0.0;
  for (std::size_t i = 0; i < at_rest.size(); ++i) {
    largest_move = std::max(largest_move, norm(world.particles().position[i] - at_rest[i]));
  }
  EXPECT_LT(largest_move, 1e-4 * plan.largest_ball) << "a ball crept during a further second";
  EXPECT_LT(world.kinetic_energy(), 1e-6 * reference_energy);
}

TEST(Mill, TumblesBelowCriticalAndCentrifugesAboveIt) {
  const auto at_speed = [](double fraction) {
    return run(lab_mill({fmt::format("mill.speed={}", fraction), "simulation.revolutions=8",
                         "simulation.measure_revolutions=4"}));
  };
  const MillResult tumbling = at_speed(0.6);
  const MillResult centrifuging = at_speed(1.5);
  const MillResult far_above = at_speed(2.0);
  const double radius = tumbling.plan.radius;

  // Tumbling: the charge is held up on the rising side, its centre of mass well off the axis,
  // and the mill draws hundreds of watts.
  EXPECT_GT(tumbling.power_kw, 0.2);
  EXPECT_GT(tumbling.charge_centre[0], 0.1 * radius);
  EXPECT_LT(tumbling.orbital_speed_ratio, 0.8);

  // Centrifuged: the charge rides round with the shell, its centre of mass on the axis, so
  // lifting it takes no torque. What power is left is balls rolling freely along the shell in
  // part-filled bays between lifters (docs/validation.md); it dies away at higher speed.
  const double tumbling_offset = norm(tumbling.charge_centre);
  // At 150 % the outer ring (about 52 of the 75 discs fit round the shell) rides with it; the
  // discs above it roll over it, chaotically, so their share of the mean is not a fixed
  // number: the bound says "most of the charge rides round", 0.94 to 0.96 in runs seen.
  EXPECT_NEAR(centrifuging.orbital_speed_ratio, 1.0, 0.1);
  EXPECT_LT(norm(centrifuging.charge_centre), 0.2 * tumbling_offset);
  EXPECT_LT(centrifuging.power_kw, 0.5 * tumbling.power_kw);
  EXPECT_NEAR(far_above.orbital_speed_ratio, 1.0, 0.01);
  EXPECT_LT(norm(far_above.charge_centre), 0.02 * tumbling_offset);
  // Not exactly zero: the second layer of discs rides above the 4 cm lifters on the first and
  // keeps rolling to and fro as gravity turns round it. That motion is chaotic (changing only
  // the order in which forces are summed took this power from 0.4 % to 4.6 % of the tumbling
  // power), so the bound is "an order of magnitude below tumbling", not a measured value.
  EXPECT_LT(std::abs(far_above.power_kw), 0.1 * tumbling.power_kw);

  // The charge profile (measure/charge_profile.hpp). Tumbling, the charge lies against the shell
  // over about the arc of a bed at rest filling J, 2α with 2α − sin 2α = 2π J (a tumbling bed is
  // not a rigid segment: the bound is 15°, and 0.6 gave 151° against 143°). A bed that turned
  // as a rigid segment would have its centre of mass on the bisector of that arc: the arc's
  // middle and the direction of the charge's centre, both from the bottom with the turn, agree
  // to within 5° (2° seen). Centrifuged, the layer goes all the way round: no toe or shoulder.
  const double filling = tumbling.plan.config.filling;
  double arc = pi;  // 2α, by bisection of 2α − sin 2α − 2π J on (0, 2π)
  for (double low = 0.0, high = 2.0 * pi; high - low > 1e-12; arc = 0.5 * (low + high)) {
    (arc - std::sin(arc) < 2.0 * pi * filling ? low : high) = arc;
  }
  const auto ends = tumbling.charge_profile->toe_and_shoulder();
  ASSERT_TRUE(ends.has_value());
  const double toe = ends->toe - 1.5 * pi;            // from the bottom, negative: falling side
  const double shoulder = ends->shoulder + 0.5 * pi;  // from the bottom, positive: rising side
  EXPECT_NEAR(shoulder - toe, arc, 15.0 * pi / 180.0);
  const double centre_direction = std::atan2(tumbling.charge_centre[0], -tumbling.charge_centre[1]);
  EXPECT_NEAR(0.5 * (toe + shoulder), centre_direction, 5.0 * pi / 180.0);
  EXPECT_FALSE(centrifuging.charge_profile->toe_and_shoulder().has_value());
  EXPECT_FALSE(far_above.charge_profile->toe_and_shoulder().has_value());
}

TEST(Mill, EnergyAccountClosesAndBothPowersAgree) {
  const MillResult r =
      run(lab_mill({"simulation.revolutions=4", "simulation.measure_revolutions=3"}));
  testing::expect_energy_account_closes(r);
  // The run lasts as long as its plan says (what `info` and the progress line report), spin-up
  // included: settling ends within half a step of settle_time, and the turn ends on the first
  // step at or past the last revolution's angle, so within [-0.5, +1.5] steps of the total.
  const double over = r.simulated_seconds - r.plan.total_time;
  EXPECT_GE(over, -0.5 * r.plan.time_step);
  EXPECT_LE(over, 1.5 * r.plan.time_step);
  const double steps_over = static_cast<double>(r.steps) - r.plan.total_time / r.plan.time_step;
  EXPECT_GE(steps_over, -0.5);
  EXPECT_LE(steps_over, 1.5);
  // The settling's share of the wall time is part of it.
  EXPECT_GT(r.settle_wall_seconds, 0.0);
  EXPECT_LT(r.settle_wall_seconds, r.wall_seconds);
}

}  // namespace
}  // namespace millsim
