// The angles round the mill that the charge profile and the shell impacts are given in, and
// their bins: one convention, Morrell's (docs/model.md, "Measurements").
#pragma once

#include <algorithm>
#include <cmath>

#include "millsim/core/constants.hpp"

namespace millsim {

/// Angles about the mill axis from the horizontal through the axis on the side where the shell
/// rises, in the direction it turns, in [0, 2π); the bottom of the shell is at 3π/2. Cut into
/// 72 bins of 5°.
class MillAngles {
 public:
  static constexpr int bins = 72;
  static constexpr double bin_width = 2.0 * pi / bins;  ///< rad

  /// turns_counterclockwise: the shell's angular velocity points along +z (it rises at +x).
  explicit MillAngles(bool turns_counterclockwise)
      : direction_(turns_counterclockwise ? 1.0 : -1.0) {}

  /// The angle of the point (x, y) of the cross-section.
  double of_point(double x, double y) const { return wrapped(std::atan2(y, direction_ * x)); }
  /// The angle of a lab angle (counterclockwise from +x, as std::atan2(y, x)): the same for a
  /// shell turning counterclockwise, its mirror image π − lab otherwise.
  double of_lab(double lab_angle) const {
    return wrapped(direction_ > 0.0 ? lab_angle : pi - lab_angle);
  }
  /// The bin of an angle in [0, 2π).
  static int bin_of(double angle) {
    return std::clamp(static_cast<int>(angle / bin_width), 0, bins - 1);
  }

 private:
  static double wrapped(double angle) { return angle - 2.0 * pi * std::floor(angle / (2.0 * pi)); }
  double direction_;  ///< +1 counterclockwise, −1 clockwise
};

}  // namespace millsim
