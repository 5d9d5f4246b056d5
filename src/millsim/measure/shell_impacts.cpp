#include "millsim/measure/shell_impacts.hpp"

#include <algorithm>
#include <cmath>

namespace millsim {

ShellImpacts::ShellImpacts(bool turns_counterclockwise)
    : direction_(turns_counterclockwise ? 1.0 : -1.0) {}

std::size_t ShellImpacts::index(ContactType type) {
  const auto found = std::find(types.begin(), types.end(), type);
  return static_cast<std::size_t>(found - types.begin());
}

int ShellImpacts::bin_of(double lab_angle) const {
  // A clockwise shell rises at −x: its angles are the mirror image, π − the lab angle.
  double angle = direction_ > 0.0 ? lab_angle : pi - lab_angle;
  angle -= 2.0 * pi * std::floor(angle / (2.0 * pi));
  return std::clamp(static_cast<int>(angle / bin_width), 0, bins - 1);
}

void ShellImpacts::record(ContactType type, double lab_angle, double energy) {
  const std::size_t k = index(type);
  if (k == types.size()) return;
  const int bin = bin_of(lab_angle);
  ++counts_[k][static_cast<std::size_t>(bin)];
  energies_[k][static_cast<std::size_t>(bin)] += energy;
}

long ShellImpacts::total_count(ContactType type) const {
  long total = 0;
  for (const long n : counts_[index(type)]) total += n;
  return total;
}

}  // namespace millsim
