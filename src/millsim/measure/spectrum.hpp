// Impact energy spectrum (MODEL.md §7): each collision's dissipated energy, recorded when the
// contact ends, counted in logarithmic bins per contact type.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>
#include <vector>

namespace millsim {

enum class ContactType { ball_ball, ball_shell, ball_lifter, ball_end_plate, ball_plane };
inline constexpr std::size_t contact_type_count = 5;
std::string_view contact_type_name(ContactType type);

class ImpactSpectrum {
 public:
  /// Bins of equal width in log10(energy) from lowest_energy up, `bins_per_decade` per decade,
  /// `decades` decades; bin 0 also takes everything below lowest_energy, the last everything
  /// above the top.
  explicit ImpactSpectrum(double lowest_energy = 1e-10, int bins_per_decade = 5, int decades = 14);

  void record(ContactType type, double energy);

  std::size_t bin_count() const { return counts_[0].size(); }
  double bin_lower_edge(std::size_t bin) const;  ///< J (0 for bin 0)
  double bin_upper_edge(std::size_t bin) const;  ///< J
  long count(ContactType type, std::size_t bin) const {
    return counts_[static_cast<std::size_t>(type)][bin];
  }
  double energy(ContactType type, std::size_t bin) const {
    return energies_[static_cast<std::size_t>(type)][bin];
  }
  long total_count(ContactType type) const;
  double total_energy(ContactType type) const;

 private:
  double lowest_energy_;
  int bins_per_decade_;
  std::array<std::vector<long>, contact_type_count> counts_;
  std::array<std::vector<double>, contact_type_count> energies_;
};

}  // namespace millsim
