// The impact energy spectrum (measure/spectrum.hpp): logarithmic bins from the lowest energy up,
// each energy in the bin whose edges enclose it, and totals per contact type. Bin numbers are
// worked out by hand from log10 in the comments.
//
// Edge convention: a bin is the half-open range [lower edge, upper edge), so an energy exactly at
// an edge belongs to the bin above it; bin 0 also takes everything below the lowest energy and
// the last bin everything from the top edge up.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "millsim/measure/spectrum.hpp"

namespace millsim {
namespace {

constexpr ContactType all_types[] = {ContactType::ball_ball, ContactType::ball_shell,
                                     ContactType::ball_lifter, ContactType::ball_end_plate,
                                     ContactType::ball_plane};

/// The bin one energy lands in (checks that it lands in exactly one).
std::size_t bin_of(double energy, const ImpactSpectrum& empty = ImpactSpectrum{}) {
  ImpactSpectrum s = empty;
  s.record(ContactType::ball_ball, energy);
  std::size_t found = s.bin_count();
  for (std::size_t k = 0; k < s.bin_count(); ++k) {
    if (s.count(ContactType::ball_ball, k) == 1) {
      EXPECT_EQ(found, s.bin_count()) << "energy " << energy << " counted twice";
      found = k;
    }
  }
  EXPECT_LT(found, s.bin_count()) << "energy " << energy << " not counted";
  return found;
}

TEST(ImpactSpectrum, DefaultBinsAreFiveADecadeFromTenToTheMinusTenJoules) {
  // Defaults: lowest 1e-10 J, 5 bins a decade, 14 decades: 70 bins up to 1e-10 × 10^14 = 1e4 J.
  const ImpactSpectrum s;
  ASSERT_EQ(s.bin_count(), 70u);
  EXPECT_EQ(s.bin_lower_edge(0), 0.0) << "bin 0 reaches down to zero";
  // Edge k = 1e-10 × 10^(k/5): k = 1: 10^0.2 = 1.5848932, so 1.5848932e-10 J; k = 5: 1e-9 J;
  // k = 37: 10^7.4 = 2.5118864e7, so 2.5118864e-3 J; k = 50: 1 J.
  EXPECT_NEAR(s.bin_lower_edge(1), 1.5848932e-10, 1e-7 * 1.5848932e-10);
  EXPECT_NEAR(s.bin_lower_edge(5), 1e-9, 1e-12 * 1e-9);
  EXPECT_NEAR(s.bin_lower_edge(37), 2.5118864e-3, 1e-7 * 2.5118864e-3);
  EXPECT_NEAR(s.bin_lower_edge(50), 1.0, 1e-12);
  EXPECT_NEAR(s.bin_upper_edge(0), 1.5848932e-10, 1e-7 * 1.5848932e-10);
  EXPECT_NEAR(s.bin_upper_edge(69), 1e4, 1e-12 * 1e4);
  // The upper edge of one bin is the lower edge of the next, and every bin is a factor
  // 10^(1/5) = 1.5848932 wide.
  for (std::size_t k = 1; k + 1 < s.bin_count(); ++k) {
    EXPECT_EQ(s.bin_upper_edge(k), s.bin_lower_edge(k + 1)) << "bin " << k;
    EXPECT_NEAR(s.bin_upper_edge(k) / s.bin_lower_edge(k), 1.5848932, 1e-7) << "bin " << k;
  }
}

TEST(ImpactSpectrum, OtherGridsFollowLowestTimesTenToTheKOverBinsPerDecade) {
  // 1e-6 J, 10 a decade, 3 decades: 30 bins; edge k = 1e-6 × 10^(k/10), so edge 10 = 1e-5 J,
  // edge 15 = 1e-6 × 10^1.5 = 3.1622777e-5 J, top = 1e-3 J.
  const ImpactSpectrum s(1e-6, 10, 3);
  ASSERT_EQ(s.bin_count(), 30u);
  EXPECT_NEAR(s.bin_lower_edge(10), 1e-5, 1e-12 * 1e-5);
  EXPECT_NEAR(s.bin_lower_edge(15), 3.1622777e-5, 1e-7 * 3.1622777e-5);
  EXPECT_NEAR(s.bin_upper_edge(29), 1e-3, 1e-12 * 1e-3);
  // Mid-bin energy 1e-6 × 10^((k + 1/2)/10) lands in bin k.
  for (std::size_t k = 0; k < s.bin_count(); ++k) {
    const double middle = 1e-6 * std::pow(10.0, (static_cast<double>(k) + 0.5) / 10.0);
    EXPECT_EQ(bin_of(middle, s), k);
  }
}

TEST(ImpactSpectrum, EnergiesLandInTheBinWhoseEdgesEncloseThem) {
  // bin = floor(5 log10(E / 1e-10)):
  //   2e-10 J: 5 × log10(2) = 5 × 0.30103 = 1.505 -> 1
  //   3e-3 J: 5 × log10(3e7) = 5 × 7.47712 = 37.39 -> 37
  //   0.5 J: 5 × log10(5e9) = 5 × 9.69897 = 48.49 -> 48
  //   7 J: 5 × log10(7e10) = 5 × 10.84510 = 54.23 -> 54
  //   9e3 J: 5 × log10(9e13) = 5 × 13.95424 = 69.77 -> 69
  EXPECT_EQ(bin_of(2e-10), 1u);
  EXPECT_EQ(bin_of(3e-3), 37u);
  EXPECT_EQ(bin_of(0.5), 48u);
  EXPECT_EQ(bin_of(7.0), 54u);
  EXPECT_EQ(bin_of(9e3), 69u);
  // The middle of every bin, 1e-10 × 10^((k + 1/2)/5), is in bin k.
  const ImpactSpectrum s;
  for (std::size_t k = 0; k < s.bin_count(); ++k) {
    const double middle = 1e-10 * std::pow(10.0, (static_cast<double>(k) + 0.5) / 5.0);
    EXPECT_EQ(bin_of(middle), k) << "middle of bin " << k;
    EXPECT_GT(middle, s.bin_lower_edge(k));
    EXPECT_LT(middle, s.bin_upper_edge(k));
  }
}

TEST(ImpactSpectrum, AnEnergyAtAnEdgeGoesToTheBinAbove) {
  // Decade edges are exact decimal numbers: 10^n J is edge 5 (n + 10), e.g. 1e-9 J -> bin 5,
  // 1 J -> bin 50, 1e3 J -> bin 65.
  for (int n = -9; n <= 3; ++n) {
    const double edge = std::pow(10.0, n);
    EXPECT_EQ(bin_of(edge), static_cast<std::size_t>(5 * (n + 10))) << "10^" << n << " J";
  }
  // The same for every edge as the spectrum reports it, with the default grid (the one a mill
  // run records in).
  const ImpactSpectrum s;
  for (std::size_t k = 1; k < s.bin_count(); ++k) {
    EXPECT_EQ(bin_of(s.bin_lower_edge(k)), k) << "lower edge of bin " << k;
  }
}

// Regression: record() once took only floor(bins_per_decade × log10(E / lowest)), which put some
// reported edges in the bin below (lowest 1e-6 J, 5 a decade: bin_lower_edge(3) =
// 3.9810717055349717e-6 J was counted in bin 2).
TEST(ImpactSpectrum, EveryReportedEdgeGoesToTheBinAboveOnAnyGrid) {
  for (const double lowest : {1e-10, 1e-6, 1.0}) {
    for (const int per_decade : {4, 5, 10}) {
      const ImpactSpectrum s(lowest, per_decade, 6);
      for (std::size_t k = 1; k < s.bin_count(); ++k) {
        EXPECT_EQ(bin_of(s.bin_lower_edge(k), s), k)
            << "lowest " << lowest << ", " << per_decade << " a decade, edge " << k;
      }
    }
  }
}

TEST(ImpactSpectrum, OutOfRangeEnergiesLandInTheEndBinsWithTheirOwnEnergy) {
  ImpactSpectrum s;
  // Below 1e-10 J (also zero): bin 0. At or above the top, 1e4 J: the last bin, 69.
  for (const double low : {0.0, 1e-30, 1e-12, 0.99e-10}) s.record(ContactType::ball_shell, low);
  for (const double high : {1e4, 1e5, 1e9}) s.record(ContactType::ball_shell, high);
  EXPECT_EQ(s.count(ContactType::ball_shell, 0), 4);
  EXPECT_EQ(s.count(ContactType::ball_shell, 69), 3);
  EXPECT_EQ(s.total_count(ContactType::ball_shell), 7);
  // The energy kept is the energy recorded, not the bin's edge.
  EXPECT_DOUBLE_EQ(s.energy(ContactType::ball_shell, 0), 0.0 + 1e-30 + 1e-12 + 0.99e-10);
  EXPECT_DOUBLE_EQ(s.energy(ContactType::ball_shell, 69), 1e4 + 1e5 + 1e9);
}

TEST(ImpactSpectrum, AnEnergyThatIsNotANumberOrInfiniteStillLandsInAnEndBin) {
  // Only a diverged run could record one; its bin was an integer cast of a NaN or an infinity
  // (undefined). The energy is kept as recorded, so the bin shows what happened.
  ImpactSpectrum s;
  s.record(ContactType::ball_ball, std::nan(""));
  s.record(ContactType::ball_ball, HUGE_VAL);
  EXPECT_EQ(s.count(ContactType::ball_ball, 0), 1);
  EXPECT_TRUE(std::isnan(s.energy(ContactType::ball_ball, 0)));
  EXPECT_EQ(s.count(ContactType::ball_ball, 69), 1);
  EXPECT_EQ(s.energy(ContactType::ball_ball, 69), HUGE_VAL);
}

TEST(ImpactSpectrum, RefusesAGridWithoutBins) {
  EXPECT_THROW(ImpactSpectrum(1e-10, 0, 14), std::invalid_argument);
  EXPECT_THROW(ImpactSpectrum(1e-10, 5, 0), std::invalid_argument);
  EXPECT_THROW(ImpactSpectrum(0.0, 5, 14), std::invalid_argument);
}

TEST(ImpactSpectrum, TotalsAreKeptPerContactType) {
  ImpactSpectrum s;
  // ball_ball: 2e-10 (bin 1), 3e-3 and 3.5e-3 (both bin 37: 5 log10(3.5e7) = 37.72), 0.5 (48).
  for (const double e : {2e-10, 3e-3, 3.5e-3, 0.5}) s.record(ContactType::ball_ball, e);
  // ball_lifter: 7 J twice (bin 54).
  s.record(ContactType::ball_lifter, 7.0);
  s.record(ContactType::ball_lifter, 7.0);
  // ball_plane: one below the range.
  s.record(ContactType::ball_plane, 1e-12);

  EXPECT_EQ(s.total_count(ContactType::ball_ball), 4);
  EXPECT_DOUBLE_EQ(s.total_energy(ContactType::ball_ball), 2e-10 + 3e-3 + 3.5e-3 + 0.5);
  EXPECT_EQ(s.count(ContactType::ball_ball, 1), 1);
  EXPECT_EQ(s.count(ContactType::ball_ball, 37), 2);
  EXPECT_DOUBLE_EQ(s.energy(ContactType::ball_ball, 37), 6.5e-3);
  EXPECT_EQ(s.count(ContactType::ball_ball, 48), 1);
  EXPECT_EQ(s.total_count(ContactType::ball_lifter), 2);
  EXPECT_EQ(s.count(ContactType::ball_lifter, 54), 2);
  EXPECT_DOUBLE_EQ(s.total_energy(ContactType::ball_lifter), 14.0);
  EXPECT_EQ(s.total_count(ContactType::ball_plane), 1);
  EXPECT_DOUBLE_EQ(s.total_energy(ContactType::ball_plane), 1e-12);
  EXPECT_EQ(s.total_count(ContactType::ball_shell), 0);
  EXPECT_EQ(s.total_energy(ContactType::ball_shell), 0.0);
  // One type's records do not show in another's bins.
  EXPECT_EQ(s.count(ContactType::ball_lifter, 37), 0);
  EXPECT_EQ(s.count(ContactType::ball_ball, 54), 0);
}

TEST(ImpactSpectrum, ContactTypesHaveTheirColumnNames) {
  EXPECT_EQ(contact_type_name(ContactType::ball_ball), "ball_ball");
  EXPECT_EQ(contact_type_name(ContactType::ball_shell), "ball_shell");
  EXPECT_EQ(contact_type_name(ContactType::ball_lifter), "ball_lifter");
  EXPECT_EQ(contact_type_name(ContactType::ball_end_plate), "ball_end_plate");
  EXPECT_EQ(contact_type_name(ContactType::ball_plane), "ball_plane");
  // One name per type, and contact_type_count covers them all.
  EXPECT_EQ(std::size(all_types), contact_type_count);
  std::vector<std::string_view> names;
  for (const ContactType t : all_types) names.push_back(contact_type_name(t));
  for (std::size_t a = 0; a < names.size(); ++a) {
    for (std::size_t b = a + 1; b < names.size(); ++b) EXPECT_NE(names[a], names[b]);
  }
}

}  // namespace
}  // namespace millsim
