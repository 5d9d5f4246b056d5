// What plan_mill derives from a mill config (speeds, disc counts, masses, time step) and how
// build_mill_world places the charge (sim/charge.hpp), each number worked out by hand in the
// comment above its check. The mill is the built-in example: D = 0.9 m, L = 0.15 m, J = 0.30,
// 5.08 cm steel balls (ρ = 7800 kg/m³, porosity 0.4), half critical speed, eight 4 × 4 cm lifters,
// k_n = 4e5 N/m, k_s = 3e5 N/m, e = 0.6 for ball–ball and ball–wall.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "millsim/builtin_example.hpp"
#include "millsim/core/constants.hpp"
#include "millsim/core/error.hpp"
#include "millsim/geometry/walls.hpp"
#include "millsim/io/config.hpp"
#include "millsim/particles/material.hpp"
#include "millsim/sim/charge.hpp"

namespace millsim {
namespace {

// Relative tolerance for values worked by hand to 8 significant figures.
constexpr double hand_tolerance = 1e-7;

#define EXPECT_HAND(actual, hand) EXPECT_NEAR((actual), (hand), std::abs(hand) * hand_tolerance)

MillConfig lab_mill(std::vector<std::string> overrides = {}) {
  overrides.push_back("output.snapshot_interval=0");
  return parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", overrides);
}

/// The lab mill with a graded charge of top size 5.08 cm instead of one size.
MillConfig graded_lab_mill() {
  MillConfig config = lab_mill();
  config.sizes = graded_charge(0.0508);
  return config;
}

TEST(MillPlan, CriticalSpeedAndSpeedFromAFractionOfIt) {
  const MillPlan plan = plan_mill(lab_mill());
  EXPECT_HAND(plan.radius, 0.45);
  EXPECT_HAND(plan.largest_ball, 0.0508);
  // N_c = (60/2π) sqrt(2g/(D − d_max)): D − d = 0.9 − 0.0508 = 0.8492 m,
  // 2g/(D − d) = 19.62 / 0.8492 = 23.104098 s⁻², sqrt = 4.8066722 s⁻¹,
  // × 60/(2π) = × 9.5492966: N_c = 45.900339 rpm (the rule of thumb 42.3/sqrt(0.8492) = 45.90).
  EXPECT_HAND(plan.critical_speed_rpm, 45.900339);
  // speed = 0.5: N = 22.950169 rpm, ω = N × 2π/60 = 2.4033361 rad/s, T = 60/N = 2.6143598 s.
  EXPECT_HAND(plan.speed_fraction, 0.5);
  EXPECT_HAND(plan.speed_rpm, 22.950169);
  EXPECT_HAND(plan.angular_speed, 2.4033361);
  EXPECT_HAND(plan.revolution_period, 2.6143598);
  // The shell comes up to speed over a quarter of a period, 0.65358995 s, in which it turns as
  // in half that time at full speed. Total time = settle 1 s + 0.65358995 s / 2 + 6 revolutions
  // × 2.6143598 s = 1 + 0.32679498 + 15.686159 = 17.012954 s.
  EXPECT_HAND(plan.spin_up_time, 0.65358995);
  EXPECT_HAND(plan.total_time, 17.012954);
}

TEST(MillPlan, CriticalSpeedUsesTheLargestBallWhereverItIsListed) {
  // MODEL.md §1: N_c with d the largest ball. Sizes listed smallest first, 3 cm and 6 cm:
  // D − d = 0.9 − 0.06 = 0.84 m, 2g/(D − d) = 23.357143 s⁻², sqrt = 4.8329228 s⁻¹,
  // × 60/(2π) = 46.151013 rpm.
  MillConfig config = lab_mill();
  config.sizes = {{0.03, 0.5}, {0.06, 0.5}};
  const MillPlan plan = plan_mill(config);
  EXPECT_EQ(plan.largest_ball, 0.06);
  EXPECT_HAND(plan.critical_speed_rpm, 46.151013);
  EXPECT_HAND(plan.speed_rpm, 0.5 * 46.151013);
}

TEST(MillPlan, SpeedGivenInRpm) {
  MillConfig config = lab_mill();
  config.speed_fraction.reset();
  config.speed_rpm = 30.0;
  const MillPlan plan = plan_mill(config);
  // 30 rpm of N_c = 45.900339 rpm is 0.65358995 of critical; ω = 30 × 2π/60 = π rad/s; T = 2 s.
  EXPECT_HAND(plan.speed_rpm, 30.0);
  EXPECT_HAND(plan.critical_speed_rpm, 45.900339);
  EXPECT_HAND(plan.speed_fraction, 0.65358995);
  EXPECT_HAND(plan.angular_speed, 3.1415927);
  EXPECT_HAND(plan.revolution_period, 2.0);
}

TEST(MillPlan, DiscCountMassesAndPowerScaleOfOneSize) {
  const MillPlan plan = plan_mill(lab_mill());
  // Disc area = J π R² (1 − 0.2) = 0.3 × 0.63617251 × 0.8 = 0.15268140 m²; one disc
  // π d²/4 = 0.78539816 × 0.00258064 = 0.0020268299 m²; 0.15268140 / 0.0020268299 = 75.33 -> 75.
  ASSERT_EQ(plan.discs.size(), 1u);
  EXPECT_EQ(plan.discs[0].count, 75);
  EXPECT_EQ(plan.particle_count, 75);
  EXPECT_HAND(plan.discs[0].diameter, 0.0508);
  // Each disc has the mass of its sphere: ρ π d³/6 = 7800 × 0.52359878 × 1.31096512e-4
  // = 0.53540739 kg; the slice holds 75 × 0.53540739 = 40.155554 kg.
  EXPECT_HAND(plan.discs[0].mass, 0.53540739);
  EXPECT_HAND(plan.slice_mass, 40.155554);
  // Mill charge ρ (1 − porosity) J π R² L = 7800 × 0.6 × 0.3 × 0.63617251 × 0.15 = 133.97793 kg;
  // power_scale = 133.97793 / 40.155554 = 3.3364732.
  EXPECT_HAND(plan.mill_charge_mass, 133.97793);
  EXPECT_HAND(plan.power_scale, 3.3364732);
}

TEST(MillPlan, GradedChargeFollowsBondInFourClasses) {
  // Bond: mass fraction below d is (d/top)^3.84; classes at top × 0.8^k, k = 0..3.
  // 0.8^3.84 = exp(3.84 × ln 0.8) = exp(3.84 × −0.22314355) = exp(−0.85687124) = 0.42448813,
  // 0.8^7.68 = 0.42448813² = 0.18019017, 0.8^11.52 = 0.42448813³ = 0.076488589. Fractions:
  // 1 − 0.42448813 = 0.57551187, 0.42448813 − 0.18019017 = 0.24429796,
  // 0.18019017 − 0.076488589 = 0.10370158, and the rest 0.076488589 (docs/model.md: 0.576,
  // 0.244, 0.104, 0.077).
  const std::vector<SizeClass> sizes = graded_charge(0.0508);
  ASSERT_EQ(sizes.size(), 4u);
  const double diameters[] = {0.0508, 0.04064, 0.032512, 0.0260096};  // 0.0508 × 0.8^k
  const double fractions[] = {0.57551187, 0.24429796, 0.10370158, 0.076488589};
  double total = 0.0;
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_HAND(sizes[k].diameter, diameters[k]);
    EXPECT_HAND(sizes[k].mass_fraction, fractions[k]);
    total += sizes[k].mass_fraction;
  }
  EXPECT_NEAR(total, 1.0, 1e-12);
  // The same shape at any top size.
  const std::vector<SizeClass> small = graded_charge(0.02);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_HAND(small[k].diameter, 0.02 * std::pow(0.8, static_cast<double>(k)));
    EXPECT_DOUBLE_EQ(small[k].mass_fraction, sizes[k].mass_fraction);
  }
}

TEST(MillPlan, DiscCountsOfAGradedCharge) {
  const MillPlan plan = plan_mill(graded_lab_mill());
  // count_k = round(f_k × 0.15268140 m² / (π d_k²/4)):
  //   5.08 cm: 0.57551187 × 0.15268140 / 0.0020268299 = 43.35 -> 43
  //   4.064 cm: 0.24429796 × 0.15268140 / 0.0012971711 = 28.75 -> 29
  //   3.2512 cm: 0.10370158 × 0.15268140 / 0.00083018953 = 19.07 -> 19
  //   2.60096 cm: 0.076488589 × 0.15268140 / 0.00053132130 = 21.98 -> 22
  // Masses ρ π d³/6 = 4084.0704 d³: 0.53540739, 0.27412858, 0.14035384, 0.071861164 kg.
  ASSERT_EQ(plan.discs.size(), 4u);
  const double diameters[] = {0.0508, 0.04064, 0.032512, 0.0260096};
  const int counts[] = {43, 29, 19, 22};
  const double masses[] = {0.53540739, 0.27412858, 0.14035384, 0.071861164};
  double slice_mass = 0.0;
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_HAND(plan.discs[k].diameter, diameters[k]);
    EXPECT_EQ(plan.discs[k].count, counts[k]) << "class " << k;
    EXPECT_HAND(plan.discs[k].mass, masses[k]);
    slice_mass += counts[k] * masses[k];
  }
  EXPECT_EQ(plan.particle_count, 43 + 29 + 19 + 22);
  // 43 × 0.53540739 + 29 × 0.27412858 + 19 × 0.14035384 + 22 × 0.071861164
  // = 23.022518 + 7.9497289 + 2.6667229 + 1.5809456 = 35.219915 kg; power_scale
  // = 133.97793 / 35.219915 = 3.8040390.
  EXPECT_HAND(slice_mass, 35.219915);
  EXPECT_HAND(plan.slice_mass, 35.219915);
  EXPECT_HAND(plan.power_scale, 3.8040390);
}

TEST(MillPlan, AutoTimeStepIsATwentiethOfTheShortestContact) {
  // For a linear spring–dashpot with Corkum's damping, ζ² = ln²e / (ln²e + π²), so
  // t_c = π / (ω₀ sqrt(1 − ζ²)) = sqrt(m*/k_n) sqrt(π² + ln²e).
  // e = 0.6: ln e = −0.51082562, π² + ln²e = 9.8696044 + 0.26094282 = 10.130547, root 3.1828521.
  // Two 5.08 cm discs: m* = 0.53540739 / 2 = 0.26770370 kg, sqrt(m*/k_n) = sqrt(6.6925924e-7)
  // = 8.1808266e-4 s, t_c = 2.6038361e-3 s. One disc on a wall: m* = m, t_c × sqrt 2
  // = 3.6823803e-3 s. Δt = 2.6038361e-3 / 20 = 1.3019180e-4 s.
  const MillConfig config = lab_mill();
  const MillPlan plan = plan_mill(config);
  EXPECT_HAND(contact_duration(config.ball_ball, 0.26770370), 2.6038361e-3);
  EXPECT_HAND(contact_duration(config.ball_wall, 0.53540739), 3.6823803e-3);
  EXPECT_HAND(plan.contact_duration_ball_ball, 2.6038361e-3);
  EXPECT_HAND(plan.contact_duration_ball_wall, 3.6823803e-3);
  EXPECT_HAND(plan.time_step, 1.3019180e-4);
  EXPECT_EQ(plan.time_step,
            std::min(plan.contact_duration_ball_ball, plan.contact_duration_ball_wall) /
                steps_per_contact);

  // Graded charge: the smallest disc, 2.60096 cm, 0.071861164 kg: m* = 0.035930582 kg,
  // sqrt(m*/k_n) = sqrt(8.9826455e-8) = 2.9971062e-4 s, t_c = 9.5393456e-4 s, Δt = 4.7696728e-5 s.
  const MillPlan graded = plan_mill(graded_lab_mill());
  EXPECT_HAND(graded.contact_duration_ball_ball, 9.5393456e-4);
  EXPECT_HAND(graded.time_step, 4.7696728e-5);
}

TEST(MillPlan, GivenTimeStepIsUsedBelowTheStabilityLimitAndRefusedAboveIt) {
  // Stability limit: each mode's 2 / (ω (sqrt(1 + 4 ζ²) + 2 ζ)), the shorter (docs/model.md).
  // Two 5.08 cm discs: normal ω = sqrt(k_n/m*) = sqrt(4e5/0.26770370) = 1222.3704 s⁻¹ with
  // e = 0.6's ζ = 0.16049305, sqrt(1 + 4 ζ²) + 2 ζ = 1.3712394: 1.1932017e-3 s; tangential,
  // with 1/m_t = 2 (1 + 1/(1/2))/m = 6/m: ω = sqrt(6 k_s/m) = sqrt(1.8e6/0.53540739) =
  // 1833.5555 s⁻¹ with ζ sqrt(m*/m_t) = ζ √3, sqrt(1 + 4 ζ²·3) + 2 ζ √3 = 1.7001216:
  // 6.4158756e-4 s, the shorter (a wall's, m* = m and m_t = m/3, are longer).
  const MillPlan plan = plan_mill(lab_mill());
  EXPECT_HAND(plan.critical_time_step, 6.4158756e-4);
  EXPECT_EQ(plan_mill(lab_mill({"simulation.time_step=6.4e-4"})).time_step, 6.4e-4);
  EXPECT_THROW(plan_mill(lab_mill({"simulation.time_step=6.5e-4"})), InputError);
  // The limit as messages and `info` print it is allowed (in four digits it read 0.0006416, which
  // is above it and was refused).
  const std::string printed = limit_text(plan.critical_time_step, Allowed::below);
  EXPECT_EQ(printed, "0.0006415875");
  EXPECT_NO_THROW(plan_mill(lab_mill({"simulation.time_step=" + printed})));
}

TEST(MillPlan, AGivenTimeStepOfFewerThanTenStepsPerContactIsRunWithAWarning) {
  // The shortest contact is t_c = 2.6038361e-3 s (above): 10 steps are 2.6038361e-4 s.
  EXPECT_TRUE(plan_mill(lab_mill()).warnings.empty());  // auto: 20 steps
  EXPECT_TRUE(plan_mill(lab_mill({"simulation.time_step=2.6e-4"})).warnings.empty());
  const MillPlan coarse = plan_mill(lab_mill({"simulation.time_step=5.2e-4"}));
  EXPECT_EQ(coarse.time_step, 5.2e-4);
  ASSERT_EQ(coarse.warnings.size(), 1u);
  const std::string& warning = coarse.warnings[0];
  for (const std::string_view part :
       {"command line (--set simulation.time_step=5.2e-4): simulation.time_step: 0.00052 s",
        "shortest contact (0.0026 s) in 5.01 steps, fewer than 10",
        "\"auto\" takes 0.00013 s, 1/20 of it"}) {
    EXPECT_NE(warning.find(part), std::string::npos) << warning;
  }
  // Just coarser than 10 steps: 9.9987 steps, which three digits once showed as "10 steps,
  // fewer than 10".
  const MillPlan just = plan_mill(lab_mill({"simulation.time_step=2.60418e-4"}));
  ASSERT_EQ(just.warnings.size(), 1u);
  EXPECT_NE(just.warnings[0].find("in 9.999 steps, fewer than 10"), std::string::npos)
      << just.warnings[0];
}

TEST(MillPlan, AFigureBeyondAThresholdIsShownBeyondIt) {
  EXPECT_EQ(beyond_text(5.2, 5.0), "5.2");
  EXPECT_EQ(beyond_text(5.004, 5.0), "5.004");
  EXPECT_EQ(beyond_text(4.9996, 5.0), "4.9996");
  EXPECT_EQ(beyond_text(50.4, 50.0, 2), "50.4");
  EXPECT_EQ(beyond_text(63.0, 50.0, 2), "63");
  EXPECT_EQ(beyond_text(5.0, 5.0), "5");  // on the threshold: as asked
}

TEST(MillPlan, SnapshotsAreCountedAndTheirSizeBoundedWithAWarningWhenLarge) {
  // The built-in example: 17.012954 s at Δt = 1.3019180e-4 s (above), a snapshot every
  // 0.05 s: floor((17.012954 − Δt/2) / 0.05) + 1 = floor(340.258) + 1 = 341, of 75 discs.
  const MillPlan csv = plan_mill(parse_mill_config(builtin_example_toml, "lab-mill-2d.toml"));
  EXPECT_EQ(csv.snapshot_count, 341.0);
  EXPECT_EQ(csv.snapshot_bytes, 341.0 * 75.0 * snapshot_bytes_per_particle(2, false));
  const MillPlan both = plan_mill(
      parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", {"output.snapshot_format=both"}));
  EXPECT_EQ(both.snapshot_bytes, 341.0 * (75.0 * (snapshot_bytes_per_particle(2, false) +
                                                  snapshot_bytes_per_particle(2, true)) +
                                          snapshot_mill_bytes(2, 8, false)));
  EXPECT_TRUE(both.warnings.empty());
  const MillPlan none = plan_mill(lab_mill());
  EXPECT_EQ(none.snapshot_count, 0.0);
  EXPECT_EQ(none.snapshot_bytes, 0.0);
  EXPECT_TRUE(none.warnings.empty());
  // A format asked for with no snapshots to write is said to be without effect.
  const MillPlan unused = plan_mill(lab_mill({"output.snapshot_format=vtk"}));
  ASSERT_EQ(unused.warnings.size(), 1U);
  EXPECT_EQ(unused.warnings[0],
            "command line (--set output.snapshot_format=vtk): output.snapshot_format: \"vtk\" is "
            "set, but output.snapshot_interval is 0 (command line (--set "
            "output.snapshot_interval=0)): no snapshots are written");
  // Small balls and a snapshot every 2 ms: beyond snapshot_bytes_warned, said with the key.
  const MillPlan large =
      plan_mill(parse_mill_config(builtin_example_toml, "lab-mill-2d.toml",
                                  {"charge.ball_diameter=0.005", "output.snapshot_interval=0.0002",
                                   "output.snapshot_format=both"}));
  ASSERT_GT(large.snapshot_bytes, snapshot_bytes_warned);
  ASSERT_EQ(large.warnings.size(), 1U);
  EXPECT_EQ(large.warnings[0],
            fmt::format("command line (--set output.snapshot_interval=0.0002): "
                        "output.snapshot_interval: {:.0f} snapshots of {} particles take up to "
                        "about {:.0f} GB of disk; a longer interval takes less, 0 none",
                        large.snapshot_count, large.particle_count, large.snapshot_bytes / 1e9));
}

TEST(MillPlan, AutoTimeStepStaysAtAQuarterOfTheStabilityLimitWhenTheTangentialSpringIsStiff) {
  // k_s = 1e9 N/m: the tangential ω = sqrt(6 k_s/m) = sqrt(6e9/0.53540739) = 1.0586038e5 s⁻¹,
  // limit 2 / (ω · 1.7001216) = 1.1112622e-5 s (GivenTimeStepIsUsedBelow...), far below
  // t_c/20 = 1.3019180e-4 s: the step is a quarter of it, 2.7781556e-6 s.
  const MillPlan plan = plan_mill(lab_mill({"materials.ball_ball.tangential_stiffness=1e9",
                                            "materials.ball_wall.tangential_stiffness=1e9"}));
  EXPECT_HAND(plan.critical_time_step, 1.1112622e-5);
  EXPECT_HAND(plan.time_step, 2.7781556e-6);
  EXPECT_EQ(plan.time_step, 0.25 * plan.critical_time_step);
}

/// The message of the InputError plan_mill throws for `config`.
std::string plan_error(const MillConfig& config) {
  try {
    plan_mill(config);
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "planned";
  return {};
}

void expect_has(const std::string& message, std::initializer_list<std::string_view> parts) {
  for (const std::string_view part : parts) {
    EXPECT_NE(message.find(part), std::string::npos) << "lacks \"" << part << "\":\n" << message;
  }
}

TEST(MillPlan, RefusesAOneSizeChargePastTheJammingLimitOfRandomPlacementBeforePlacingIt) {
  // The lab mill's discs cover 0.8 J of its cross-section: 173 discs at J = 0.69 cover
  // 173 × π 0.0254² / (π 0.45²) = 0.5512, past the 0.5470735 that discs placed one by one at
  // random can reach; 171 at J = 0.68 cover 0.5448 and are left to the placement.
  expect_has(plan_error(lab_mill({"charge.filling=0.69"})),
             {"charge.filling: 173 discs of 0.0508 m would take 0.551 of the mill's cross-section",
              "more than the 0.5470735", "cannot be placed", "allowed: a filling below about"});
  EXPECT_EQ(plan_mill(lab_mill({"charge.filling=0.68"})).particle_count, 171);
  // Found at once however many: 2.9 million discs at J = 0.95 in a 100 m mill, whose placement
  // had not given up after 15 minutes.
  expect_has(plan_error(lab_mill({"mill.diameter=100", "charge.filling=0.95"})),
             {"charge.filling: 2945", "would take 0.76"});
  // Spheres: 0.6 J of a whole mill 0.15 m long, past 0.384130 from J = 0.65 (542 balls, 0.390).
  const std::vector<std::string> whole_3d = {"simulation.dimension=3", "mill.length=0.15"};
  auto in_3d = [&](const std::string& filling) {
    std::vector<std::string> overrides = whole_3d;
    overrides.push_back(filling);
    return lab_mill(overrides);
  };
  expect_has(plan_error(in_3d("charge.filling=0.65")),
             {"542 balls of 0.0508 m would take 0.390 of the mill's volume", "0.38413",
              "and this porosity"});
  EXPECT_GT(plan_mill(in_3d("charge.filling=0.62")).particle_count, 0);
  // A graded charge is not held to one size's limit (its small balls fill the large ones' gaps).
  MillConfig graded = graded_lab_mill();
  graded.filling = 0.75;
  EXPECT_GT(plan_mill(graded).particle_count, 0);
}

TEST(MillPlan, RefusesMillsThatCannotRunNamingTheKey) {
  // Critical speed 45.900339 rpm (above): at most 5 times that, 229.5 rpm.
  MillConfig in_rpm = lab_mill();
  in_rpm.speed_fraction.reset();
  in_rpm.speed_rpm = 1e6;
  expect_has(plan_error(in_rpm),
             {"mill.speed_rpm", "1000000 rpm is 21786.332 times", "critical speed, 45.9003 rpm",
              "at most 5 times critical, 229.50169 rpm"});
  // Just past the limit: each figure to as many digits as keep it on its side of the limit,
  // not "5 times" and "229.5 rpm", which the speed seemed to meet.
  in_rpm.speed_rpm = 229.502;
  expect_has(plan_error(in_rpm),
             {"229.502 rpm is 5.00001 times", "at most 5 times critical, 229.50169 rpm"});
  // A 100 m mill 30 % full of 5 mm discs at a 2D void fraction of 0.2:
  // 0.3 × π 50² × 0.8 / (π/4 × 0.005²) = 9.6e7 discs.
  expect_has(plan_error(lab_mill({"mill.diameter=100", "charge.ball_diameter=0.005"})),
             {"charge.filling", "9.6e+07 discs", "at most 5e+07"});
  // 1e-9 of the volume: 75 discs at J = 0.3 become 2.5e-7 of one.
  expect_has(plan_error(lab_mill({"charge.filling=1e-9"})), {"charge.filling", "rounds to none"});
  // 1 s of settling, half the spin-up's quarter period and 6 revolutions of 60/22.950170 =
  // 2.6143604 s: 17.013 s, at 1e-9 s a step 1.70e10 steps.
  expect_has(plan_error(lab_mill({"simulation.time_step=1e-9"})),
             {"simulation.revolutions", "1.7e+10 steps", "at most 1e+10 steps"});
  // Just past the limit, the count is not rounded to the limit itself ("1e+10 steps; allowed:
  // at most 1e+10 steps" once), nor a charge just short of half a disc to half a disc: 0.0019911
  // of the example's 75.33 discs at J = 0.3 is 0.49997 of one.
  EXPECT_EQ(step_count_text(1.7e10, 1e10), "1.7e+10");
  EXPECT_EQ(step_count_text(1.0000001e10, 1e10), "1.0000001e+10");
  expect_has(plan_error(lab_mill({"charge.filling=0.0019911"})),
             {"charge.filling: this charge is 0.4999", "rounds to none"});
  // A subnormal step overflows the count, which once read "inf steps".
  expect_has(plan_error(lab_mill({"simulation.time_step=1e-310"})),
             {"simulation.revolutions", "is more than 1.7e+308 steps", "at most 1e+10 steps"});
  MillConfig snapshots = lab_mill();
  snapshots.snapshot_interval = 1e-5;
  expect_has(plan_error(snapshots),
             {"output.snapshot_interval", "shorter than the time step, 0.0001302 s"});
}

/// Every disc inside the shell, clear of the lifters and of every other disc.
void expect_placed_without_contacts(const MillPlan& plan, const World<2>& world) {
  const auto& p = world.particles();
  ASSERT_EQ(p.size(), static_cast<std::size_t>(plan.particle_count));
  const Mill2D& mill = *world.walls().mill;
  EXPECT_EQ(mill.radius, plan.radius);
  EXPECT_EQ(mill.lifter_count, 8);
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_LT(norm(p.position[i]) + p.radius[i], plan.radius) << "disc " << i << " in the shell";
    WallContact<2> found[4];
    EXPECT_EQ(mill_contacts(mill, p.position[i], p.radius[i], found), 0) << "disc " << i;
    EXPECT_EQ(p.velocity[i], Vec2{}) << "disc " << i << " starts at rest";
    EXPECT_EQ(p.angular_velocity[i], 0.0);
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      EXPECT_GT(norm(p.position[j] - p.position[i]), p.radius[i] + p.radius[j])
          << "discs " << i << " and " << j << " overlap";
    }
  }
  // Each class is there with its count, radius and mass.
  for (const DiscClass& c : plan.discs) {
    const auto count = std::count_if(p.radius.begin(), p.radius.end(),
                                     [&](double r) { return r == 0.5 * c.diameter; });
    EXPECT_EQ(count, c.count) << "discs of " << c.diameter << " m";
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto c = std::find_if(plan.discs.begin(), plan.discs.end(), [&](const DiscClass& d) {
      return 0.5 * d.diameter == p.radius[i];
    });
    ASSERT_NE(c, plan.discs.end());
    EXPECT_EQ(p.mass[i], c->mass);
  }
}

TEST(MillPlan, ChargeIsPlacedWithoutTouchingWallsOrEachOther) {
  const MillPlan plan = plan_mill(lab_mill());
  const World<2> world = build_mill_world<2>(plan);
  expect_placed_without_contacts(plan, world);
  EXPECT_EQ(world.walls().mill->angular_speed, 0.0) << "the shell starts still";
  EXPECT_EQ(world.settings().time_step, plan.time_step);
  EXPECT_EQ(world.settings().gravity, (Vec2{{0.0, -9.81}}));

  const MillPlan graded = plan_mill(graded_lab_mill());
  expect_placed_without_contacts(graded, build_mill_world<2>(graded));
}

TEST(MillPlan, PlacementIsDecidedByTheSeed) {
  const MillPlan plan = plan_mill(lab_mill());
  const World<2> a = build_mill_world<2>(plan);
  const World<2> b = build_mill_world<2>(plan);
  EXPECT_EQ(a.particles().position, b.particles().position) << "same seed, same bits";
  EXPECT_EQ(a.particles().radius, b.particles().radius);

  const MillPlan other = plan_mill(lab_mill({"simulation.seed=2"}));
  const World<2> c = build_mill_world<2>(other);
  ASSERT_EQ(c.particles().size(), a.particles().size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a.particles().size(); ++i) {
    differing += a.particles().position[i] != c.particles().position[i] ? 1 : 0;
  }
  EXPECT_EQ(differing, a.particles().size()) << "another seed moves every disc";
}

}  // namespace
}  // namespace millsim
