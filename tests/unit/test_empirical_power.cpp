// The empirical mill-power models (measure/empirical_power.hpp): each formula against a value
// worked by hand, the arithmetic in the comment above the check and the expected value computed
// step by step from literal numbers; then scaling and limiting cases, the inputs millsim takes
// from a mill plan, and summary.json's "empirical" object.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "millsim/builtin_example.hpp"
#include "millsim/core/constants.hpp"
#include "millsim/io/config.hpp"
#include "millsim/io/output.hpp"
#include "millsim/measure/empirical_power.hpp"
#include "millsim/sim/charge.hpp"
#include "millsim/sim/mill_run.hpp"

namespace millsim {
namespace {

// A formula re-evaluated from literal numbers agrees to rounding.
constexpr double formula_tolerance = 1e-9;

#define EXPECT_FORMULA(actual, expected) \
  EXPECT_NEAR((actual), (expected), std::abs(expected) * formula_tolerance)

/// A round-number mill: D = 2 m, L = 1 m, J = 0.4, 75 % of the shell's critical speed, steel
/// bed of 7800 kg/m³ with porosity 0.4 (ρ_b = 4680 kg/m³), 5 cm top ball.
EmpiricalPowerInputs round_mill() {
  EmpiricalPowerInputs in;
  in.diameter = 2.0;
  in.length = 1.0;
  in.filling = 0.4;
  // N_c = (60/2π) sqrt(2 × 9.81 / 2) = 9.5492966 × 3.1320919 = 29.909275 rpm.
  in.shell_critical_speed_rpm = 60.0 / (2.0 * pi) * std::sqrt(2.0 * 9.81 / 2.0);
  in.speed_fraction = 0.75;
  in.speed_rpm = 0.75 * in.shell_critical_speed_rpm;  // 22.431956 rpm
  in.ball_density = 7800.0;
  in.porosity = 0.4;
  in.bed_density = 4680.0;
  // M = ρ_b J π D²/4 L = 4680 × 0.4 × π × 1 × 1 = 5881.0614 kg.
  in.ball_charge_mass = 4680.0 * 0.4 * pi;
  in.top_ball_diameter = 0.05;
  return in;
}

/// Case 2D-g of MODEL.md §8 as the formulas see it, with round inputs given directly:
/// D = 4.11 m, L = 5.49 m, J = 0.34, φ = 0.77, 7.6 cm top ball, ρ_b = 4680 kg/m³.
EmpiricalPowerInputs case_2d_g() {
  EmpiricalPowerInputs in;
  in.diameter = 4.11;
  in.length = 5.49;
  in.filling = 0.34;
  in.speed_fraction = 0.77;
  in.speed_rpm = 16.2;
  in.ball_density = 7800.0;
  in.porosity = 0.4;
  in.bed_density = 4680.0;
  in.ball_charge_mass = 100000.0;  // 100 t, round for Bond's check
  in.top_ball_diameter = 0.076;
  return in;
}

TEST(EmpiricalPower, BondRoundNumberMill) {
  EmpiricalPowerInputs in;
  in.diameter = 1.0;
  in.filling = 0.4;
  in.speed_fraction = 0.8;
  in.top_ball_diameter = 0.05;
  in.ball_charge_mass = 1000.0;
  // D^0.3 = 1; 3.2 − 3 × 0.4 = 2; 2^(9 − 8) = 2, so 0.8 × (1 − 0.1/2) = 0.8 × 0.95 = 0.76;
  // D = 1 m <= 3.3 m: S_s = 0. kWb = 4.879 × 1 × 2 × 0.76 = 7.41608 kW/t; 1 t: 7.41608 kW.
  const BondPower bond = bond_power(in);
  EXPECT_EQ(bond.ball_size_factor, 0.0);
  EXPECT_FORMULA(bond.kw_per_ball_tonne, 4.879 * 1.0 * 2.0 * 0.76);
  EXPECT_FORMULA(bond.power_kw, 7.41608);
}

TEST(EmpiricalPower, BondCase2Dg) {
  const EmpiricalPowerInputs in = case_2d_g();
  // D^0.3 = 4.11^0.3 = 1.5281027; 3.2 − 3 × 0.34 = 2.18;
  // 2^(9 − 7.7) = 2^1.3 = 2.4622888, so 0.77 × (1 − 0.1/2.4622888) = 0.73872828;
  // D > 3.3 m: S_s = 1.102 × (76 − 12.5 × 4.11)/50.8 = 1.102 × 24.625/50.8 = 0.53418799 kW/t.
  // kWb = 4.879 × 1.5281027 × 2.18 × 0.73872828 + 0.53418799 = 12.540914 kW/t; × 100 t.
  const double d_power = std::pow(4.11, 0.3);
  const double speed_term = 0.77 * (1.0 - 0.1 / std::pow(2.0, 1.3));
  const double size_factor = 1.102 * (76.0 - 12.5 * 4.11) / 50.8;
  const double kwb = 4.879 * d_power * 2.18 * speed_term + size_factor;
  const BondPower bond = bond_power(in);
  EXPECT_FORMULA(bond.ball_size_factor, size_factor);
  EXPECT_FORMULA(bond.ball_size_factor, 0.53418799212598);
  EXPECT_FORMULA(bond.kw_per_ball_tonne, kwb);
  EXPECT_NEAR(bond.kw_per_ball_tonne, 12.540914, 1e-6);
  EXPECT_FORMULA(bond.power_kw, kwb * 100.0);
}

TEST(EmpiricalPower, BondBallSizeFactorOnlyAboveThreePointThreeMetres) {
  // B = 76 mm: D = 3.3 m is not above the limit; D = 3.31 m gives
  // 1.102 × (76 − 41.375)/50.8 = 0.75111220 kW/t; a 2 m mill none.
  EXPECT_EQ(bond_ball_size_factor(3.3, 0.076), 0.0);
  EXPECT_EQ(bond_ball_size_factor(2.0, 0.076), 0.0);
  EXPECT_FORMULA(bond_ball_size_factor(3.31, 0.076), 1.102 * (76.0 - 12.5 * 3.31) / 50.8);
  // The factor is what kWb gains over the bare formula.
  const double bare = 4.879 * std::pow(3.31, 0.3) * (3.2 - 3.0 * 0.34) * 0.77 *
                      (1.0 - 0.1 / std::pow(2.0, 9.0 - 7.7));
  EXPECT_FORMULA(bond_kw_per_ball_tonne(3.31, 0.34, 0.77, 0.076),
                 bare + 1.102 * (76.0 - 41.375) / 50.8);
  // A small ball in a big mill lowers the power: B = 40 mm, D = 4 m: 1.102 × (40 − 50)/50.8 < 0.
  EXPECT_LT(bond_ball_size_factor(4.0, 0.040), 0.0);
}

TEST(EmpiricalPower, BondDoesNotApplyWhereItsEquationGivesNoPositivePower) {
  EmpiricalPowerInputs in;
  in.diameter = 1.0;
  in.filling = 0.4;
  in.top_ball_diameter = 0.05;
  in.ball_charge_mass = 1000.0;
  // At 80 % of critical: 7.41608 kW (BondRoundNumberMill).
  in.speed_fraction = 0.8;
  EXPECT_TRUE(bond_power(in).applies);
  EXPECT_EQ(bond_power_text(bond_power(in)), "Bond 7.416 kW");
  // At 150 %: 2^(9 − 15) = 1/64, so the speed term is 1.5 × (1 − 6.4) = −8.1 and kWb < 0.
  in.speed_fraction = 1.5;
  EXPECT_FORMULA(bond_power(in).kw_per_ball_tonne, 4.879 * 2.0 * 1.5 * (1.0 - 6.4));
  EXPECT_FALSE(bond_power(in).applies);
  EXPECT_EQ(bond_power_text(bond_power(in)),
            "Bond n/a (its equation gives no positive power for this mill)");
  // A 150 m mill at 80 %: S_s = 1.102 × (50 − 1875)/50.8 = −39.59 kW/t outweighs
  // 4.879 × 150^0.3 × 2 × 0.76 = 33.34 kW/t.
  in.speed_fraction = 0.8;
  in.diameter = 150.0;
  EXPECT_FORMULA(bond_power(in).kw_per_ball_tonne,
                 4.879 * std::pow(150.0, 0.3) * 2.0 * 0.76 + 1.102 * (50.0 - 1875.0) / 50.8);
  EXPECT_FALSE(bond_power(in).applies);
}

TEST(EmpiricalPower, SummaryJsonLeavesOutBondsPowerWhereItDoesNotApply) {
  MillResult result;
  result.plan =
      plan_mill(parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", {"mill.speed=1.5"}));
  ASSERT_FALSE(empirical_power(result.plan).bond.applies);
  const std::string json = summary_json(result);
  EXPECT_EQ(json.find("\"bond_kw\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"hogg_fuerstenau_kw\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"kw_per_ball_tonne\""), std::string::npos) << json;
  EXPECT_NE(summary_line(result).find("empirical: Bond n/a"), std::string::npos);
}

TEST(EmpiricalPower, ResultWarningsFlagAnOpenEnergyBalanceOrPowersThatDisagree) {
  MillResult result;
  result.plan = plan_mill(parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", {}));
  result.power_kw = 1.0;
  result.power_dissipation_kw = 1.09;  // 8.3 % of the larger apart: within 10 %
  result.energy_balance_error = 0.049;
  EXPECT_TRUE(result_warnings(result).empty());
  result.power_dissipation_kw = 1.12;  // 10.7 % apart
  ASSERT_EQ(result_warnings(result).size(), 1u);
  EXPECT_NE(result_warnings(result)[0].find(
                "power by torque (1 kW) and by dissipation (1.12 kW) differ by more than 10 %"),
            std::string::npos)
      << result_warnings(result)[0];
  // The built-in example runs 6 revolutions and measures 4: the spin-up is not measured.
  EXPECT_NE(result_warnings(result)[0].find("run more revolutions before measuring"),
            std::string::npos)
      << result_warnings(result)[0];
  result.power_dissipation_kw = 0.89;  // the other way round: 11 % of the larger
  EXPECT_EQ(result_warnings(result).size(), 1u);
  MillResult measured_spin_up = result;
  measured_spin_up.plan = plan_mill(
      parse_mill_config(builtin_example_toml, "lab-mill-2d.toml",
                        {"simulation.revolutions=2", "simulation.measure_revolutions=2"}));
  ASSERT_EQ(result_warnings(measured_spin_up).size(), 1u);
  EXPECT_NE(result_warnings(measured_spin_up)[0].find(
                "the first revolution, which includes the spin-up, was measured; run more "
                "revolutions than are measured"),
            std::string::npos)
      << result_warnings(measured_spin_up)[0];
  // An open balance explains the powers' disagreement: it alone is reported.
  result.energy_balance_error = 0.051;
  ASSERT_EQ(result_warnings(result).size(), 1u);
  EXPECT_NE(
      result_warnings(result)[0].find("the energy balance is off by 5.1 % of the shell's work"),
      std::string::npos)
      << result_warnings(result)[0];
  result.energy_balance_error = 21.2;
  EXPECT_NE(result_warnings(result)[0].find("off by 2120 % of"), std::string::npos)
      << result_warnings(result)[0];
  // Just past 5 %: not "off by 5 % ... (more than 5 %)".
  result.energy_balance_error = 0.05004;
  EXPECT_NE(result_warnings(result)[0].find("off by 5.004 % of"), std::string::npos)
      << result_warnings(result)[0];
  // The same for overlaps just past a half of the radius.
  result.energy_balance_error = 0.01;
  result.power_dissipation_kw = result.power_kw;
  result.largest_overlap_fraction = 0.504;
  ASSERT_EQ(result_warnings(result).size(), 1u);
  EXPECT_NE(result_warnings(result)[0].find("overlapped by up to 50.4 % of the smaller ball's "
                                            "radius (more than 50 %)"),
            std::string::npos)
      << result_warnings(result)[0];
  result.largest_overlap_fraction = 0.0;
  result.power_dissipation_kw = 0.89;
  // A balance that is not a number is not closed either: it is the warning given, not the
  // powers' (which still differ by 11 % here, so a NaN taken as closed would give that one).
  result.energy_balance_error = std::nan("");
  ASSERT_EQ(result_warnings(result).size(), 1u);
  EXPECT_EQ(
      result_warnings(result)[0].rfind("the energy balance is off by nan % of the shell's work", 0),
      0u)
      << result_warnings(result)[0];
}

TEST(EmpiricalPower, TheSummaryLineShowsTheSpreadOnlyWhenSeveralRevolutionsAreMeasured) {
  MillResult result;
  result.plan = plan_mill(parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", {}));
  result.power_std_kw = 0.0123;
  EXPECT_NE(summary_line(result).find("±0.012 kW between revolutions"), std::string::npos)
      << summary_line(result);
  result.plan = plan_mill(parse_mill_config(builtin_example_toml, "lab-mill-2d.toml",
                                            {"simulation.measure_revolutions=1"}));
  EXPECT_NE(summary_line(result).find("one revolution measured"), std::string::npos)
      << summary_line(result);
  EXPECT_EQ(summary_line(result).find("between revolutions"), std::string::npos);
}

TEST(EmpiricalPower, SummaryJsonRefusesAFigureThatIsNotFinite) {
  // JSON has no infinity or NaN: a diverged run is reported as failed, not written as "inf".
  MillResult result;
  result.plan = plan_mill(parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", {}));
  result.power_kw = 0.5;
  EXPECT_NO_THROW((void)summary_json(result));
  result.power_dissipation_kw = std::numeric_limits<double>::infinity();
  try {
    (void)summary_json(result);
    ADD_FAILURE() << "written";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("the run diverged: power_dissipation_kw is inf"),
              std::string::npos)
        << error.what();
  }
  result.power_dissipation_kw = 0.5;
  result.charge_centre[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)summary_json(result), std::runtime_error);
}

TEST(EmpiricalPower, SegmentHalfAngle) {
  // J = (θ − sin θ cos θ)/π: θ = π/2 for a half-full mill, 0 empty, π full.
  EXPECT_NEAR(segment_half_angle(0.5), pi / 2.0, 1e-14);
  EXPECT_EQ(segment_half_angle(0.0), 0.0);
  EXPECT_NEAR(segment_half_angle(1.0), pi, 1e-14);
  // J = 0.34: θ = 1.3138911 rad, and θ − sin θ cos θ = 1.0681415 = 0.34 π.
  const double theta = segment_half_angle(0.34);
  EXPECT_NEAR(theta, 1.3138911138, 1e-9);
  EXPECT_NEAR(theta - std::sin(theta) * std::cos(theta), 0.34 * pi, 1e-14);
}

TEST(EmpiricalPower, HoggFuerstenauHalfFilledMill) {
  EmpiricalPowerInputs in = round_mill();
  in.filling = 0.5;
  in.speed_rpm = 30.0;
  in.repose_angle = pi / 6.0;
  in.ball_charge_mass = 4680.0 * 0.5 * pi;
  // J = 0.5: θ = π/2, sin³θ = 1; r_c = 2 R/(3 × π/2) = 4/(3π) = 0.42441318 m.
  // P = (4π/3) N g ρ_b L R³ sin³θ sin α = 4.1887902 × 0.5 × 9.81 × 4680 × 1 × 1 × 1 × 0.5
  //   = 48077.677 W = 48.077677 kW.
  const HoggFuerstenauPower hf = hogg_fuerstenau_power(in);
  EXPECT_NEAR(hf.half_angle, pi / 2.0, 1e-14);
  EXPECT_FORMULA(hf.centre_of_mass_radius, 4.0 / (3.0 * pi));
  EXPECT_FORMULA(hf.power_kw, 4.0 * pi / 3.0 * 0.5 * 9.81 * 4680.0 * 0.5 / 1000.0);
  EXPECT_NEAR(hf.power_kw, 48.077677, 1e-6);
  // The same as 2π N M g r_c sin α with M = 4680 × 0.5 × π = 7351.3268 kg.
  EXPECT_FORMULA(hf.power_kw,
                 2.0 * pi * 0.5 * (4680.0 * 0.5 * pi) * 9.81 * (4.0 / (3.0 * pi)) * 0.5 / 1000.0);
}

TEST(EmpiricalPower, HoggFuerstenauCase2Dg) {
  const EmpiricalPowerInputs in = case_2d_g();
  // θ = 1.3138911 rad (SegmentHalfAngle), sin θ = 0.96718096, sin³θ = 0.90473879;
  // R = 2.055 m: r_c = 2 × 2.055 × 0.90473879 / (3 × 1.0681415) = 1.1604194 m;
  // M = 4680 × 0.34 × π × 2.055² × 5.49 = 115896.59 kg; N = 16.2/60 = 0.27 rev/s; sin 35° =
  // 0.57357644. P = 2π × 0.27 × 115896.59 × 9.81 × 1.1604194 × 0.57357644 = 1283.7769 kW.
  const double theta = 1.3138911138074814;
  const double r_c = 2.0 * 2.055 * std::pow(std::sin(theta), 3) /
                     (3.0 * (theta - std::sin(theta) * std::cos(theta)));
  const double mass = 4680.0 * 0.34 * pi * 2.055 * 2.055 * 5.49;
  const double expected = 2.0 * pi * 0.27 * mass * 9.81 * r_c * std::sin(35.0 * pi / 180.0) / 1000;
  const HoggFuerstenauPower hf = hogg_fuerstenau_power(in);
  EXPECT_NEAR(hf.half_angle, theta, 1e-12);
  EXPECT_NEAR(hf.centre_of_mass_radius, r_c, 1e-11);
  EXPECT_NEAR(hf.power_kw, expected, expected * 1e-11);
  EXPECT_NEAR(hf.power_kw, 1283.7769, 1e-4);
}

TEST(EmpiricalPower, MorrellRoundNumberMill) {
  const EmpiricalPowerInputs in = round_mill();
  // φ = 0.75, J = 0.4: 0.35 × (3.364 − 0.4) = 1.0374 > φ, so φ_c = 1.0374.
  const double phi_c = 0.35 * (3.364 - 0.4);
  // θ_T = 2.5307 × (1.2796 − 0.4) × (1 − e^(−19.42 × 0.2874)) + π/2
  //     = 2.22600 × (1 − 0.0037676342) + 1.5707963 = 3.7884133 rad.
  const double toe = 2.5307 * 0.8796 * (1.0 - std::exp(-19.42 * (phi_c - 0.75))) + pi / 2.0;
  // θ_S = π/2 − (θ_T − π/2) × [(0.3386 + 0.1041 × 0.75) + (1.54 − 2.5673 × 0.75) × 0.4]
  //     = 1.5707963 − 2.2176170 × 0.262485 = 0.98870514 rad.
  const double shoulder = pi / 2.0 - (toe - pi / 2.0) * 0.262485;
  // Active arc 2π + θ_S − θ_T = 3.4834772 rad; r_m = 1 m;
  // r̄ = 0.5 × (1 + sqrt(1 − 2π × 0.4/3.4834772)) = 0.76387293 m.
  const double arc = 2.0 * pi + shoulder - toe;
  const double mean_radius = 0.5 * (1.0 + std::sqrt(1.0 - 2.0 * pi * 0.4 / arc));
  // N_m = 22.431956/60 = 0.37386594 rev/s, N = N_m/2; t_c = arc/(2π N) = 2.9658364 s;
  // sin θ_S − sin θ_T = 0.83531480 + 0.60265230 = 1.4379671;
  // t_f = sqrt(2 × 0.76387293 × 1.4379671/9.81) = 0.47322266 s; β = t_c/(t_f + t_c) = 0.86239764.
  const double n_m = 0.75 * 29.909274989176860 / 60.0;
  const double t_c = arc / (2.0 * pi * 0.5 * n_m);
  const double drop = std::sin(shoulder) - std::sin(toe);
  const double t_f = std::sqrt(2.0 * mean_radius * drop / 9.81);
  const double beta = t_c / (t_f + t_c);
  // r_i = sqrt(1 − 2π × 0.86239764 × 0.4/3.4834772) = 0.61464920 m; z = 0.6^0.4532 = 0.79333780.
  const double r_i = std::sqrt(1.0 - 2.0 * pi * beta * 0.4 / arc);
  const double z = std::pow(0.6, 0.4532);
  // r_m − z r_i = 0.51237556; [2 − 3 z r_i + r_i³ (3z − 2)] = 0.62536980;
  // potential = π × 9.81 × 1 × N_m × 1/(3 × 0.51237556) × 0.62536980 × 4680 × 1.4379671
  //           = 31546.910 W;
  // kinetic = 1 × 4680 × (N_m π/0.51237556)³ × [0.51237556⁴ − r_i⁴ (z − 1)⁴]
  //         = 4680 × 2.2923312³ × 0.068660978 = 3870.6860 W;
  // charge motion 35.417596 kW; net = 1.26 × 35.417596 = 44.626171 kW.
  const double gap = 1.0 - z * r_i;
  const double potential = pi * 9.81 * n_m / (3.0 * gap) *
                           (2.0 - 3.0 * z * r_i + r_i * r_i * r_i * (3.0 * z - 2.0)) * 4680.0 *
                           drop;
  const double kinetic = 4680.0 * std::pow(n_m * pi / gap, 3) *
                         (std::pow(gap, 4) - std::pow(r_i, 4) * std::pow(z - 1.0, 4));
  const MorrellPower m = morrell_power(in);
  EXPECT_FORMULA(m.centrifuging_speed_fraction, 1.0374);
  EXPECT_FORMULA(m.toe_angle, toe);
  EXPECT_FORMULA(m.shoulder_angle, shoulder);
  EXPECT_FORMULA(m.mean_radius, mean_radius);
  EXPECT_FORMULA(m.active_fraction, beta);
  EXPECT_FORMULA(m.inner_radius, r_i);
  EXPECT_FORMULA(m.z, z);
  EXPECT_FORMULA(m.charge_motion_kw, (potential + kinetic) / 1000.0);
  EXPECT_FORMULA(m.net_kw, 1.26 * (potential + kinetic) / 1000.0);
  EXPECT_NEAR(m.toe_angle, 3.7884133, 1e-7);
  EXPECT_NEAR(m.shoulder_angle, 0.98870514, 1e-8);
  EXPECT_NEAR(potential, 31546.910, 1e-3);
  EXPECT_NEAR(kinetic, 3870.6860, 1e-3);
  EXPECT_NEAR(m.net_kw, 44.626171, 1e-6);
}

TEST(EmpiricalPower, MorrellAboveCentrifugingSpeedHasToeAtRightAngle) {
  // φ = 1.2 > 0.35 × (3.364 − 0.4) = 1.0374: φ_c = φ, the exponential term vanishes and
  // θ_T = π/2, θ_S = π/2: the charge rides with the shell and lifts nothing.
  EmpiricalPowerInputs in = round_mill();
  in.speed_fraction = 1.2;
  in.speed_rpm = 1.2 * in.shell_critical_speed_rpm;
  const MorrellPower m = morrell_power(in);
  EXPECT_EQ(m.centrifuging_speed_fraction, 1.2);
  EXPECT_NEAR(m.toe_angle, pi / 2.0, 1e-15);
  EXPECT_NEAR(m.shoulder_angle, pi / 2.0, 1e-15);
}

TEST(EmpiricalPower, PowerGrowsLinearlyWithLength) {
  EmpiricalPowerInputs in = case_2d_g();
  const EmpiricalPower one = empirical_power(in);
  in.length *= 3.0;
  in.ball_charge_mass *= 3.0;  // the charge is J of the (longer) mill
  const EmpiricalPower three = empirical_power(in);
  EXPECT_FORMULA(three.bond.power_kw, 3.0 * one.bond.power_kw);
  EXPECT_FORMULA(three.hogg_fuerstenau.power_kw, 3.0 * one.hogg_fuerstenau.power_kw);
  EXPECT_FORMULA(three.morrell.net_kw, 3.0 * one.morrell.net_kw);
}

TEST(EmpiricalPower, EmptyMillDrawsNothing) {
  EmpiricalPowerInputs in = case_2d_g();
  in.filling = 0.0;
  in.ball_charge_mass = 0.0;
  const EmpiricalPower p = empirical_power(in);
  // Bond: kWb > 0 but no tonnes of balls; H–F: sin³θ = 0; Morrell: no charge.
  EXPECT_GT(p.bond.kw_per_ball_tonne, 0.0);
  EXPECT_EQ(p.bond.power_kw, 0.0);
  EXPECT_EQ(p.hogg_fuerstenau.power_kw, 0.0);
  EXPECT_EQ(p.morrell.net_kw, 0.0);
  // And a nearly empty mill draws nearly nothing (no division by zero on the way).
  in.filling = 1e-6;
  in.ball_charge_mass = 4680.0 * 1e-6 * pi * 2.055 * 2.055 * 5.49;
  const EmpiricalPower q = empirical_power(in);
  EXPECT_LT(q.bond.power_kw, 1e-2);
  EXPECT_LT(q.hogg_fuerstenau.power_kw, 1e-2);
  EXPECT_GE(q.morrell.net_kw, 0.0);
  EXPECT_LT(q.morrell.net_kw, 1e-2);
}

MillConfig validation_case(const std::string& name) {
  return load_mill_config(
      std::string(MILLSIM_SOURCE_DIR) + "/examples/validation/" + name + ".toml",
      {"output.snapshot_interval=0"});
}

TEST(EmpiricalPower, InputsFromThePlanOfCase2Dg) {
  const MillPlan plan = plan_mill(validation_case("2D-g"));
  const EmpiricalPowerInputs in = empirical_power_inputs(plan);
  EXPECT_EQ(in.diameter, 4.11);
  EXPECT_EQ(in.length, 5.49);
  EXPECT_EQ(in.filling, 0.34);
  EXPECT_EQ(in.top_ball_diameter, 0.076);
  EXPECT_EQ(in.ball_charge_mass, plan.mill_charge_mass);
  // ρ_b = 7800 × 0.6 = 4680 kg/m³. Speed 0.77 of MODEL.md's N_c = 42.30/sqrt(4.11 − 0.076):
  // 0.77 × 21.059945 = 16.215997 rpm; the shell's N_c = 9.5492966 × sqrt(19.62/4.11) =
  // 20.864309 rpm, so φ = 16.215997/20.864309 = 0.77721950.
  EXPECT_FORMULA(in.bed_density, 4680.0);
  EXPECT_FORMULA(in.speed_rpm, 0.77 * 60.0 / (2.0 * pi) * std::sqrt(19.62 / (4.11 - 0.076)));
  EXPECT_FORMULA(in.shell_critical_speed_rpm, 60.0 / (2.0 * pi) * std::sqrt(19.62 / 4.11));
  EXPECT_FORMULA(in.speed_fraction, 0.77 * std::sqrt(4.11 / (4.11 - 0.076)));
  EXPECT_NEAR(in.speed_fraction, 0.7772195, 1e-7);
  EXPECT_NEAR(in.repose_angle, 35.0 * pi / 180.0, 1e-15);
  // The three models for the measured mill (1324 kW measured), worked independently of this
  // code from the formulas of docs/empirical_power.md (in double precision, outside C++):
  // M = 4680 × 0.34 × π 4.11²/4 × 5.49 = 115896.585 kg.
  // Bond: kWb = 4.879 × 4.11^0.3 × (3.2 − 1.02) × φ (1 − 0.1/2^(9 − 10φ)) = 12.092974, plus
  // S_s = 1.102 (76 − 51.375)/50.8 = 0.534188 (D > 3.3 m): 12.627162 kW/t × 115.896585 t
  // = 1463.44497 kW.
  // Hogg–Fuerstenau: θ − sin θ cos θ = 0.34 π gives θ = 1.3138911; (4π/3) N g ρ_b L R³ sin³θ
  // sin 35°, N = 16.215997/60 rev/s: 1285.04465 kW.
  // Morrell: φ_c = 0.35 (3.364 − 0.34) = 1.0584, θ_T = 3.9385331, θ_S = 0.9440857, then r̄, t_c,
  // t_f, β, r_i and z as in the doc: net 1.26 P = 1436.91989 kW.
  const EmpiricalPower p = empirical_power(plan);
  EXPECT_NEAR(p.bond.power_kw, 1463.44497, 1e-3);
  EXPECT_NEAR(p.hogg_fuerstenau.power_kw, 1285.04465, 1e-3);
  EXPECT_NEAR(p.morrell.net_kw, 1436.91989, 1e-3);
}

/// The numbers of a JSON text's objects by dotted name ("a.b.c" for "c" inside "b" inside "a"),
/// read back with strtod; numbers inside arrays are skipped. A small recursive-descent reader of
/// the JSON that toml++'s json_formatter writes (objects, arrays, strings, numbers, literals);
/// it fails the test on anything else.
class JsonNumbers {
 public:
  explicit JsonNumbers(const std::string& text) : text_(text) {
    value("", false);
    space();
    if (at_ < text_.size()) fail("text after the value");
  }
  std::map<std::string, double> numbers;
  std::vector<std::string> errors;

 private:
  const std::string& text_;
  std::size_t at_ = 0;

  void fail(const std::string& what) {
    errors.push_back(what + " at offset " + std::to_string(at_));
    at_ = text_.size();
  }
  void space() {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
  }
  bool take(char c) {
    space();
    if (at_ < text_.size() && text_[at_] == c) {
      ++at_;
      return true;
    }
    return false;
  }
  std::string string() {
    if (!take('"')) {
      fail("expected a string");
      return {};
    }
    std::string s;
    while (at_ < text_.size() && text_[at_] != '"') {
      if (text_[at_] == '\\') ++at_;  // the keys and texts here need no unescaping
      if (at_ < text_.size()) s += text_[at_++];
    }
    if (!take('"')) fail("unterminated string");
    return s;
  }
  void value(const std::string& name, bool in_array) {
    space();
    if (at_ >= text_.size()) return fail("expected a value");
    const char c = text_[at_];
    if (c == '{') {
      ++at_;
      if (take('}')) return;
      do {
        const std::string key = string();
        if (!take(':')) return fail("expected ':'");
        value(name.empty() ? key : name + "." + key, in_array);
      } while (take(','));
      if (!take('}')) fail("expected '}'");
    } else if (c == '[') {
      ++at_;
      if (take(']')) return;
      do value(name, true);
      while (take(','));
      if (!take(']')) fail("expected ']'");
    } else if (c == '"') {
      string();
    } else {
      const char* begin = text_.c_str() + at_;
      char* end = nullptr;
      const double x = std::strtod(begin, &end);
      if (end == begin) {
        for (const char* literal : {"true", "false", "null"}) {
          if (text_.compare(at_, std::strlen(literal), literal) == 0) {
            at_ += std::strlen(literal);
            return;
          }
        }
        return fail("expected a value");
      }
      at_ += static_cast<std::size_t>(end - begin);
      if (in_array) return;
      if (!numbers.emplace(name, x).second) fail("a second \"" + name + "\"");
    }
  }
};

TEST(EmpiricalPower, SummaryJsonHoldsEveryScalarWithItsValueInItsNestedObject) {
  MillResult result;
  result.plan = plan_mill(parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", {}));
  result.power_kw = 0.5;
  const std::string json = summary_json(result);
  const EmpiricalPower p = empirical_power(result.plan);
  const auto scalars = summary_scalars(result);
  const JsonNumbers read(json);
  ASSERT_TRUE(read.errors.empty()) << read.errors.front() << "\n" << json;
  // Every scalar is the number under its dotted name, the same double: toml++ writes the shortest
  // text that reads back as the same double (or 17 significant digits), and whole numbers
  // (particle_count, steps, …) are small integers, exact in a double.
  bool bond = false;
  std::set<std::string> names;
  for (const auto& [name, value] : scalars) {
    names.insert(name);
    const auto found = read.numbers.find(name);
    if (found == read.numbers.end()) {
      ADD_FAILURE() << name << " is not in summary.json\n" << json;
      continue;
    }
    EXPECT_EQ(found->second, value) << name;
    if (name == "empirical.bond_kw") {
      bond = true;
      EXPECT_EQ(value, p.bond.power_kw);
    } else if (name == "empirical.hogg_fuerstenau_kw") {
      EXPECT_EQ(value, p.hogg_fuerstenau.power_kw);
    } else if (name == "empirical.morrell_net_kw") {
      EXPECT_EQ(value, p.morrell.net_kw);
    } else if (name == "power_kw") {
      EXPECT_EQ(value, 0.5);
    }
  }
  EXPECT_TRUE(bond);
  // And no number of an object is left out of summary_scalars (the sweep's table has them all).
  for (const auto& [name, value] : read.numbers) {
    EXPECT_TRUE(names.count(name) == 1) << name << " = " << value << " is not a summary scalar";
  }
  EXPECT_TRUE(read.numbers.count("empirical.inputs.diameter_m") == 1);
}

TEST(EmpiricalPower, SummaryNumbersAreWrittenInTheirShortestExactForm) {
  // What toml++'s writer gives with GCC (17 significant digits), and what is kept.
  EXPECT_EQ(shortest_json_numbers(
                R"({"a" : 0.050799999999999998, "b" : -1.0000000000000001e-05, "c" : 3.0, )"
                R"("d" : 75, "e" : [ 0.16070020622622724, -0.1633766397445303 ], )"
                R"("f" : "0.050799999999999998 \"1.5000000000000000\" x", "g" : 1e+300})"),
            R"({"a" : 0.0508, "b" : -1e-05, "c" : 3.0, )"
            R"("d" : 75, "e" : [ 0.16070020622622724, -0.1633766397445303 ], )"
            R"("f" : "0.050799999999999998 \"1.5000000000000000\" x", "g" : 1e+300})");
  // The written summary: the disc diameter as configured.
  MillResult result;
  result.plan = plan_mill(parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", {}));
  result.power_kw = 0.1 + 0.2;  // 0.30000000000000004: shortest is not rounding
  const std::string json = summary_json(result);
  EXPECT_NE(json.find("\"diameter_m\" : 0.0508,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"power_kw\" : 0.30000000000000004,"), std::string::npos) << json;
  // (That every number reads back to its value: SummaryJsonHoldsEveryScalarWithItsValue...)
}

}  // namespace
}  // namespace millsim
