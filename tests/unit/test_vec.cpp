#include <gtest/gtest.h>

#include "millsim/core/vec.hpp"

namespace millsim {
namespace {

TEST(Vec, ArithmeticAndNorm) {
  const Vec2 a{{3.0, 4.0}};
  EXPECT_DOUBLE_EQ(norm(a), 5.0);
  EXPECT_EQ(a + a, (Vec2{{6.0, 8.0}}));
  EXPECT_EQ(2.0 * a - a, a);
  EXPECT_DOUBLE_EQ(dot(a, Vec2{{1.0, -1.0}}), -1.0);
}

TEST(Vec, PlaneCrossProductsFollowTheRightHandRule) {
  const Vec2 x{{1.0, 0.0}};
  const Vec2 y{{0.0, 1.0}};
  EXPECT_DOUBLE_EQ(cross(x, y), 1.0);             // x × y = +z
  EXPECT_EQ(cross(2.0, x), (Vec2{{0.0, 2.0}}));   // (2 z) × x = 2 y
  EXPECT_EQ(cross(x, 2.0), (Vec2{{0.0, -2.0}}));  // x × (2 z) = −2 y
  const Vec3 x3{{1.0, 0.0, 0.0}};
  const Vec3 y3{{0.0, 1.0, 0.0}};
  EXPECT_EQ(cross(x3, y3), (Vec3{{0.0, 0.0, 1.0}}));
}

}  // namespace
}  // namespace millsim
