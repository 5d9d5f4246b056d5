// Where collisions with the mill's walls begin (MODEL.md §7, "shell impact positions"): counts
// and dissipated energy by angle round the mill, per wall type.
#pragma once

#include <array>
#include <vector>

#include "millsim/measure/mill_angle.hpp"
#include "millsim/measure/spectrum.hpp"

namespace millsim {

/// Collisions of balls with the shell, the lifters and (3D) the end plates, each counted in the
/// 5° bin of angle where it began, with the energy it dissipated by its end (recorded when it
/// ends, as the spectrum records it). Angles are those of ChargeProfile and Morrell's C-model:
/// from the horizontal on the side where the shell rises, in the direction it turns; the
/// bottom is at 3π/2. The angle is that of the contact point in the fixed frame at the first
/// step of contact.
class ShellImpacts {
 public:
  static constexpr int bins = MillAngles::bins;
  static constexpr double bin_width = MillAngles::bin_width;  ///< rad
  /// The wall types counted, in the order of the columns of impacts.csv.
  static constexpr std::array<ContactType, 3> types = {
      ContactType::ball_shell, ContactType::ball_lifter, ContactType::ball_end_plate};

  explicit ShellImpacts(bool turns_counterclockwise);

  /// A collision of `type` that began at `lab_angle` (rad, counterclockwise from +x, as
  /// std::atan2(y, x) of the contact point) and dissipated `energy`. Other types are ignored.
  void record(ContactType type, double lab_angle, double energy);

  /// The bin of a lab angle.
  int bin_of(double lab_angle) const;
  /// The count and the energy of `type`'s collisions in a bin, and its count in all; none for
  /// a type that is not a wall's (ball–ball, ball–plane).
  long count(ContactType type, int bin) const;
  double energy(ContactType type, int bin) const;
  long total_count(ContactType type) const;

 private:
  static std::size_t index(ContactType type);
  MillAngles angles_;
  std::array<std::array<long, bins>, types.size()> counts_{};
  std::array<std::array<double, bins>, types.size()> energies_{};
};

}  // namespace millsim
