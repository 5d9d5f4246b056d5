// The no-tension rule of MODEL.md §3 on one contact: when the total normal force falls to zero
// while the bodies still overlap, the contact breaks and forgets both its springs (the normal
// one restarts at the overlap of the break, the tangential one at zero), and the energy they
// held is booked as dissipated. A contact is driven through the law: two steps of loading build
// both springs, a third pulls the bodies apart fast enough that the dashpot beats the spring
// while they overlap, a fourth pushes them together again. Then one slipping step, worked by
// hand: Coulomb's cap on the total normal force, and the energy the step books.
// 2D and 3D have their own code (evaluate_2d, evaluate_3d) up to the break, which both hand to
// the one conclude(); Lanes run that same code (ContactLanes checks they give each lane the bits
// of one double), so the doubles here pin the break for the lanes too.
#include <gtest/gtest.h>

#include <cmath>

#include "millsim/contact/linear_spring_dashpot.hpp"

namespace millsim {
namespace {

// k_n = 10⁶ N/m, k_s = 8 × 10⁵ N/m, μ = 0.5 (the restitution is not used: the dashpots are
// given), c_n = 40 N s/m, c_s = 1 N s/m, Δt = 10⁻⁵ s.
constexpr double normal_stiffness = 1e6;
constexpr double tangential_stiffness = 8e5;
constexpr double friction = 0.5;
constexpr ContactDamping damping{40.0, 1.0};
constexpr double time_step = 1e-5;
constexpr double speed = 5.0;  // m/s, of approach, separation and sliding alike

/// Unit vector along axis a.
template <int D>
Vec<D> axis(int a) {
  Vec<D> e{};
  e[a] = 1.0;
  return e;
}

/// B moving relative to A at normal_speed along the normal n = x (negative: approaching) and
/// sliding_speed along y, over the last step and at the time of the positions alike; no spin.
template <int D>
ContactInput<D> moving(double overlap, double normal_speed, double sliding_speed) {
  ContactInput<D> in;
  in.normal = axis<D>(0);
  in.overlap = overlap;
  in.velocity = normal_speed * axis<D>(0) + sliding_speed * axis<D>(1);
  in.step_velocity = in.velocity;
  return in;
}

/// The stored tangential spring as a force on B: in 2D the stored length times the tangent
/// t = tangent_of(n) = (0, −1) for n = x.
template <int D>
Vec<D> tangential_spring_force(const ContactHistory<D>& history) {
  if constexpr (D == 2) {
    return history.tangential_spring * tangent_of(axis<2>(0));
  } else {
    return history.tangential_spring;
  }
}

void expect_close(double actual, double expected) {
  EXPECT_NEAR(actual, expected, 1e-12 * std::abs(expected) + 1e-15);
}

template <int D>
void expect_close(const Vec<D>& actual, const Vec<D>& expected) {
  for (int a = 0; a < D; ++a) {
    SCOPED_TRACE(testing::Message() << "component " << a);
    expect_close(actual[a], expected[a]);
  }
}

/// The law of these tests (restitution 0.5, unused: the dashpots are given).
LinearSpringDashpot test_law() {
  return LinearSpringDashpot(
      ContactMaterial{normal_stiffness, tangential_stiffness, 0.5, friction});
}

template <int D>
void check_break_forgets_both_springs() {
  const LinearSpringDashpot law = test_law();
  const Vec<D> n = axis<D>(0);
  const Vec<D> y = axis<D>(1);
  ContactHistory<D> history;

  // Loading, two steps approaching at 5 m/s (overlap 5 × 10⁻⁵ m, then 10⁻⁴ m) while B slides
  // at 5 m/s along y. Each step the tangential spring grows by −k_s v_s Δt = −8e5 × 5 × 1e-5
  // = −40 N along y: −80 N after the second, when the normal spring is k_n δ = 100 N. The
  // contact sticks: the trial force −80 − c_s v_s = −85 N is below μ (100 + c_n × 5) = 150 N.
  // Each sticking step books both dashpots' work (MODEL.md §7), |D_n·v_n| Δt + |D_s·v_s| Δt =
  // c_n v_n² Δt + c_s v_s² Δt = (40 × 25 + 1 × 25) × 10⁻⁵ = 1.025 × 10⁻² J, and no slip work.
  const ContactOutput<D> first =
      law.evaluate(moving<D>(5e-5, -speed, speed), damping, history, time_step);
  expect_close(first.dissipated, 1.025e-2);
  const ContactOutput<D> second =
      law.evaluate(moving<D>(1e-4, -speed, speed), damping, history, time_step);
  expect_close(second.dissipated, 1.025e-2);
  ASSERT_EQ(history.normal_spring_origin, 0.0);
  expect_close(tangential_spring_force(history), -80.0 * y);
  const double dissipated_before = history.dissipated;
  expect_close(dissipated_before, 2.05e-2);

  // Separating at 5 m/s, the overlap back at 5 × 10⁻⁵ m: the normal spring pushes k_n δ = 50 N,
  // the dashpot pulls c_n × 5 = 200 N, so the total −150 N would pull: the contact breaks.
  const double break_overlap = 5e-5;
  const ContactOutput<D> broken =
      law.evaluate(moving<D>(break_overlap, speed, 0.0), damping, history, time_step);
  EXPECT_EQ(broken.force, Vec<D>{});
  EXPECT_EQ(broken.tangential_force, Vec<D>{});
  // Both springs forgotten: the normal one restarts at the overlap of the break, the
  // tangential one at zero.
  EXPECT_EQ(history.normal_spring_origin, break_overlap);
  EXPECT_EQ(history.tangential_spring, SpinOf<D>{});
  // What the springs held is lost, booked at the break (a broken contact does no work, so
  // nothing of the dashpots): the normal spring's F_n²/(2 k_n) = 50² / 2e6 = 1.25 × 10⁻³ J at
  // the overlap of the break, and the tangential one's |F_s|²/(2 k_s) = 80² / 1.6e6 = 4 × 10⁻³ J
  // as it stood (no slip this step): 5.25 × 10⁻³ J in all.
  expect_close(broken.dissipated, 5.25e-3);
  expect_close(history.dissipated - dissipated_before, 5.25e-3);

  // Pushed together again to 10⁻⁴ m at 5 m/s, sliding at 5 m/s: the springs start afresh. The
  // normal spring is k_n (10⁻⁴ − 5 × 10⁻⁵) = 50 N (not 100 N) and the total normal force
  // 50 + c_n × 5 = 250 N; the tangential spring is −40 N along y (not −120 N) and the force
  // −40 − c_s × 5 = −45 N, below μ × 250 = 125 N.
  const ContactOutput<D> again =
      law.evaluate(moving<D>(1e-4, -speed, speed), damping, history, time_step);
  expect_close(again.force, 250.0 * n - 45.0 * y);
  expect_close(tangential_spring_force(history), -40.0 * y);
}

TEST(ContactBreak, PulledApartWhileOverlappingForgetsBothSpringsAndBooksTheirEnergyDiscs) {
  check_break_forgets_both_springs<2>();
}

TEST(ContactBreak, PulledApartWhileOverlappingForgetsBothSpringsAndBooksTheirEnergySpheres) {
  check_break_forgets_both_springs<3>();
}

/// One slipping step worked by hand (MODEL.md §3, "Friction", and docs/model.md): the cap is μ
/// times the total normal force, spring and dashpot, the tangential force points along the
/// trial force, the spring is set to it, and the step books the dashpot's work and the slip's.
template <int D>
void check_slipping_step() {
  const LinearSpringDashpot law = test_law();
  const Vec<D> n = axis<D>(0);
  const Vec<D> y = axis<D>(1);
  ContactHistory<D> history;
  // First step of contact: overlap 5 × 10⁻⁵ m, approaching at 5 m/s, sliding at 100 m/s along y.
  // Normal: spring k_n δ = 50 N, dashpot c_n × 5 = 200 N, total 250 N. Tangential: the spring
  // grows by −k_s v_s Δt = −8e5 × 100 × 1e-5 = −800 N, the trial force −800 − c_s × 100 =
  // −900 N, beyond μ × 250 = 125 N: it slips, at −125 N along y. (Capped at μ times the spring
  // alone it would be 25 N.)
  const double sliding = 100.0;
  const ContactOutput<D> out =
      law.evaluate(moving<D>(5e-5, -speed, sliding), damping, history, time_step);
  expect_close(out.force, 250.0 * n - 125.0 * y);
  expect_close(out.tangential_force, -125.0 * y);
  expect_close(tangential_spring_force(history), -125.0 * y);
  // The normal dashpot's c_n v_n² Δt = 40 × 25 × 1e-5 = 0.01 J; the slip's −F_t·v_s Δt less what
  // the spring took up: 125 × 100 × 1e-5 − 125² / (2 × 8e5) = 0.125 − 0.009765625 J.
  expect_close(out.dissipated, 0.01 + 0.125 - 0.009765625);
  expect_close(history.dissipated, 0.01 + 0.125 - 0.009765625);
}

TEST(ContactSlip, ASlippingStepIsCappedAtMuTimesTheTotalNormalForceDiscs) {
  check_slipping_step<2>();
}

TEST(ContactSlip, ASlippingStepIsCappedAtMuTimesTheTotalNormalForceSpheres) {
  check_slipping_step<3>();
}

// MODEL.md §3: the stored tangential spring is carried round as the contact normal turns,
// keeping its length (R of F_s ← R(F_s) − k_s v_s Δt). In 2D the spring is a signed length
// along the tangent t = (n_y, −n_x) (docs/model.md), so R is the exact rotation with the normal.
// Two sticking steps along n = x build −80 N along y (as in ContactBreak); then the pair turns
// by φ = 30° while still approaching at 5 m/s with no sliding: the normal spring grows to 150 N,
// the total normal force is 150 + c_n × 5 = 350 N, and the spring, below μ × 350 = 175 N, is the
// same 80 N turned with the normal: 80 t = 80 (sin φ, −cos φ).
TEST(ContactSpring2D, TurnsWithTheNormalKeepingItsLength) {
  const LinearSpringDashpot law = test_law();
  ContactHistory<2> history;
  law.evaluate(moving<2>(5e-5, -speed, speed), damping, history, time_step);
  law.evaluate(moving<2>(1e-4, -speed, speed), damping, history, time_step);
  expect_close(tangential_spring_force(history), Vec2{{0.0, -80.0}});
  const double phi = std::acos(-1.0) / 6.0;
  const Vec2 n{{std::cos(phi), std::sin(phi)}};
  ContactInput<2> in;
  in.normal = n;
  in.overlap = 1.5e-4;
  in.velocity = -speed * n;
  in.step_velocity = in.velocity;
  const ContactOutput<2> turned = law.evaluate(in, damping, history, time_step);
  const Vec2 spring{{80.0 * std::sin(phi), -80.0 * std::cos(phi)}};
  expect_close(turned.force, 350.0 * n + spring);
  expect_close(turned.tangential_force, spring);
  EXPECT_NEAR(std::abs(history.tangential_spring), 80.0, 1e-12 * 80.0);
}

}  // namespace
}  // namespace millsim
