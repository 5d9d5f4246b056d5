// The charge profile's toe and shoulder (measure/charge_profile.hpp) on charges laid out by hand:
// the angle convention, the liner layer, the half-peak edges, and the cases without an edge.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "millsim/core/constants.hpp"
#include "millsim/measure/charge_profile.hpp"

namespace millsim {
namespace {

constexpr double shell = 0.45;   // R, m
constexpr double lifter = 0.04;  // h, m
constexpr double ball = 0.025;   // r, m
constexpr double degree = pi / 180.0;

/// A ball whose centre is at distance rho from the axis, at angle theta of the profile's
/// convention for a shell turning counterclockwise (from +x, counterclockwise).
Vec2 at(double rho, double theta) {
  return {{rho * std::cos(theta), rho * std::sin(theta)}};
}

/// One ball a degree, against the shell, from `toe` to `shoulder` (degrees of the convention,
/// through the bottom at 270°), plus a second row further in that is not in the liner layer.
struct Charge {
  std::vector<Vec2> position;
  std::vector<double> radius;
  void arc(double toe, double shoulder, double rho) {
    for (int k = 0; toe + 0.5 + k < shoulder + 360.0; ++k) {
      const double a = toe + 0.5 + k;
      position.push_back(at(rho, a * degree));
      radius.push_back(ball);
    }
  }
};

TEST(ChargeProfile, AnglesRunFromTheRisingSideInTheDirectionOfTheTurn) {
  const ChargeProfile counterclockwise(shell, lifter, true);
  EXPECT_NEAR(counterclockwise.angle_of(1.0, 0.0), 0.0, 1e-15);        // rising side
  EXPECT_NEAR(counterclockwise.angle_of(0.0, -1.0), 1.5 * pi, 1e-15);  // bottom
  EXPECT_NEAR(counterclockwise.angle_of(-1.0, 1e-300), pi, 1e-15);     // falling side
  const ChargeProfile clockwise(shell, lifter, false);
  EXPECT_NEAR(clockwise.angle_of(-1.0, 0.0), 0.0, 1e-15);  // a clockwise shell rises at −x
  EXPECT_NEAR(clockwise.angle_of(0.0, -1.0), 1.5 * pi, 1e-15);
  EXPECT_NEAR(clockwise.angle_of(0.0, 1.0), 0.5 * pi, 1e-15);
}

TEST(ChargeProfile, ToeAndShoulderAreTheEndsOfTheArcAgainstTheShell) {
  // Edges on bin boundaries (multiples of 5°): the half-peak crossing falls on them exactly.
  Charge charge;
  charge.arc(230.0, 40.0, shell - ball);
  charge.arc(250.0, 10.0, shell - lifter - 3.2 * ball);  // inner rows: outside the layer
  ChargeProfile profile(shell, lifter, true);
  profile.add<2>(charge.position, charge.radius);
  const auto ends = profile.toe_and_shoulder();
  ASSERT_TRUE(ends.has_value());
  EXPECT_NEAR(ends->toe, 230.0 * degree, 1e-9);
  EXPECT_NEAR(ends->shoulder, 40.0 * degree, 1e-9);
  EXPECT_NEAR(profile.mean_count(ChargeProfile::bins * 3 / 4), 5.0, 1e-12);  // 270° to 275°
}

TEST(ChargeProfile, BallsOnLifterTopsAreInTheLinerLayerAndTheRowInsideThemIsNot) {
  ChargeProfile profile(shell, lifter, true);
  // Outer edge within h + d/2 of the shell: centre at or beyond R − h − 2r.
  profile.add<2>(
      {at(shell - lifter - 2.0 * ball + 1e-9, 0.0), at(shell - lifter - 2.0 * ball - 1e-6, pi)},
      {ball, ball});
  EXPECT_EQ(profile.mean_count(0), 1.0);
  EXPECT_EQ(profile.mean_count(ChargeProfile::bins / 2), 0.0);
}

TEST(ChargeProfile, EdgesBetweenBinsAreInterpolatedLinearlyBetweenBinCentres) {
  // Balls at 233.5°, 234.5°, …, 386.5° (= 26.5°), one a degree; bins are 5° wide.
  //   Toe side: bin 230–235° holds 2 (233.5°, 234.5°), bin 235–240° holds 5; the fullest
  //   count is 5, so half = 2.5, and the crossing lies from the centre of the inside bin
  //   (237.5°) towards the outside one (232.5°) by the fraction (5 − 2.5)/(5 − 2) = 5/6:
  //   toe = 237.5° − 5/6 × 5° = 237.5° − 25/6° = 233⅓°.
  //   Shoulder side: bin 20–25° holds 5, bin 25–30° holds 2 (25.5°, 26.5°); same fraction:
  //   shoulder = 22.5° + 25/6° = 26⅔°.
  // Rounding to a bin boundary (fraction ½) would give 235° and 25°.
  Charge charge;
  charge.arc(233.0, 27.0, shell - ball);
  // A few balls in flight pass the layer at the toe's impacts: too few to move the toe.
  for (const double a : {200.0, 210.0, 215.0}) {
    charge.position.push_back(at(shell - ball, a * degree));
    charge.radius.push_back(ball);
  }
  ChargeProfile profile(shell, 0.0, true);
  profile.add<2>(charge.position, charge.radius);
  const auto ends = profile.toe_and_shoulder();
  ASSERT_TRUE(ends.has_value());
  EXPECT_NEAR(ends->toe, (237.5 - 25.0 / 6.0) * degree, 1e-9);
  EXPECT_NEAR(ends->shoulder, (22.5 + 25.0 / 6.0) * degree, 1e-9);
}

TEST(ChargeProfile, AShoulderBelowTheHorizontalIsNegative) {
  Charge charge;
  charge.arc(250.0, -20.0, shell - ball);  // a slow mill: shoulder 20° below the horizontal
  ChargeProfile profile(shell, 0.0, true);
  profile.add<2>(charge.position, charge.radius);
  const auto ends = profile.toe_and_shoulder();
  ASSERT_TRUE(ends.has_value());
  EXPECT_NEAR(ends->shoulder, -20.0 * degree, 1e-9);
  EXPECT_NEAR(ends->toe, 250.0 * degree, 1e-9);
}

TEST(ChargeProfile, ACentrifugedChargeOrAnEmptyLayerHasNoToeOrShoulder) {
  ChargeProfile none(shell, lifter, true);
  EXPECT_FALSE(none.toe_and_shoulder().has_value()) << "no sample";
  none.add<2>({at(0.1, 0.0)}, {ball});
  EXPECT_FALSE(none.toe_and_shoulder().has_value()) << "no ball against the shell";

  Charge ring;
  ring.arc(0.0, 0.0, shell - ball);  // all the way round, a ball a degree
  ChargeProfile centrifuged(shell, lifter, true);
  centrifuged.add<2>(ring.position, ring.radius);
  EXPECT_FALSE(centrifuged.toe_and_shoulder().has_value());
}

TEST(ChargeProfile, MeanCountsAreAveragedOverTheSamples) {
  ChargeProfile profile(shell, 0.0, true);
  profile.add<3>({Vec3{{shell - ball, 1e-3, 0.2}}}, {ball});
  profile.add<3>({Vec3{{shell - ball, -1e-3, 0.1}}}, {ball});  // bin 71, just below 2π
  EXPECT_EQ(profile.samples(), 2);
  EXPECT_EQ(profile.mean_count(0), 0.5);
  EXPECT_EQ(profile.mean_count(ChargeProfile::bins - 1), 0.5);
}

}  // namespace
}  // namespace millsim
