// Where wall collisions began (measure/shell_impacts.hpp): the angle convention of the charge
// profile, per wall type, and the types it does not count.
#include <gtest/gtest.h>

#include <cmath>

#include "millsim/core/constants.hpp"
#include "millsim/measure/shell_impacts.hpp"

namespace millsim {
namespace {

constexpr double degree = pi / 180.0;

TEST(ShellImpacts, AnglesRunFromTheRisingSideInTheDirectionOfTheTurn) {
  const ShellImpacts counterclockwise(true);
  EXPECT_EQ(counterclockwise.bin_of(0.5 * degree), 0);
  EXPECT_EQ(counterclockwise.bin_of(-90.0 * degree + 1e-9), ShellImpacts::bins * 3 / 4);  // bottom
  EXPECT_EQ(counterclockwise.bin_of(-0.5 * degree), ShellImpacts::bins - 1);
  // A clockwise shell rises at −x: lab angle 180° is its 0, and the bottom is still 270°.
  const ShellImpacts clockwise(false);
  EXPECT_EQ(clockwise.bin_of(179.5 * degree), 0);
  EXPECT_EQ(clockwise.bin_of(-90.0 * degree - 1e-9), ShellImpacts::bins * 3 / 4);
  EXPECT_EQ(clockwise.bin_of(-170.0 * degree), 70);  // 180 − (−170) = 350°
}

TEST(ShellImpacts, CountsAndEnergiesPerWallTypeAndNothingElse) {
  ShellImpacts impacts(true);
  impacts.record(ContactType::ball_shell, 233.0 * degree, 0.5);
  impacts.record(ContactType::ball_shell, 234.0 * degree, 0.25);  // 230° to 235°: bin 46
  impacts.record(ContactType::ball_lifter, 10.0 * degree, 1.0);
  impacts.record(ContactType::ball_end_plate, 300.0 * degree, 2.0);
  impacts.record(ContactType::ball_ball, 233.0 * degree, 8.0);   // not a wall
  impacts.record(ContactType::ball_plane, 233.0 * degree, 8.0);  // not the mill's
  EXPECT_EQ(impacts.count(ContactType::ball_shell, 46), 2);
  EXPECT_EQ(impacts.energy(ContactType::ball_shell, 46), 0.75);
  EXPECT_EQ(impacts.count(ContactType::ball_lifter, 2), 1);
  EXPECT_EQ(impacts.count(ContactType::ball_end_plate, 60), 1);
  EXPECT_EQ(impacts.total_count(ContactType::ball_shell), 2);
  EXPECT_EQ(impacts.total_count(ContactType::ball_lifter), 1);
  EXPECT_EQ(impacts.total_count(ContactType::ball_end_plate), 1);
  // Asked of a type that is not a wall's: none (it once read past the end of the counts).
  for (const ContactType other : {ContactType::ball_ball, ContactType::ball_plane}) {
    EXPECT_EQ(impacts.total_count(other), 0);
    EXPECT_EQ(impacts.count(other, 46), 0);
    EXPECT_EQ(impacts.energy(other, 46), 0.0);
  }
}

}  // namespace
}  // namespace millsim
