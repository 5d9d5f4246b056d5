#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

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

TEST(Vec, NearestIntegerHasTheBitsOfNearbyint) {
  // Random values over the range a periodic slab meets and far beyond, exact halves (ties go to
  // even), signed zeros, values about 2^52 and 2^53, and the non-finite.
  std::vector<double> values{0.0,
                             -0.0,
                             0.5,
                             -0.5,
                             1.5,
                             -1.5,
                             2.5,
                             -2.5,
                             0.49999999999999994,
                             -0.3,
                             1e-300,
                             -1e-300,
                             4503599627370495.5,
                             -4503599627370495.5,
                             4503599627370496.0,
                             4503599627370497.0,
                             9007199254740993.0,
                             1e300,
                             std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity()};
  for (int k = -40; k <= 40; ++k) values.push_back(k + 0.5);
  std::mt19937_64 random(7);
  for (const double scale : {1.0, 10.0, 1e6, 1e15, 1e17}) {
    std::uniform_real_distribution<double> uniform(-scale, scale);
    for (int k = 0; k < 10000; ++k) values.push_back(uniform(random));
  }
  for (const double t : values) {
    const double expected = std::nearbyint(t);
    const double got = nearest_integer(t);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(expected), std::bit_cast<std::uint64_t>(got))
        << "t = " << t << ": nearbyint " << expected << ", nearest_integer " << got;
  }
  EXPECT_TRUE(std::isnan(nearest_integer(std::numeric_limits<double>::quiet_NaN())));
}

}  // namespace
}  // namespace millsim
