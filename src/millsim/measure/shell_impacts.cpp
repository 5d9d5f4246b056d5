#include "millsim/measure/shell_impacts.hpp"

#include <algorithm>
#include <cmath>

namespace millsim {

ShellImpacts::ShellImpacts(bool turns_counterclockwise) : angles_(turns_counterclockwise) {}

std::size_t ShellImpacts::index(ContactType type) {
  const auto found = std::find(types.begin(), types.end(), type);
  return static_cast<std::size_t>(found - types.begin());
}

int ShellImpacts::bin_of(double lab_angle) const {
  return MillAngles::bin_of(angles_.of_lab(lab_angle));
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
