// The distance from a centre to a lifter's bar, worked out in the tests independently of the
// library's closest-feature code, as the answer that code is checked against.
#pragma once

#include <algorithm>
#include <cmath>

#include "millsim/core/constants.hpp"
#include "millsim/geometry/walls.hpp"

namespace millsim::testing {

/// Distance from `centre` to lifter `k`'s bar (radial span R − h … R + h, so reaching past the
/// shell; width w): the centre in the lifter's frame, clamped to the bar.
inline double distance_to_lifter(const Mill2D& mill, int k, const Vec2& centre) {
  const double angle = mill.angle + 2.0 * pi * k / mill.lifter_count;
  const double a = centre[0] * std::cos(angle) + centre[1] * std::sin(angle);
  const double b = -centre[0] * std::sin(angle) + centre[1] * std::cos(angle);
  const double da =
      a - std::clamp(a, mill.radius - mill.lifter_height, mill.radius + mill.lifter_height);
  const double db = b - std::clamp(b, -0.5 * mill.lifter_width, 0.5 * mill.lifter_width);
  return std::sqrt(da * da + db * db);
}

}  // namespace millsim::testing
