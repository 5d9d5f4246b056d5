// Toe and shoulder of the charge (MODEL.md §7): the arc over which the charge lies against the
// shell, from the time-mean number of balls in the liner layer at each angle.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "millsim/core/vec.hpp"
#include "millsim/measure/mill_angle.hpp"

namespace millsim {

/// Toe and shoulder angles, rad, measured as Morrell's C-model measures them (and
/// `empirical.morrell` reports them: docs/empirical_power.md): from the horizontal through the
/// axis on the side where the shell rises, in the direction the shell turns. The bottom of the
/// shell is at 3π/2. A tumbling charge's toe lies between π/2 and 3π/2, and its shoulder past
/// the bottom, given in [−π/2, 3π/2) (a shoulder above the horizontal is between 0 and π/2).
struct ToeAndShoulder {
  double toe = 0.0;
  double shoulder = 0.0;
};

/// Counts, sample after sample, the balls of the liner layer by angle, and finds the charge's toe
/// and shoulder in the mean counts (our choice of definition, docs/model.md "Charge profile"):
/// - a ball is in the liner layer when its outer edge is within h + d/2 of the shell, h the
///   lifter height (0 for a smooth shell) and d the ball's diameter: the balls touching the
///   shell, between the lifters or on their tops;
/// - the angles are cut into bins of 5°, and each sample adds each liner-layer ball to its bin;
/// - the charge lies against the shell over the arc round the fullest bin where the mean count
///   is at least half of that bin's; its ends, interpolated linearly between bin centres, are the
///   toe (against the turn) and the shoulder (with it). Balls in flight, which pass the liner
///   layer only at the toe's impacts, add too little to move them.
class ChargeProfile {
 public:
  static constexpr int bins = MillAngles::bins;
  static constexpr double bin_width = MillAngles::bin_width;  ///< rad

  /// shell_radius R, m (the cylinder's); lifter_height h, m (0 without lifters);
  /// turns_counterclockwise: the shell's angular velocity points along +z.
  ChargeProfile(double shell_radius, double lifter_height, bool turns_counterclockwise);

  /// Adds one sample: every ball of the liner layer counted in its bin. Only x and y are read.
  template <int D>
  void add(const std::vector<Vec<D>>& position, const std::vector<double>& radius);

  int samples() const { return samples_; }
  /// The angle, in [0, 2π), of a point (x, y) of the cross-section.
  double angle_of(double x, double y) const;
  /// Mean number of liner-layer balls in bin k, [k, k + 1) bin widths from angle 0.
  double mean_count(int bin) const;
  /// Toe and shoulder of the mean counts; none before a sample, when no ball lay against the
  /// shell, or when the occupied arc goes all the way round (a centrifuged charge).
  std::optional<ToeAndShoulder> toe_and_shoulder() const;

 private:
  double shell_radius_;
  double lifter_height_;
  MillAngles angles_;
  int samples_ = 0;
  std::array<long, bins> counts_{};
};

extern template void ChargeProfile::add<2>(const std::vector<Vec2>&, const std::vector<double>&);
extern template void ChargeProfile::add<3>(const std::vector<Vec3>&, const std::vector<double>&);

}  // namespace millsim
