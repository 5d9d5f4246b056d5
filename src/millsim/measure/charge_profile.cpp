#include "millsim/measure/charge_profile.hpp"

#include <algorithm>
#include <cmath>

namespace millsim {

ChargeProfile::ChargeProfile(double shell_radius, double lifter_height, bool turns_counterclockwise)
    : shell_radius_(shell_radius), lifter_height_(lifter_height), angles_(turns_counterclockwise) {}

double ChargeProfile::angle_of(double x, double y) const {
  return angles_.of_point(x, y);
}

template <int D>
void ChargeProfile::add(const std::vector<Vec<D>>& position, const std::vector<double>& radius) {
  for (std::size_t i = 0; i < position.size(); ++i) {
    const double x = position[i][0];
    const double y = position[i][1];
    const double r = radius[i];
    // Outer edge within h + d/2 of the shell: ρ + r >= R − h − r.
    const double inner = shell_radius_ - lifter_height_ - 2.0 * r;
    if (inner > 0.0 && x * x + y * y < inner * inner) continue;
    const int bin = MillAngles::bin_of(angle_of(x, y));
    ++counts_[static_cast<std::size_t>(bin)];
  }
  ++samples_;
}

double ChargeProfile::mean_count(int bin) const {
  if (samples_ == 0) return 0.0;
  return static_cast<double>(counts_[static_cast<std::size_t>(bin)]) / samples_;
}

std::optional<ToeAndShoulder> ChargeProfile::toe_and_shoulder() const {
  if (samples_ == 0) return std::nullopt;
  const auto count = [&](int k) { return mean_count(((k % bins) + bins) % bins); };
  int fullest = 0;
  for (int k = 1; k < bins; ++k) {
    if (count(k) > count(fullest)) fullest = k;
  }
  const double half = 0.5 * count(fullest);
  if (half <= 0.0) return std::nullopt;
  // Walk from the fullest bin with the turn to the last bin at or above half, then against it.
  int last = fullest;
  while (count(last + 1) >= half) {
    if (++last - fullest >= bins) return std::nullopt;  // all the way round
  }
  int first = fullest;
  while (count(first - 1) >= half) --first;
  const auto centre = [](int k) { return (k + 0.5) * bin_width; };
  // Where the count falls through half, linearly between the centres either side.
  const auto crossing = [&](int inside, int outside) {
    const double fraction = (count(inside) - half) / (count(inside) - count(outside));
    return centre(inside) + fraction * (centre(outside) - centre(inside));
  };
  const auto wrapped = [](double angle, double from) {
    return angle - 2.0 * pi * std::floor((angle - from) / (2.0 * pi));
  };
  return ToeAndShoulder{wrapped(crossing(first, first - 1), 0.0),
                        wrapped(crossing(last, last + 1), -0.5 * pi)};
}

template void ChargeProfile::add<2>(const std::vector<Vec2>&, const std::vector<double>&);
template void ChargeProfile::add<3>(const std::vector<Vec3>&, const std::vector<double>&);

}  // namespace millsim
