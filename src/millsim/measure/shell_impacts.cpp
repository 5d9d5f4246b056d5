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

long ShellImpacts::count(ContactType type, int bin) const {
  const std::size_t k = index(type);
  return k == types.size() ? 0 : counts_[k][static_cast<std::size_t>(bin)];
}

double ShellImpacts::energy(ContactType type, int bin) const {
  const std::size_t k = index(type);
  return k == types.size() ? 0.0 : energies_[k][static_cast<std::size_t>(bin)];
}

long ShellImpacts::total_count(ContactType type) const {
  const std::size_t k = index(type);
  if (k == types.size()) return 0;  // not a wall type: none recorded
  long total = 0;
  for (const long n : counts_[k]) total += n;
  return total;
}

}  // namespace millsim
