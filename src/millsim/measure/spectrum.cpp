#include "millsim/measure/spectrum.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace millsim {

std::string_view contact_type_name(ContactType type) {
  switch (type) {
    case ContactType::ball_ball:
      return "ball_ball";
    case ContactType::ball_shell:
      return "ball_shell";
    case ContactType::ball_lifter:
      return "ball_lifter";
    case ContactType::ball_end_plate:
      return "ball_end_plate";
    case ContactType::ball_plane:
      return "ball_plane";
  }
  return "unknown";
}

ImpactSpectrum::ImpactSpectrum(double lowest_energy, int bins_per_decade, int decades)
    : lowest_energy_(lowest_energy), bins_per_decade_(bins_per_decade) {
  if (!(lowest_energy > 0.0) || bins_per_decade <= 0 || decades <= 0) {
    throw std::invalid_argument(
        "ImpactSpectrum: the lowest energy, the bins a decade and the decades must be > 0");
  }
  const std::size_t bins =
      static_cast<std::size_t>(bins_per_decade) * static_cast<std::size_t>(decades);
  for (auto& c : counts_) c.assign(bins, 0);
  for (auto& e : energies_) e.assign(bins, 0.0);
}

void ImpactSpectrum::record(ContactType type, double energy) {
  // (A NaN energy, which only a diverged run could give, goes to the first bin, an infinite
  // one to the last: the bin is found in doubles before it becomes an integer.)
  const double position =
      std::log10((energy > lowest_energy_ ? energy : lowest_energy_) / lowest_energy_);
  const auto last = static_cast<long>(bin_count()) - 1;
  long bin = std::clamp(
      static_cast<long>(std::min(position * bins_per_decade_, static_cast<double>(last))), 0L,
      last);
  // The logarithm can round an energy sitting exactly on an edge to either side: settle it
  // against the edges as reported, so that a bin holds [lower edge, upper edge).
  if (bin < last && energy >= bin_lower_edge(static_cast<std::size_t>(bin + 1))) ++bin;
  if (bin > 0 && energy < bin_lower_edge(static_cast<std::size_t>(bin))) --bin;
  const auto t = static_cast<std::size_t>(type);
  ++counts_[t][static_cast<std::size_t>(bin)];
  energies_[t][static_cast<std::size_t>(bin)] += energy;
}

double ImpactSpectrum::bin_lower_edge(std::size_t bin) const {
  if (bin == 0) return 0.0;
  // From the exponent, so that decade edges of a decimal lowest energy come out exact (1e-7 J,
  // not 1e-10 × 10^3 = 1.0000000000000001e-7 J).
  return std::pow(10.0, std::log10(lowest_energy_) + static_cast<double>(bin) / bins_per_decade_);
}

double ImpactSpectrum::bin_upper_edge(std::size_t bin) const {
  return std::pow(10.0,
                  std::log10(lowest_energy_) + static_cast<double>(bin + 1) / bins_per_decade_);
}

long ImpactSpectrum::total_count(ContactType type) const {
  const auto& c = counts_[static_cast<std::size_t>(type)];
  return std::accumulate(c.begin(), c.end(), 0L);
}

double ImpactSpectrum::total_energy(ContactType type) const {
  const auto& e = energies_[static_cast<std::size_t>(type)];
  return std::accumulate(e.begin(), e.end(), 0.0);
}

}  // namespace millsim
