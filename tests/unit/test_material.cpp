// The constants derived from a contact material (material.hpp), each against a value worked
// out by hand in the comment above its check.
#include <gtest/gtest.h>

#include <cmath>

#include "millsim/contact/linear_spring_dashpot.hpp"
#include "millsim/core/constants.hpp"
#include "millsim/core/lanes.hpp"
#include "millsim/particles/material.hpp"

namespace millsim {
namespace {

// Relative tolerance for values worked by hand to 7–8 significant figures.
constexpr double hand_tolerance = 1e-6;

// The paper's 2D steel–steel pair (MODEL.md §8) between two 1 kg discs: m* = 0.5 kg.
ContactMaterial steel(double restitution = 0.6) {
  return ContactMaterial{4.0e5, 3.0e5, restitution, 0.5};
}
constexpr double pair_mass = 0.5;  // m* of two 1 kg discs, kg

TEST(Material, DampingRatioVanishesForAPerfectlyElasticContact) {
  // ζ = −ln e / sqrt(ln²e + π²): ln 1 = 0, so ζ = 0 and every dashpot is off.
  EXPECT_EQ(damping_ratio(1.0), 0.0);
  EXPECT_EQ(normal_damping(steel(1.0), pair_mass), 0.0);
  EXPECT_EQ(tangential_damping(steel(1.0), pair_mass), 0.0);
}

TEST(Material, DampingRatioMatchesCorkumByHand) {
  // e = 0.5: ln e = −0.69314718, ln²e = 0.48045301, ln²e + π² = 0.48045301 + 9.86960440
  // = 10.35005741, its root 3.21715052, so ζ = 0.69314718 / 3.21715052 = 0.21545376.
  EXPECT_NEAR(damping_ratio(0.5), 0.21545376, 0.21545376 * hand_tolerance);
  // e = 0.6: ln e = −0.51082562, ln²e = 0.26094282, sum 10.13054722, root 3.18285834,
  // ζ = 0.51082562 / 3.18285834 = 0.16049305.
  EXPECT_NEAR(damping_ratio(0.6), 0.16049305, 0.16049305 * hand_tolerance);
  // ζ grows from 0 towards 1 (critical damping) as e falls towards 0.
  EXPECT_LT(damping_ratio(0.9), damping_ratio(0.5));
  EXPECT_LT(damping_ratio(0.5), damping_ratio(0.1));
  EXPECT_LT(damping_ratio(1e-12), 1.0);
}

TEST(Material, NormalAndTangentialDampingByHand) {
  // c_n = 2 ζ sqrt(k_n m*) = 2 · 0.16049305 · sqrt(4e5 · 0.5) = 0.32098609 · 447.21360
  // = 143.54934 N s/m.
  EXPECT_NEAR(normal_damping(steel(), pair_mass), 143.54934, 143.54934 * hand_tolerance);
  // c_s: the same relation with k_s: 0.32098609 · sqrt(3e5 · 0.5) = 0.32098609 · 387.29833
  // = 124.31738 N s/m.
  EXPECT_NEAR(tangential_damping(steel(), pair_mass), 124.31738, 124.31738 * hand_tolerance);
  // Against a wall m* is the particle's own mass: c_n scales as sqrt(m*).
  EXPECT_NEAR(normal_damping(steel(), 2.0 * pair_mass),
              std::sqrt(2.0) * normal_damping(steel(), pair_mass), 1e-12);
}

TEST(Material, TheContactLawDampsWithTheseCoefficients) {
  // The law computes its dashpots itself, from ζ and the square roots of the stiffnesses kept
  // at construction: the same c_n = 143.54934 and c_s = 124.31738 N s/m as above, on one
  // contact and on four at once (each lane its own m*: 0.5, 1.0 = 2 × 0.5, 0.125 = 0.5 / 4).
  const LinearSpringDashpot law(steel());
  const ContactDampingOf<double> one = law.damping(pair_mass);
  EXPECT_NEAR(one.normal, 143.54934, 143.54934 * hand_tolerance);
  EXPECT_NEAR(one.tangential, 124.31738, 124.31738 * hand_tolerance);
  const ContactDampingOf<Lanes> four =
      law.damping(Lanes{pair_mass, 2.0 * pair_mass, 0.125, pair_mass});
  const double scale[4] = {1.0, std::sqrt(2.0), 0.5, 1.0};
  for (int lane = 0; lane < 4; ++lane) {
    EXPECT_NEAR(four.normal[lane], scale[lane] * 143.54934, 143.54934 * hand_tolerance) << lane;
    EXPECT_NEAR(four.tangential[lane], scale[lane] * 124.31738, 124.31738 * hand_tolerance) << lane;
  }
  // A perfectly elastic contact has no dashpot at all.
  const ContactDampingOf<double> elastic = LinearSpringDashpot(steel(1.0)).damping(pair_mass);
  EXPECT_EQ(elastic.normal, 0.0);
  EXPECT_EQ(elastic.tangential, 0.0);
}

TEST(Material, ContactDurationByHand) {
  // e = 1 (no damping): t_c = π sqrt(m*/k_n) = π sqrt(0.5 / 4e5) = π · 1.1180340e-3
  // = 3.5124074e-3 s, half a period of the undamped spring.
  EXPECT_NEAR(contact_duration(steel(1.0), pair_mass), 3.5124074e-3, 3.5124074e-3 * hand_tolerance);
  EXPECT_NEAR(contact_duration(steel(1.0 - 1e-9), pair_mass), pi * std::sqrt(pair_mass / 4.0e5),
              1e-9 * 3.5124074e-3);
  // e = 0.6: k_n/m* = 8e5 s⁻², c_n/(2 m*) = 143.54934 s⁻¹ whose square is 20606.41; the root
  // of 8e5 − 20606.41 = 779393.59 is 882.83271 s⁻¹, so t_c = π / 882.83271 = 3.5585368e-3 s.
  EXPECT_NEAR(contact_duration(steel(), pair_mass), 3.5585368e-3, 3.5585368e-3 * hand_tolerance);
}

TEST(Material, CriticalTimeStepByHand) {
  // Two 1 kg discs: m* = 0.5 kg, m_t = 1/6 kg (see TangentialMassByHand). Undamped (e = 1): the
  // normal frequency sqrt(4e5 / 0.5) = 894.42719 s⁻¹, the tangential sqrt(3e5 · 6) =
  // 1341.6408 s⁻¹, the larger, so Δt_crit = 2 / 1341.6408 = 1.4907120e-3 s.
  const double disc_pair_tangential_mass = 1.0 / 6.0;
  EXPECT_NEAR(critical_time_step(steel(1.0), pair_mass, disc_pair_tangential_mass), 1.4907120e-3,
              1.4907120e-3 * hand_tolerance);
  // e = 0.6: ζ = −ln 0.6 / sqrt(ln² 0.6 + π²) = 0.51082562 / 3.1828521 = 0.16049305, and the
  // tangential mode's ζ sqrt(m*/m_t) = ζ √3 = 0.27798211. Each mode's limit is
  // 2 / (ω (sqrt(1 + 4 ζ²) + 2 ζ)): normal 2 / (894.42719 · 1.3712394) = 1.6306911e-3 s,
  // tangential 2 / (1341.6408 · 1.7001216) = 8.7682666e-4 s, the shorter.
  EXPECT_NEAR(critical_time_step(steel(), pair_mass, disc_pair_tangential_mass), 8.7682666e-4,
              8.7682666e-4 * hand_tolerance);
  // With a soft tangential spring (k_s = 1e4: 2 / (sqrt(1e4 · 6) · 1.7001216) = 4.8025774e-3 s)
  // the normal mode sets the step: 1.6306911e-3 s, below the undamped 2 sqrt(m*/k_n) =
  // 2.2360680e-3 s.
  ContactMaterial soft_tangential = steel();
  soft_tangential.tangential_stiffness = 1.0e4;
  EXPECT_NEAR(critical_time_step(soft_tangential, pair_mass, disc_pair_tangential_mass),
              1.6306911e-3, 1.6306911e-3 * hand_tolerance);
  soft_tangential.restitution = 1.0;
  EXPECT_NEAR(critical_time_step(soft_tangential, pair_mass, disc_pair_tangential_mass),
              2.2360680e-3, 2.2360680e-3 * hand_tolerance);
}

TEST(Material, ReducedMassByHand) {
  EXPECT_DOUBLE_EQ(reduced_mass(1.0, 1.0), 0.5);   // 1·1/(1+1)
  EXPECT_DOUBLE_EQ(reduced_mass(1.0, 3.0), 0.75);  // 1·3/(1+3)
  EXPECT_DOUBLE_EQ(reduced_mass(2.0, 2.0), 1.0);   // 2·2/(2+2)
  EXPECT_DOUBLE_EQ(reduced_mass(3.0, 1.0), reduced_mass(1.0, 3.0));
}

TEST(Material, TangentialMassByHand) {
  // 1/m_t = 1/m_a + 1/m_b + r_a²/I_a + r_b²/I_b, and r²/I = 1/(f m) with I = f m r².
  // Two 1 kg discs (f = 1/2): 1/m_t = 1 + 1 + 2 + 2 = 6, m_t = 1/6 kg.
  EXPECT_NEAR(tangential_mass(1.0, 1.0, 0.5), 1.0 / 6.0, 1e-15);
  // A 2 kg disc against a wall (mass_b = 0, infinite): 1/m_t = 1/2 + 2/2 = 3/2, m_t = m/3.
  EXPECT_NEAR(tangential_mass(2.0, 0.0, 0.5), 2.0 / 3.0, 1e-15);
  // A 1 kg sphere (f = 2/5) against a wall: 1/m_t = 1 + 5/2 = 7/2, m_t = 2m/7.
  EXPECT_NEAR(tangential_mass(1.0, 0.0, 0.4), 2.0 / 7.0, 1e-15);
  // Discs of 1 kg and 3 kg: 1/m_t = 3/1 + 3/3 = 4, m_t = 1/4 kg.
  EXPECT_NEAR(tangential_mass(1.0, 3.0, 0.5), 0.25, 1e-15);
}

}  // namespace
}  // namespace millsim
