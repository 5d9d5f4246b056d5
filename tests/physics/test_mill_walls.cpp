// The turning mill as a wall: the drive torque and the work it does (World<2>::shell_torque and
// energy_account().shell_work), the exact geometry of disc–lifter contacts, and a mill run that
// repeats bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "millsim/builtin_example.hpp"
#include "millsim/core/constants.hpp"
#include "millsim/geometry/walls.hpp"
#include "millsim/io/config.hpp"
#include "millsim/measure/spectrum.hpp"
#include "millsim/sim/charge.hpp"
#include "millsim/sim/world.hpp"
#include "support/lifter_distance.hpp"

namespace millsim {
namespace {

using testing::distance_to_lifter;

// The lab mill's shell and balls: R = 0.45 m, a 5.08 cm steel ball, m = ρ π d³/6
// = 7800 × 0.52359878 × 1.31096512e-4 = 0.53540739 kg, weight m g = 5.2523465 N; the paper's steel
// contact, μ = 0.5.
constexpr double shell_radius = 0.45;
constexpr double ball_radius = 0.0254;
constexpr double ball_mass = 7800.0 * pi / 6.0 * 0.0508 * 0.0508 * 0.0508;
constexpr double time_step = 1e-4;  // s; t_c of ball on wall is 3.7e-3 s (test_mill_plan.cpp)
const ContactMaterial steel{4.0e5, 3.0e5, 0.6, 0.5};

/// A smooth shell (no lifters) turning at `angular_speed`, empty.
World<2> smooth_shell(double angular_speed, const Vec2& gravity) {
  WorldSettings<2> settings;
  settings.time_step = time_step;
  settings.gravity = gravity;
  settings.ball_ball = steel;
  settings.ball_wall = steel;
  Walls<2> walls;
  Mill2D mill;
  mill.radius = shell_radius;
  mill.angular_speed = angular_speed;
  walls.mill = mill;
  return World<2>(settings, walls);
}

/// Steps `world` and checks, every step, that the drive's power times the step is the work
/// the shell did in it: T ω Δt = Σ F·(ω × p) Δt, since F·(ω ẑ × p) = ω ẑ·(p × F). Both sides
/// come from the same forces, so they agree to round-off.
void step_checking_torque_power(World<2>& world, long steps) {
  const double omega = world.walls().mill->angular_speed;
  for (long n = 0; n < steps; ++n) {
    const double before = world.energy_account().shell_work;
    world.step();
    const double work = world.energy_account().shell_work - before;
    const double power_times_step = world.shell_torque() * omega * time_step;
    // Round-off: a few ulps of the terms, and of shell_work, to which the step's work is added.
    const double round_off =
        1e-12 * (std::abs(power_times_step) + std::abs(world.energy_account().shell_work));
    EXPECT_NEAR(power_times_step, work, round_off) << "step " << n;
    if (std::abs(power_times_step - work) > round_off) return;  // one message is enough
  }
}

TEST(MillWall, DraggingADiscAtRestDoesPositiveWorkAtTheFrictionLimit) {
  // A disc resting at the bottom of the shell with the overlap that carries its weight,
  // δ = m g / k_n = 0.53540739 × 9.81 / 4e5 = 1.3130866e-5 m, at rest, no spin. The shell starts
  // turning counter-clockwise at ω = 2.4 rad/s (the lab mill's speed): its surface at the
  // bottom, p = (0, −R), moves at ω × p = (ω R, 0) = (1.08 m/s, 0).
  const double omega = 2.4;
  World<2> world = smooth_shell(omega, Vec2{{0.0, -standard_gravity}});
  const double overlap = ball_mass * standard_gravity / steel.normal_stiffness;
  world.particles().add(Vec2{{0.0, -(shell_radius - ball_radius + overlap)}}, ball_radius,
                        ball_mass);

  // First step: the disc is at rest, so the normal force is the spring's, k_n δ = m g. The
  // sliding speed is ω R = 1.08 m/s; the tangential dashpot alone would give
  // c_s ω R = 2 ζ sqrt(k_s m) ω R = 2 × 0.16049305 × sqrt(3e5 × 0.53540739) × 1.08
  // = 0.3209861 × 400.777 × 1.08 = 139 N, far above μ m g = 2.6261733 N: the disc slips and
  // the shell pulls it along +x with exactly μ m g. Drive torque p × F = R μ m g
  // = 0.45 × 2.6261733 = 1.1817780 N m (positive: with the turning), work in the step
  // T ω Δt = 1.1817780 × 2.4 × 1e-4 = 2.8362671e-4 J.
  world.step();
  EXPECT_NEAR(world.shell_torque(), 1.1817780, 1e-7);
  EXPECT_NEAR(world.energy_account().shell_work, 2.8362671e-4, 1e-11);
  EXPECT_GT(world.particles().velocity[0][0], 0.0) << "dragged along the shell's motion";

  // Then the disc is carried up the rising side (0.1 s on: x > 0) and rocks about the bottom
  // like a pendulum. The shell's total work stays positive (it equals the disc's kinetic and
  // potential energy plus what friction and the dashpots dissipated, all of which start at
  // zero), and every step's work is T ω Δt.
  step_checking_torque_power(world, 1000);
  EXPECT_GT(world.particles().position[0][0], 0.0) << "carried up the rising (+x) side";
  EXPECT_GT(world.energy_account().shell_work, 0.0);
  step_checking_torque_power(world, 9000);
  EXPECT_GT(world.energy_account().shell_work, 0.0);
}

TEST(MillWall, ShellDragsAnOrbitingDiscUpToRollingAndDoesTwoThirdsOfMV0Squared) {
  // Gravity off. A disc runs round inside the shell, held against it by its own centripetal
  // force: at ρ = R − r + δ with δ = 1e-4 m (ρ = 0.4247 m), m V0²/ρ = k_n δ gives
  // m V0² = k_n δ ρ = 4e5 × 1e-4 × 0.4247 = 16.988 J, V0 = sqrt(16.988 / 0.53540739)
  // = 5.6328598 m/s, no spin. The shell's surface moves twice as fast, ω R = 2 V0.
  const double overlap = 1e-4;
  const double rho = shell_radius - ball_radius + overlap;
  const double speed = std::sqrt(steel.normal_stiffness * overlap * rho / ball_mass);
  const double omega = 2.0 * speed / shell_radius;
  World<2> world = smooth_shell(omega, Vec2{});
  world.particles().add(Vec2{{rho, 0.0}}, ball_radius, ball_mass, Vec2{{0.0, speed}});

  // First step: the disc does not move radially, so F_n = k_n δ = 40 N; the slip 2V0 − V0
  // = 5.6 m/s makes a trial spring k_s × 5.6 × Δt = 169 N, above μ F_n = 20 N, so friction is
  // 20 N forward and the drive torque is R μ F_n = 0.45 × 20 = 9 N m.
  world.step();
  EXPECT_NEAR(world.shell_torque(), 9.0, 1e-9);

  // Friction F (forward, at the contact) changes the disc's speed by m dV = F dt and its spin by
  // I dω_d = r F dt, with I = m r²/2: after an impulse J, V = V0 + J/m, ω_d = 2 J/(m r). It
  // slips until its contact point moves with the shell, V + ω_d r = ω R = 2 V0:
  // V0 + 3 J/m = 2 V0, so J = m V0/3, V = 4 V0/3 = 7.5104797 m/s, ω_d = 2 V0/(3 r)
  // = 147.84409 rad/s. The drive's work is ω R J = 2 V0 × m V0/3 = (2/3) m V0² = 11.325333 J; the
  // kinetic energy grows from m V0²/2 to m V0² (16/9 + 2/9)/2 = m V0², by 8.494 J, and friction
  // dissipates the rest, m V0²/6 = 2.8313333 J.
  // These take ρ fixed; in fact δ grows with the centripetal force to (16/9) δ = 1.78e-4 m,
  // moving ρ by 7.8e-5 m (0.02 %): the checks allow 0.1 %.
  step_checking_torque_power(world, 19999);  // 2 s, much longer than the slip (0.2 s)
  const auto& p = world.particles();
  const Vec2 x = p.position[0];
  const double along = cross(x, p.velocity[0]) / norm(x);  // tangential speed
  EXPECT_NEAR(along, 7.5104797, 1e-3 * 7.5104797);
  EXPECT_NEAR(p.angular_velocity[0], 147.84409, 1e-3 * 147.84409);
  EXPECT_NEAR(world.energy_account().shell_work, 11.325333, 1e-3 * 11.325333);
  // Dissipation: the energy account closes to its discretisation error, which the whole-mill
  // test (test_mill.cpp) allows to be 1 %.
  EXPECT_NEAR(world.energy_account().dissipated, 2.8313333, 0.01 * 2.8313333);
  // Now it rolls with the shell: no slip, no friction, no drive torque (round-off of 9 N m).
  // The slip is read from the half-step velocity, whose direction lags the position's tangent
  // by Ω Δt/2 = (7.51 / 0.4248) × 5e-5 = 8.8e-4 rad: its tangential part is short by
  // V (8.8e-4)²/2 = 3e-6 m/s at most, hence 1e-5 m/s.
  EXPECT_NEAR(along + p.angular_velocity[0] * ball_radius, omega * shell_radius, 1e-5);
  EXPECT_NEAR(world.shell_torque(), 0.0, 1e-9);
}

// ---- Lifter contact geometry --------------------------------------------------------------

// The lab mill's lifters: eight, 4 cm high and 4 cm wide. In the frame of lifter k (radial
// unit a_k at angle θ_k = angle + 2πk/8, tangential unit b_k = ẑ × a_k) its inner face is at
// a = R − h = 0.41 m and its sides at b = ±w/2 = ±0.02 m.
constexpr double lifter_height = 0.04;
constexpr double lifter_width = 0.04;
constexpr double inner_face = shell_radius - lifter_height;  // 0.41 m

Mill2D lab_mill_walls(double angle, double angular_speed) {
  Mill2D mill;
  mill.radius = shell_radius;
  mill.lifter_count = 8;
  mill.lifter_height = lifter_height;
  mill.lifter_width = lifter_width;
  mill.angular_speed = angular_speed;
  mill.turn_to(angle);
  return mill;
}

struct LifterFrame {
  Vec2 radial;
  Vec2 tangential;
  Vec2 at(double a, double b) const { return a * radial + b * tangential; }
};

LifterFrame frame_of(double angle, int lifter) {
  const double theta = angle + 2.0 * pi * lifter / 8.0;
  return {Vec2{{std::cos(theta), std::sin(theta)}}, Vec2{{-std::sin(theta), std::cos(theta)}}};
}

void expect_vec_near(const Vec2& actual, const Vec2& expected, double tolerance,
                     const std::string& what) {
  EXPECT_NEAR(actual[0], expected[0], tolerance) << what;
  EXPECT_NEAR(actual[1], expected[1], tolerance) << what;
}

// Shell orientations: zero, a little, across the ±π cut of atan2, negative, beyond 2π.
constexpr double test_angles[] = {0.0, 0.3, 3.0, -2.0, 10.0};
constexpr double depth = 1e-3;  // overlap of each test disc, m
constexpr double geometry_tolerance = 1e-12;

TEST(MillWall, DiscOnALifterInnerFaceTouchesItAlongTheRadius) {
  // A 5.08 cm disc centred on lifter k's axis at a = 0.41 − r + δ = 0.3856 m, b = 0: the face
  // is the closest feature, overlap δ = 1e-3 m, normal −a_k (into the disc, towards the axis),
  // contact point (R − h) a_k. The disc is 0.3856 + 0.0254 = 0.411 m from the axis, clear of
  // the shell, and 0.3856 m along a_k: its nearest point of each neighbouring lifter is
  // ≥ 0.3856 sin 45° − 0.02 − 0.0254 = 0.227 m away, so this is the only contact.
  for (const double angle : test_angles) {
    const Mill2D mill = lab_mill_walls(angle, 2.0);
    for (int k = 0; k < 8; ++k) {
      const LifterFrame f = frame_of(angle, k);
      const Vec2 centre = f.at(inner_face - ball_radius + depth, 0.0);
      WallContact<2> found[4];
      ASSERT_EQ(mill_contacts(mill, centre, ball_radius, found), 1)
          << "angle " << angle << " lifter " << k;
      const WallContact<2>& c = found[0];
      const std::string what = "angle " + std::to_string(angle) + " lifter " + std::to_string(k);
      EXPECT_EQ(c.wall_id, 1 + k) << what;
      EXPECT_EQ(c.kind, WallKind::lifter) << what;
      EXPECT_NEAR(c.overlap, depth, geometry_tolerance) << what;
      expect_vec_near(c.normal, -f.radial, geometry_tolerance, what);
      const Vec2 point = f.at(inner_face, 0.0);
      expect_vec_near(c.point, point, geometry_tolerance, what);
      // The wall moves with the shell: ω ẑ × p = 2 (−p_y, p_x).
      expect_vec_near(c.wall_velocity, Vec2{{-2.0 * point[1], 2.0 * point[0]}}, geometry_tolerance,
                      what);
    }
  }
}

TEST(MillWall, DiscAtALifterCornerTouchesTheCorner) {
  // The corner of lifter k's inner face and its leading side is (a, b) = (0.41, 0.02). A disc
  // whose centre lies from it along u = (−0.6, 0.8) (in the lifter frame; |u| = 1), at
  // r − δ = 0.0244 m, touches the corner only: centre (0.41 − 0.01464, 0.02 + 0.01952)
  // = (0.39536, 0.03952), beyond the face (a < 0.41) and beside the side (b > 0.02). Overlap
  // δ, normal u, contact point the corner. Distance from the axis sqrt(0.39536² + 0.03952²)
  // = 0.39733 m, + r = 0.42273 m < R: clear of the shell. The same on the trailing side,
  // u = (−0.6, −0.8).
  for (const double angle : test_angles) {
    const Mill2D mill = lab_mill_walls(angle, 0.0);
    for (int k = 0; k < 8; ++k) {
      const LifterFrame f = frame_of(angle, k);
      for (const double side : {1.0, -1.0}) {
        const Vec2 corner = f.at(inner_face, side * 0.5 * lifter_width);
        const Vec2 u = f.at(-0.6, side * 0.8);
        const Vec2 centre = corner + (ball_radius - depth) * u;
        WallContact<2> found[4];
        const std::string what = "angle " + std::to_string(angle) + " lifter " + std::to_string(k) +
                                 " side " + std::to_string(side);
        ASSERT_EQ(mill_contacts(mill, centre, ball_radius, found), 1) << what;
        const WallContact<2>& c = found[0];
        EXPECT_EQ(c.wall_id, 1 + k) << what;
        EXPECT_EQ(c.kind, WallKind::lifter) << what;
        EXPECT_NEAR(c.overlap, depth, geometry_tolerance) << what;
        expect_vec_near(c.normal, u, geometry_tolerance, what);
        expect_vec_near(c.point, corner, geometry_tolerance, what);
        expect_vec_near(c.wall_velocity, Vec2{}, 0.0, what + " (shell still)");
      }
    }
  }
}

TEST(MillWall, DiscInTheBayBetweenALifterSideAndTheShellTouchesBoth) {
  // Centre half-way up lifter 2's leading side, a = R − h/2 = 0.43 m, at b = w/2 + r − δ
  // = 0.02 + 0.0254 − 0.001 = 0.0444 m: the side face at b = 0.02 is the closest feature,
  // overlap δ, normal +b_k, point (0.43, 0.02). Distance from the axis
  // sqrt(0.43² + 0.0444²) = sqrt(0.1849 + 0.00197136) = sqrt(0.18687136) = 0.43228620 m, so the
  // disc also presses into the shell by 0.43228620 + 0.0254 − 0.45 = 0.0076862 m, along the
  // inward radius through its centre.
  const double angle = 0.3;
  const Mill2D mill = lab_mill_walls(angle, 0.0);
  const LifterFrame f = frame_of(angle, 2);
  const Vec2 centre = f.at(0.43, 0.0444);
  WallContact<2> found[4];
  ASSERT_EQ(mill_contacts(mill, centre, ball_radius, found), 2);
  const auto* shell = std::find_if(
      found, found + 2, [](const WallContact<2>& c) { return c.kind == WallKind::shell; });
  const auto* lifter = std::find_if(
      found, found + 2, [](const WallContact<2>& c) { return c.kind == WallKind::lifter; });
  ASSERT_NE(shell, found + 2);
  ASSERT_NE(lifter, found + 2);
  EXPECT_EQ(shell->wall_id, 0);
  EXPECT_NEAR(shell->overlap, 0.0076862, 1e-7);
  expect_vec_near(shell->normal, centre * (-1.0 / norm(centre)), geometry_tolerance, "shell");
  EXPECT_EQ(lifter->wall_id, 3);
  EXPECT_NEAR(lifter->overlap, depth, geometry_tolerance);
  expect_vec_near(lifter->normal, f.tangential, geometry_tolerance, "side face");
  expect_vec_near(lifter->point, f.at(0.43, 0.02), geometry_tolerance, "side face");
}

TEST(MillWall, DiscJustClearOfALifterHasNoContact) {
  // 1 µm off the inner face, and 1 µm off the corner along u: no contact.
  const double angle = 0.3;
  const Mill2D mill = lab_mill_walls(angle, 0.0);
  const LifterFrame f = frame_of(angle, 5);
  WallContact<2> found[4];
  EXPECT_EQ(mill_contacts(mill, f.at(inner_face - ball_radius - 1e-6, 0.0), ball_radius, found), 0);
  const Vec2 corner = f.at(inner_face, 0.5 * lifter_width);
  EXPECT_EQ(
      mill_contacts(mill, corner + (ball_radius + 1e-6) * f.at(-0.6, 0.8), ball_radius, found), 0);
}

/// Discs of `diameter` in `mill`, half of them centred half-way between two lifters (where the
/// farthest lifters the search leaves out are nearest), the rest anywhere inside: how many
/// overlap a lifter that is not among their contacts, and how many lifter overlaps there were.
std::pair<long, long> lifter_contacts_missed(const Mill2D& mill, double diameter,
                                             std::mt19937_64& random) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double r = 0.5 * diameter;
  const double spacing = 2.0 * pi / mill.lifter_count;
  long missed = 0;
  long touching = 0;
  for (int trial = 0; trial < 100000; ++trial) {
    const double phi =
        trial % 2 == 0 ? mill.angle + spacing * (std::floor(mill.lifter_count * unit(random)) + 0.5)
                       : 2.0 * pi * unit(random);
    const double rho =
        (mill.radius - r) * (trial % 2 == 0 ? unit(random) : std::sqrt(unit(random)));
    const Vec2 centre{{rho * std::cos(phi), rho * std::sin(phi)}};
    WallContact<2> found[8];
    const int n = mill_contacts(mill, centre, r, found);
    for (int k = 0; k < mill.lifter_count; ++k) {
      if (distance_to_lifter(mill, k, centre) >= r) continue;
      ++touching;
      const bool listed = std::any_of(found, found + n, [&](const WallContact<2>& contact) {
        return contact.wall_id == 1 + k;
      });
      missed += listed ? 0 : 1;
    }
  }
  return {missed, touching};
}

TEST(MillWall, EveryLifterADiscTouchesIsFoundUpToTheWidestParticleForTheLifters) {
  // The contact search tests the lifter nearest a disc and its two neighbours; plan_mill refuses
  // a mill whose largest ball is wider than widest_particle_for_lifters. Discs of that width
  // overlap no lifter beyond the three, in mills of few tall lifters (near the axis they
  // converge: the limit is then 2 (R − h)) and of many small ones; discs 2 % wider do, so the
  // limit is the search's, not merely a safe one. (In each mill the centre closest to the
  // lifter left out, on the ray 3π/n off its middle, is one a disc of that size can reach
  // inside the shell; where it is not, the limit is safe but not tight.)
  struct Case {
    int count;
    double height, width, widest;
  };
  std::mt19937_64 random(7);
  // Five lifters 0.28 m wide: the ray 3π/5 off lifter k + 2 runs past its inner corner at
  // 0.2335 m, but from the axis it is 0.2 m, R − h, from the lifter's inner face.
  for (const Case c : {Case{4, 0.3, 0.05, 0.4}, Case{5, 0.3, 0.28, 0.4},
                       Case{6, 0.3, 0.1, 0.39999998999999}, Case{30, 0.15, 0.04, 0.1782696},
                       Case{60, 0.1, 0.02, 0.1053937}, Case{200, 0.02, 0.01, 0.0352332}}) {
    Mill2D mill;
    mill.radius = 0.5;
    mill.lifter_count = c.count;
    mill.lifter_height = c.height;
    mill.lifter_width = c.width;
    mill.turn_to(0.3);
    const double widest = widest_particle_for_lifters(mill.radius, c.count, c.height, c.width);
    EXPECT_NEAR(widest, c.widest, 1e-6) << c.count << " lifters";
    const auto [missed, touching] = lifter_contacts_missed(mill, widest, random);
    EXPECT_EQ(missed, 0) << c.count << " lifters: discs of the widest size, " << widest << " m";
    EXPECT_GT(touching, 10000) << c.count << " lifters: too few discs touched one";
    const auto [missed_wider, touching_wider] = lifter_contacts_missed(mill, 1.02 * widest, random);
    EXPECT_GT(missed_wider, 0) << c.count << " lifters: discs 2 % wider, " << touching_wider
                               << " lifter overlaps";
  }
}

TEST(MillWall, LiftersWhoseInnerCornersAlmostMeetMissNoContact) {
  // The config allows lifters up to the width at which neighbours' inner corners meet,
  // 2 (R − h) tan(π/n). Eight lifters 5 cm high in a 1 m mill at 0.999 of it (0.3724 m wide,
  // 0.3 mm apart at the corners), discs of the widest size the lifters allow: the search finds
  // every lifter each one overlaps, the two whose corners nearly meet included; and small discs
  // (2 cm), which can touch both lifters where their corners nearly meet.
  Mill2D mill;
  mill.radius = 0.5;
  mill.lifter_count = 8;
  mill.lifter_height = 0.05;
  mill.lifter_width = 0.999 * 2.0 * (mill.radius - mill.lifter_height) * std::tan(pi / 8.0);
  mill.turn_to(0.3);
  const double widest = widest_particle_for_lifters(mill.radius, 8, 0.05, mill.lifter_width);
  std::mt19937_64 random(11);
  for (const double diameter : {widest, 0.02}) {
    const auto [missed, touching] = lifter_contacts_missed(mill, diameter, random);
    EXPECT_EQ(missed, 0) << "discs " << diameter << " m wide";
    EXPECT_GT(touching, 1000) << "discs " << diameter << " m wide: too few touched a lifter";
  }
}

// ---- Determinism ---------------------------------------------------------------------------

TEST(MillWall, TheExampleMillRunsBitForBitTheSameTwice) {
  // The built-in example (75 discs, eight lifters), short: 1500 steps with the shell still (the
  // charge falls and lands) and 1500 turning at the set speed, 2.4 rad/s; Δt = 1.30e-4 s, so
  // 0.39 s in all.
  const std::vector<std::string> overrides = {
      "simulation.revolutions=1", "simulation.measure_revolutions=1", "simulation.settle_time=0.2",
      "output.snapshot_interval=0"};
  const MillPlan plan =
      plan_mill(parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", overrides));
  const auto run = [&plan] {
    World<2> world = build_mill_world<2>(plan);
    for (int n = 0; n < 1500; ++n) world.step();
    world.walls().mill->angular_speed = plan.angular_speed;
    for (int n = 0; n < 1500; ++n) world.step();
    return world;
  };
  const World<2> a = run();
  const World<2> b = run();
  const auto& pa = a.particles();
  const auto& pb = b.particles();
  ASSERT_EQ(pa.size(), static_cast<std::size_t>(plan.particle_count));
  ASSERT_EQ(pb.size(), pa.size());
  for (std::size_t i = 0; i < pa.size(); ++i) {
    EXPECT_EQ(pa.position[i], pb.position[i]) << "disc " << i;
    EXPECT_EQ(pa.velocity[i], pb.velocity[i]) << "disc " << i;
    EXPECT_EQ(pa.angular_velocity[i], pb.angular_velocity[i]) << "disc " << i;
    EXPECT_EQ(pa.force[i], pb.force[i]) << "disc " << i;
  }
  EXPECT_EQ(a.energy_account().shell_work, b.energy_account().shell_work);
  EXPECT_EQ(a.energy_account().dissipated, b.energy_account().dissipated);
  EXPECT_EQ(a.walls().mill->angle, b.walls().mill->angle);
  // The run did something worth comparing: discs touch, the shell did work.
  EXPECT_GT(a.touching_contacts(), 0u);
  EXPECT_GT(a.energy_account().shell_work, 0.0);
  EXPECT_GT(a.kinetic_energy(), 0.0);
}

TEST(MillWall, ADiscDroppedInAStillShellFirstStrikesItWhereItFalls) {
  // A disc let go at rest at x0 off the axis falls straight down and first touches the shell
  // when its centre is R − r from the axis: at (x0, −sqrt((R − r)² − x0²)). The contact point
  // lies on the same ray, so the collision begins at the angle of that point (ShellImpacts:
  // counterclockwise from +x, for a shell that would turn counterclockwise).
  for (const double x0 : {0.01, 0.2, -0.3}) {  // none at a bin edge (the angle is kept as a float)
    SCOPED_TRACE(x0);
    World<2> world = smooth_shell(0.0, Vec2{{0.0, -standard_gravity}});
    world.particles().add(Vec2{{x0, 0.1}}, ball_radius, ball_mass);
    ShellImpacts impacts(true);
    world.record_impacts_in(&impacts);
    for (long n = 0; n < 20000 && impacts.total_count(ContactType::ball_shell) == 0; ++n) {
      world.step();
    }
    ASSERT_EQ(impacts.total_count(ContactType::ball_shell), 1);
    const double reach = shell_radius - ball_radius;
    const double expected = std::atan2(-std::sqrt(reach * reach - x0 * x0), x0);
    EXPECT_EQ(impacts.count(ContactType::ball_shell, impacts.bin_of(expected)), 1)
        << "expected at " << expected * 180.0 / pi << " degrees";
  }
}

TEST(MillWall, AShellCollisionCutShortByAJumpIsRecordedInTheSpectrumAndTheImpactsAlike) {
  // A disc resting on the bottom of the shell holds a shell contact. Moved to the axis between
  // two steps, it is no longer a wall candidate at the next neighbour-list rebuild, and the
  // collision its slot held ends there: spectrum.csv and impacts.csv must both count it, with
  // the same energy, as they count every other collision.
  World<2> world = smooth_shell(0.0, Vec2{{0.0, -standard_gravity}});
  world.particles().add(Vec2{{0.0, -(shell_radius - ball_radius) - 1e-6}}, ball_radius, ball_mass);
  ImpactSpectrum spectrum;
  ShellImpacts impacts(true);
  world.record_collisions_in(&spectrum);
  world.record_impacts_in(&impacts);
  for (int n = 0; n < 50; ++n) world.step();
  ASSERT_EQ(world.touching_contacts(), 1u);
  ASSERT_EQ(spectrum.total_count(ContactType::ball_shell), 0);
  world.particles().position[0] = Vec2{};
  world.particles().velocity[0] = Vec2{};
  world.step();
  EXPECT_EQ(world.touching_contacts(), 0u);
  EXPECT_EQ(spectrum.total_count(ContactType::ball_shell), 1);
  EXPECT_EQ(impacts.total_count(ContactType::ball_shell), 1);
  EXPECT_GT(spectrum.total_energy(ContactType::ball_shell), 0.0);
  double impact_energy = 0.0;
  for (int bin = 0; bin < ShellImpacts::bins; ++bin) {
    impact_energy += impacts.energy(ContactType::ball_shell, bin);
  }
  EXPECT_EQ(impact_energy, spectrum.total_energy(ContactType::ball_shell));
}

TEST(MillWall, ADiscDroppedOnALifterIsABallLifterCollisionAndBesideItABallShellOne) {
  // The lab mill's lifters, still, lifter 0 pointing straight down (its inner face at
  // y = −0.41 m). A disc let go above it at x = 0 lands on that face; one let go at x = 0.2 m
  // falls to the shell at 62° below the horizontal, 17° from the nearest lifter (at −45°; 0.12 m
  // of arc against the 0.045 m a disc needs to touch its side). Each first impact is recorded in
  // the spectrum as its own contact type, with the energy it lost: less than the fall gave it
  // (from y = 0.1 m to contact: m g 0.4846 and m g 0.4746), more than a tenth of it.
  for (const double x0 : {0.0, 0.2}) {
    SCOPED_TRACE(x0);
    WorldSettings<2> settings;
    settings.time_step = time_step;
    settings.gravity = Vec2{{0.0, -standard_gravity}};
    settings.ball_ball = steel;
    settings.ball_wall = steel;
    Walls<2> walls;
    walls.mill = lab_mill_walls(-0.5 * pi, 0.0);
    World<2> world(settings, walls);
    world.particles().add(Vec2{{x0, 0.1}}, ball_radius, ball_mass);
    ImpactSpectrum spectrum;
    world.record_collisions_in(&spectrum);
    const auto impacts = [&] {
      return spectrum.total_count(ContactType::ball_lifter) +
             spectrum.total_count(ContactType::ball_shell);
    };
    for (long n = 0; n < 20000 && impacts() == 0; ++n) world.step();
    const ContactType hit = x0 == 0.0 ? ContactType::ball_lifter : ContactType::ball_shell;
    const ContactType other = x0 == 0.0 ? ContactType::ball_shell : ContactType::ball_lifter;
    ASSERT_EQ(spectrum.total_count(hit), 1);
    EXPECT_EQ(spectrum.total_count(other), 0);
    const double fall =
        x0 == 0.0 ? 0.1 + inner_face - ball_radius
                  : 0.1 + std::sqrt((shell_radius - ball_radius) * (shell_radius - ball_radius) -
                                    x0 * x0);
    const double energy = spectrum.total_energy(hit);
    EXPECT_GT(energy, 0.1 * ball_mass * standard_gravity * fall);
    EXPECT_LT(energy, ball_mass * standard_gravity * fall);
  }
}

}  // namespace
}  // namespace millsim
