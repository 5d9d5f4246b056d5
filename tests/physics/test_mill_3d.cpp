// The 3D mill (Mill3D, World<3>): exact sphere–wall geometry at the lifters' faces, edges and
// corners and at the end plates, no leaks through them under fast impacts, and whole-mill
// physics in 3D: a charge at rest stays at rest, a mill above critical speed centrifuges its
// charge, a running mill keeps its energy account, its drive torque times ω is the walls' work
// and draws power, a periodic slab scales to the mill's length, and a slab too short for its
// balls is refused.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "millsim/core/constants.hpp"
#include "millsim/core/error.hpp"
#include "millsim/geometry/walls.hpp"
#include "millsim/io/config.hpp"
#include "millsim/sim/charge.hpp"
#include "millsim/sim/mill_run.hpp"
#include "millsim/sim/world.hpp"
#include "support/energy_account.hpp"

namespace millsim {
namespace {

// ---- Geometry: the lab mill of case 3D-g -----------------------------------------------------

// R = 0.45 m, L = 0.15 m, eight lifters 4 cm high and 4 cm wide, a 5.08 cm ball. In the frame of
// lifter k (radial unit a_k at θ_k = angle + 2πk/8, tangential unit b_k = ẑ × a_k, axial ẑ) the
// bar's inner face is at a = R − h = 0.41 m, its sides at b = ±w/2 = ±0.02 m, its ends at z = 0
// and z = L, where the end plates are.
constexpr double shell_radius = 0.45;
constexpr double mill_length = 0.15;
constexpr double lifter_height = 0.04;
constexpr double lifter_width = 0.04;
constexpr double inner_face = shell_radius - lifter_height;  // 0.41 m
constexpr double half_width = 0.5 * lifter_width;            // 0.02 m
constexpr double ball_radius = 0.0254;
constexpr int lifter_count = 8;
constexpr int first_plate = 1 + lifter_count;  // wall id of the plate at z = 0; z = L is next

Mill3D lab_mill_3d(double angle, double angular_speed, bool periodic = false) {
  Mill3D mill;
  mill.radius = shell_radius;
  mill.lifter_count = lifter_count;
  mill.lifter_height = lifter_height;
  mill.lifter_width = lifter_width;
  mill.angular_speed = angular_speed;
  mill.length = mill_length;
  mill.periodic = periodic;
  mill.turn_to(angle);
  return mill;
}

struct LifterFrame {
  Vec3 radial;
  Vec3 tangential;
  Vec3 at(double a, double b, double z) const {
    return a * radial + b * tangential + Vec3{{0.0, 0.0, z}};
  }
};

LifterFrame frame_of(double angle, int lifter) {
  const double theta = angle + 2.0 * pi * lifter / lifter_count;
  return {Vec3{{std::cos(theta), std::sin(theta), 0.0}},
          Vec3{{-std::sin(theta), std::cos(theta), 0.0}}};
}

/// Velocity of a point p turning with the mill: ω ẑ × p = ω (−p_y, p_x, 0).
Vec3 turning_velocity(double angular_speed, const Vec3& p) {
  return Vec3{{-angular_speed * p[1], angular_speed * p[0], 0.0}};
}

constexpr double test_angles[] = {0.0, 0.3, 3.0, -2.0, 10.0};
constexpr double test_angular_speed = 2.0;
constexpr double depth = 1e-3;        // overlap of each test sphere, m
constexpr double plate_depth = 2e-3;  // overlap with an end plate where there is one, m
constexpr double geometry_tolerance = 1e-12;

/// One expected contact: wall, overlap, normal and contact point.
struct Expected {
  int wall_id;
  WallKind kind;
  double overlap;
  Vec3 normal;
  Vec3 point;
};

void expect_vec_near(const Vec3& actual, const Vec3& expected, double tolerance,
                     const std::string& what) {
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(actual[i], expected[i], tolerance) << what << " [" << i << "]";
}

/// Checks that `mill_contacts` finds exactly the `expected` contacts (in any order), each with
/// its overlap, normal, point and the velocity of the point turning with the mill.
void expect_contacts(const Mill3D& mill, const Vec3& centre, const std::vector<Expected>& expected,
                     const std::string& what) {
  WallContact<3> found[max_mill_contacts<3>];
  const int count = mill_contacts(mill, centre, ball_radius, found);
  ASSERT_EQ(count, static_cast<int>(expected.size())) << what;
  for (const Expected& e : expected) {
    const auto* c = std::find_if(found, found + count,
                                 [&](const WallContact<3>& f) { return f.wall_id == e.wall_id; });
    ASSERT_NE(c, found + count) << what << ": no contact with wall " << e.wall_id;
    const std::string with = what + ", wall " + std::to_string(e.wall_id);
    EXPECT_EQ(c->kind, e.kind) << with;
    EXPECT_NEAR(c->overlap, e.overlap, geometry_tolerance) << with;
    expect_vec_near(c->normal, e.normal, geometry_tolerance, with + " normal");
    expect_vec_near(c->point, e.point, geometry_tolerance, with + " point");
    // The centre lies along the normal from the point, at r − δ (the definition of both).
    expect_vec_near(centre, c->point + (ball_radius - c->overlap) * c->normal, geometry_tolerance,
                    with + " centre");
    expect_vec_near(c->wall_velocity, turning_velocity(mill.angular_speed, c->point),
                    geometry_tolerance, with + " wall velocity");
  }
}

std::string label(double angle, int lifter, const char* where) {
  return std::string(where) + " angle " + std::to_string(angle) + " lifter " +
         std::to_string(lifter);
}

TEST(Mill3DWall, SphereOnALifterInnerFaceTouchesItAlongTheRadius) {
  // Centre on lifter k's mid-plane at a = 0.41 − r + δ = 0.3856 m, b = 0, half-way along,
  // z = 0.075 m: the inner face is the closest feature, overlap δ = 1e-3 m, normal −a_k, point
  // (0.41, 0, 0.075) in the lifter frame. The sphere reaches 0.411 m from the axis (clear of
  // the shell) and 0.075 − r = 0.0496 m from each end plate; the neighbouring lifters are
  // ≥ 0.3856 sin 45° − 0.02 − 0.0254 = 0.227 m away.
  for (const double angle : test_angles) {
    const Mill3D mill = lab_mill_3d(angle, test_angular_speed);
    for (int k = 0; k < lifter_count; ++k) {
      const LifterFrame f = frame_of(angle, k);
      const double z = 0.5 * mill_length;
      expect_contacts(mill, f.at(inner_face - ball_radius + depth, 0.0, z),
                      {{1 + k, WallKind::lifter, depth, -f.radial, f.at(inner_face, 0.0, z)}},
                      label(angle, k, "inner face"));
    }
  }
}

TEST(Mill3DWall, SphereBesideALifterTouchesItsSideFace) {
  // Centre at a = 0.415 m (between the inner face, 0.41, and the shell), b = ±(w/2 + r − δ)
  // = ±0.0444 m, z = 0.03 m: the side face at b = ±0.02 is closest, overlap δ, normal ±b_k,
  // point (0.415, ±0.02, 0.03). Distance from the axis sqrt(0.415² + 0.0444²) = 0.417368 m,
  // + r = 0.442768 m < R: clear of the shell; z − r = 0.0046 m: clear of the end plate.
  for (const double angle : test_angles) {
    const Mill3D mill = lab_mill_3d(angle, test_angular_speed);
    for (int k = 0; k < lifter_count; ++k) {
      const LifterFrame f = frame_of(angle, k);
      for (const double side : {1.0, -1.0}) {
        const double b = side * (half_width + ball_radius - depth);
        expect_contacts(mill, f.at(0.415, b, 0.03),
                        {{1 + k, WallKind::lifter, depth, side * f.tangential,
                          f.at(0.415, side * half_width, 0.03)}},
                        label(angle, k, side > 0 ? "leading side" : "trailing side"));
      }
    }
  }
}

TEST(Mill3DWall, SphereAtALifterLongEdgeTouchesTheEdge) {
  // The long edge where the inner face meets a side runs along z at (a, b) = (0.41, ±0.02). A
  // centre from a point of it along u = (−0.6, ±0.8, 0) in the lifter frame (|u| = 1) at
  // r − δ = 0.0244 m, (0.39536, ±0.03952), is beyond the face and beside the side: overlap δ,
  // normal u, point on the edge at the centre's z. Distance from the axis 0.39733 m, + r
  // = 0.42273 m < R; z = 0.12 m is 0.0046 m clear of the plate at L − r = 0.1246 m.
  for (const double angle : test_angles) {
    const Mill3D mill = lab_mill_3d(angle, test_angular_speed);
    for (int k = 0; k < lifter_count; ++k) {
      const LifterFrame f = frame_of(angle, k);
      for (const double side : {1.0, -1.0}) {
        for (const double z : {0.03, 0.075, 0.12}) {
          const Vec3 edge = f.at(inner_face, side * half_width, z);
          const Vec3 u = f.at(-0.6, side * 0.8, 0.0);
          expect_contacts(mill, edge + (ball_radius - depth) * u,
                          {{1 + k, WallKind::lifter, depth, u, edge}},
                          label(angle, k, "long edge"));
        }
      }
    }
  }
}

TEST(Mill3DWall, SphereInTheCornerOfALifterAndAnEndPlateTouchesBoth) {
  // Where a lifter meets an end plate the two faces make a concave edge. A sphere on lifter k's
  // mid-plane at a = 0.41 − r + δ, z = r − δ_p (δ_p = 2e-3 m) presses the inner face by δ
  // (normal −a_k, point (0.41, 0, z)) and the plate at z = 0 by δ_p (normal +ẑ, point the
  // centre's foot on the plate, moving with the plate); the same at z = L − r + δ_p against the
  // other plate (normal −ẑ). Beside the lifter, at a = 0.415, b = w/2 + r − δ, the side face
  // and the plate.
  for (const double angle : test_angles) {
    const Mill3D mill = lab_mill_3d(angle, test_angular_speed);
    for (int k = 0; k < lifter_count; ++k) {
      const LifterFrame f = frame_of(angle, k);
      for (const int end : {0, 1}) {
        const double z =
            end == 0 ? ball_radius - plate_depth : mill_length - ball_radius + plate_depth;
        const double plate_z = end == 0 ? 0.0 : mill_length;
        const Vec3 plate_normal{{0.0, 0.0, end == 0 ? 1.0 : -1.0}};
        const Vec3 on_face = f.at(inner_face - ball_radius + depth, 0.0, z);
        expect_contacts(mill, on_face,
                        {{1 + k, WallKind::lifter, depth, -f.radial, f.at(inner_face, 0.0, z)},
                         {first_plate + end, WallKind::end_plate, plate_depth, plate_normal,
                          Vec3{{on_face[0], on_face[1], plate_z}}}},
                        label(angle, k, "inner face and plate"));
        const Vec3 beside = f.at(0.415, half_width + ball_radius - depth, z);
        expect_contacts(mill, beside,
                        {{1 + k, WallKind::lifter, depth, f.tangential, f.at(0.415, half_width, z)},
                         {first_plate + end, WallKind::end_plate, plate_depth, plate_normal,
                          Vec3{{beside[0], beside[1], plate_z}}}},
                        label(angle, k, "side face and plate"));
      }
    }
  }
}

TEST(Mill3DWall, SpherePressedThroughAnEndPlateTouchesTheLifterEndEdgeAndCorner) {
  // After a violent step a centre may lie beyond an end plate (z < 0). The bar ends at z = 0,
  // so its closest feature is then an end edge or a corner, out of the plane of the centre.
  // End edge of the inner face, (0.41, 0, 0): centre along u = (−0.6, 0, −0.8) at r − δ,
  // z = −0.8 × 0.0244 = −0.01952 m: lifter overlap δ, normal u (with a z part), point on the
  // edge; the plate at z = 0 is pressed by r − z = 0.0254 + 0.01952 = 0.04492 m, normal +ẑ.
  // Corner (0.41, ±0.02, 0): centre along u = (−0.48, ±0.64, −0.6) (|u|² = 0.2304 + 0.4096
  // + 0.36 = 1) at r − δ, z = −0.01464 m, planar distance from the axis 0.39988 m, + r < R:
  // lifter overlap δ, normal u, point the corner; plate overlap 0.0254 + 0.01464 = 0.04004 m.
  // Mirrored beyond the plate at z = L: the z parts of u change sign.
  for (const double angle : test_angles) {
    const Mill3D mill = lab_mill_3d(angle, test_angular_speed);
    for (int k = 0; k < lifter_count; ++k) {
      const LifterFrame f = frame_of(angle, k);
      for (const int end : {0, 1}) {
        const double out = end == 0 ? -1.0 : 1.0;  // the axial direction beyond this end
        const double plate_z = end == 0 ? 0.0 : mill_length;
        const Vec3 plate_normal{{0.0, 0.0, -out}};
        const Vec3 edge = f.at(inner_face, 0.0, plate_z);
        const Vec3 u_edge = f.at(-0.6, 0.0, out * 0.8);
        const Vec3 at_edge = edge + (ball_radius - depth) * u_edge;
        expect_contacts(mill, at_edge,
                        {{1 + k, WallKind::lifter, depth, u_edge, edge},
                         {first_plate + end, WallKind::end_plate, 0.04492, plate_normal,
                          Vec3{{at_edge[0], at_edge[1], plate_z}}}},
                        label(angle, k, "end edge"));
        for (const double side : {1.0, -1.0}) {
          const Vec3 corner = f.at(inner_face, side * half_width, plate_z);
          const Vec3 u_corner = f.at(-0.48, side * 0.64, out * 0.6);
          const Vec3 at_corner = corner + (ball_radius - depth) * u_corner;
          expect_contacts(mill, at_corner,
                          {{1 + k, WallKind::lifter, depth, u_corner, corner},
                           {first_plate + end, WallKind::end_plate, 0.04004, plate_normal,
                            Vec3{{at_corner[0], at_corner[1], plate_z}}}},
                          label(angle, k, "corner"));
        }
      }
    }
  }
}

TEST(Mill3DWall, SphereOnTheShellAndInTheRimTouchesShellAndPlate) {
  // Half-way between lifters k and k + 1, at θ = θ_k + π/8, radial unit e: a centre at
  // (R − r + δ) e, z = 0.075, presses the shell by δ along −e, point R e at the centre's z
  // (the lifters are (R − r) sin(π/8) − w/2 − r = 0.1286 m away). At z = r − δ_p it sits in
  // the rim where the shell meets the plate at z = 0 and presses both; the same at z = L.
  for (const double angle : test_angles) {
    const Mill3D mill = lab_mill_3d(angle, test_angular_speed);
    for (int k = 0; k < lifter_count; ++k) {
      const double theta = angle + 2.0 * pi * (k + 0.5) / lifter_count;
      const Vec3 e{{std::cos(theta), std::sin(theta), 0.0}};
      const auto centre_at = [&](double z) {
        return (shell_radius - ball_radius + depth) * e + Vec3{{0.0, 0.0, z}};
      };
      const auto on_shell = [&](double z) { return shell_radius * e + Vec3{{0.0, 0.0, z}}; };
      const double mid = 0.5 * mill_length;
      expect_contacts(mill, centre_at(mid), {{0, WallKind::shell, depth, -e, on_shell(mid)}},
                      label(angle, k, "shell"));
      const double low = ball_radius - plate_depth;
      const double high = mill_length - ball_radius + plate_depth;
      const Vec3 at_low = centre_at(low);
      const Vec3 at_high = centre_at(high);
      expect_contacts(mill, at_low,
                      {{0, WallKind::shell, depth, -e, on_shell(low)},
                       {first_plate, WallKind::end_plate, plate_depth, Vec3{{0.0, 0.0, 1.0}},
                        Vec3{{at_low[0], at_low[1], 0.0}}}},
                      label(angle, k, "rim at z = 0"));
      expect_contacts(mill, at_high,
                      {{0, WallKind::shell, depth, -e, on_shell(high)},
                       {first_plate + 1, WallKind::end_plate, plate_depth, Vec3{{0.0, 0.0, -1.0}},
                        Vec3{{at_high[0], at_high[1], mill_length}}}},
                      label(angle, k, "rim at z = L"));
    }
  }
}

TEST(Mill3DWall, SphereJustClearOfEveryWallHasNoContact) {
  // 1 µm off the inner face, the long edge, the shell and each end plate: no contact.
  const double angle = 0.3;
  const Mill3D mill = lab_mill_3d(angle, 0.0);
  const LifterFrame f = frame_of(angle, 5);
  WallContact<3> found[max_mill_contacts<3>];
  const double clear = ball_radius + 1e-6;
  EXPECT_EQ(mill_contacts(mill, f.at(inner_face - clear, 0.0, 0.075), ball_radius, found), 0);
  const Vec3 edge = f.at(inner_face, half_width, 0.075);
  EXPECT_EQ(mill_contacts(mill, edge + clear * f.at(-0.6, 0.8, 0.0), ball_radius, found), 0);
  const double theta = angle + 2.0 * pi * 5.5 / lifter_count;
  const Vec3 e{{std::cos(theta), std::sin(theta), 0.0}};
  EXPECT_EQ(
      mill_contacts(mill, (shell_radius - clear) * e + Vec3{{0.0, 0.0, 0.075}}, ball_radius, found),
      0);
  EXPECT_EQ(mill_contacts(mill, Vec3{{0.0, -0.2, clear}}, ball_radius, found), 0);
  EXPECT_EQ(mill_contacts(mill, Vec3{{0.0, -0.2, mill_length - clear}}, ball_radius, found), 0);
}

TEST(Mill3DWall, PeriodicSlabHasNoEndPlatesAndItsLiftersRunThroughTheEnds) {
  // A periodic slab has no end plates: a sphere on the inner face at z = 0.001 m (and at
  // z = L − 0.001) touches the lifter only, at its own z.
  const double angle = 0.3;
  const Mill3D mill = lab_mill_3d(angle, test_angular_speed, true);
  for (int k = 0; k < lifter_count; ++k) {
    const LifterFrame f = frame_of(angle, k);
    for (const double z : {0.001, mill_length - 0.001}) {
      expect_contacts(mill, f.at(inner_face - ball_radius + depth, 0.0, z),
                      {{1 + k, WallKind::lifter, depth, -f.radial, f.at(inner_face, 0.0, z)}},
                      label(angle, k, "periodic inner face"));
    }
  }
}

// ---- No leaks ---------------------------------------------------------------------------------

// The lab mill's steel (MODEL.md Table 3) and its ball, m = ρ π d³/6 = 0.53540739 kg.
const ContactMaterial steel_ball_ball{4.0e5, 3.0e5, 0.6, 0.6};
const ContactMaterial steel_ball_wall{4.0e5, 3.0e5, 0.5, 0.6};
constexpr double ball_mass = 7800.0 * pi / 6.0 * 0.0508 * 0.0508 * 0.0508;

/// Where a centre lies that no wall should ever let it reach: beyond the shell, beyond an end
/// plate, or inside a lifter bar. Empty when it is inside the free space of the mill.
std::string leak_of(const Mill3D& mill, const Vec3& centre) {
  const double planar = std::sqrt(centre[0] * centre[0] + centre[1] * centre[1]);
  if (planar > mill.radius) return "outside the shell";
  if (centre[2] < 0.0 || centre[2] > mill.length) return "beyond an end plate";
  for (int k = 0; k < mill.lifter_count; ++k) {
    const Vec2 radial = mill.lifter_direction[static_cast<std::size_t>(k)];
    const double a = centre[0] * radial[0] + centre[1] * radial[1];
    const double b = -centre[0] * radial[1] + centre[1] * radial[0];
    if (a > mill.radius - mill.lifter_height && std::abs(b) < 0.5 * mill.lifter_width) {
      return "inside lifter " + std::to_string(k);
    }
  }
  return {};
}

/// A point on one of the mill's edges or corners (in the mill at `angle`), chosen at random:
/// a lifter's long edge, its end edges and corners against a plate, its root against the shell,
/// or the rim where the shell meets a plate.
Vec3 random_feature_point(double angle, std::mt19937_64& random) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const int lifter = static_cast<int>(uniform(random) * lifter_count) % lifter_count;
  const LifterFrame f = frame_of(angle, lifter);
  const double side = uniform(random) < 0.5 ? -1.0 : 1.0;
  const double end = uniform(random) < 0.5 ? 0.0 : mill_length;
  const double along = mill_length * uniform(random);
  switch (static_cast<int>(uniform(random) * 6.0)) {
    case 0:  // long edge of the inner face and a side
      return f.at(inner_face, side * half_width, along);
    case 1:  // corner of the inner face, a side and an end
      return f.at(inner_face, side * half_width, end);
    case 2:  // end edge of the inner face, against a plate
      return f.at(inner_face, half_width * (2.0 * uniform(random) - 1.0), end);
    case 3:  // end edge of a side face, against a plate
      return f.at(inner_face + lifter_height * uniform(random), side * half_width, end);
    case 4:  // root of a side face on the shell, along the mill or at a plate
      return f.at(shell_radius, side * half_width, uniform(random) < 0.5 ? along : end);
    default: {  // the rim of the shell and a plate, anywhere round
      const double theta = 2.0 * pi * uniform(random);
      return Vec3{{shell_radius * std::cos(theta), shell_radius * std::sin(theta), end}};
    }
  }
}

TEST(Mill3DWall, FastImpactsOnEdgesAndCornersNeverLeak) {
  // 10⁴ shots, one ball each, in the lab mill turning at 8 rad/s (1.7 × critical; the shell
  // moves at 3.6 m/s). Each aims at a random point within 5 mm of an edge or corner of the
  // lifters or of the shell–plate rim, from 0 to 5 mm away, in a random direction from the
  // free space, at 0.5 to 20 m/s relative to the wall there, spinning at up to 50 rad/s about
  // a random axis, under gravity. A 20 m/s impact on one wall presses in by about
  // v sqrt(m/k_n) × 0.74 (the dashpot of e = 0.5) = 20 × 1.157e-3 × 0.74 = 0.017 m of the
  // 0.0254 m radius; the centre must never cross a wall: outside the shell, beyond a plate or
  // inside a bar. The time step is the engine's: 1/20 of the shortest contact, ball–ball,
  // t_c = 2.60e-3 s, Δt = 1.30e-4 s. Each shot runs 0.02 s (154 steps), long enough to land,
  // bounce and often hit a second wall.
  const double time_step =
      std::min(contact_duration(steel_ball_ball, reduced_mass(ball_mass, ball_mass)),
               contact_duration(steel_ball_wall, ball_mass)) /
      steps_per_contact;
  constexpr int shots = 10000;
  constexpr int steps_per_shot = 154;
  constexpr double angular_speed = 8.0;
  std::mt19937_64 random(20240611);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const auto random_unit = [&] {
    for (;;) {
      const Vec3 v{
          {2.0 * uniform(random) - 1.0, 2.0 * uniform(random) - 1.0, 2.0 * uniform(random) - 1.0}};
      const double length = norm(v);
      if (length > 0.1 && length <= 1.0) return v * (1.0 / length);
    }
  };
  WorldSettings<3> settings;
  settings.time_step = time_step;
  settings.gravity = Vec3{{0.0, -standard_gravity, 0.0}};
  settings.ball_ball = steel_ball_ball;
  settings.ball_wall = steel_ball_wall;

  int hits = 0;
  double deepest = 0.0;  // largest wall overlap seen, m
  double fastest = 0.0;  // largest impact speed relative to the wall, m/s, of a shot that hit
  for (int shot = 0; shot < shots; ++shot) {
    const double angle = 2.0 * pi * uniform(random);
    const Mill3D mill = lab_mill_3d(angle, angular_speed);
    // Aim: a point near a feature, a direction from which the ball starts in free space.
    Vec3 target{};
    Vec3 direction{};
    Vec3 start{};
    for (;;) {
      target = random_feature_point(angle, random) +
               0.005 * Vec3{{2.0 * uniform(random) - 1.0, 2.0 * uniform(random) - 1.0,
                             2.0 * uniform(random) - 1.0}};
      direction = random_unit();
      start = target - (ball_radius + 0.005 * uniform(random)) * direction;
      WallContact<3> found[max_mill_contacts<3>];
      if (leak_of(mill, start).empty() && mill_contacts(mill, start, ball_radius, found) == 0) {
        break;
      }
    }
    const double speed = 0.5 + 19.5 * uniform(random);
    const Vec3 velocity = turning_velocity(angular_speed, target) + speed * direction;
    const Vec3 spin = (50.0 * uniform(random)) * random_unit();
    Walls<3> walls;
    walls.mill = mill;
    World<3> world(settings, walls);
    world.particles().add(start, ball_radius, ball_mass, velocity, spin);
    bool hit = false;
    for (int n = 0; n < steps_per_shot; ++n) {
      world.step();
      const Vec3& centre = world.particles().position[0];
      const std::string leak = leak_of(*world.walls().mill, centre);
      ASSERT_TRUE(leak.empty()) << "shot " << shot << " step " << n << ": centre (" << centre[0]
                                << ", " << centre[1] << ", " << centre[2] << ") " << leak
                                << "; it started at " << speed << " m/s";
      WallContact<3> found[max_mill_contacts<3>];
      const int count = mill_contacts(*world.walls().mill, centre, ball_radius, found);
      for (int c = 0; c < count; ++c) deepest = std::max(deepest, found[c].overlap);
      hit = hit || count > 0;
    }
    if (hit) {
      ++hits;
      fastest = std::max(fastest, speed);
    }
  }
  // Every shot lands (seen: 10 000 of 10 000; the bound leaves room for a few grazing past),
  // the fastest close to 20 m/s, and no wall ever pressed into a ball much deeper than a
  // head-on 20 m/s impact does. That impact's deepest overlap is the damped oscillator's first
  // peak, (v/ω0) exp(−ζ φ/sqrt(1 − ζ²)) with φ = atan(sqrt(1 − ζ²)/ζ): for e = 0.5, ζ =
  // 0.21545376, φ = 1.3536, the factor 0.7418, so 0.023139 × 0.7418 = 0.017164 m. Allowed 5 %
  // more for the step (t_c/20 samples the peak) and for a ball pressed by two walls at once
  // in a corner (seen: 0.01722 m).
  EXPECT_GT(hits, 0.95 * shots);
  EXPECT_GT(fastest, 19.5);
  const double zeta = damping_ratio(steel_ball_wall.restitution);
  const double root = std::sqrt(1.0 - zeta * zeta);
  const double head_on_peak = 20.0 * std::sqrt(ball_mass / steel_ball_wall.normal_stiffness) *
                              std::exp(-zeta / root * std::atan(root / zeta));
  EXPECT_NEAR(head_on_peak, 0.017164, 1e-5);
  EXPECT_LT(deepest, 1.05 * head_on_peak);
}

// ---- Whole mills --------------------------------------------------------------------------

/// Case 3D-g of MODEL.md §8 (examples/validation/3D-g.toml), written out here so that the tests
/// do not change when the example does: the 0.9 m × 0.15 m lab mill with eight 4 × 4 cm lifters
/// and end plates, J = 0.3 of 5.08 cm steel balls (250 of them), half critical speed,
/// Table 3 materials.
constexpr const char* lab_mill_3d_toml = R"(
[simulation]
dimension = 3
time_step = "auto"
settle_time = 1.0
revolutions = 6
measure_revolutions = 4
seed = 1

[mill]
diameter = 0.9
length = 0.15
speed = 0.50

[mill.lifters]
count = 8
height = 0.04
width = 0.04

[charge]
filling = 0.30
porosity = 0.4
density = 7800
ball_diameter = 0.0508

[materials.ball_ball]
normal_stiffness = 4.0e5
tangential_stiffness = 3.0e5
restitution = 0.6
friction = 0.6

[materials.ball_wall]
normal_stiffness = 4.0e5
tangential_stiffness = 3.0e5
restitution = 0.5
friction = 0.6

[output]
directory = "runs/tests/mill-3d"
snapshot_interval = 0
)";

MillConfig lab_mill_config(const std::vector<std::string>& overrides = {}) {
  return parse_mill_config(lab_mill_3d_toml, "lab-mill-3d.toml", overrides);
}

MillResult run_3d(const MillConfig& config) {
  const MillPlan plan = plan_mill(config);
  return run_mill<3>(plan, build_mill_world<3>(plan), {});
}

TEST(Mill3D, SettledChargeComesToRestAndStays) {
  const MillPlan plan = plan_mill(lab_mill_config());
  ASSERT_EQ(plan.particle_count, 250);
  World<3> world = build_mill_world<3>(plan);
  const double reference_energy =
      plan.slice_mass * standard_gravity * plan.largest_ball;  // m g d of the whole charge
  while (world.time() < 2.0) world.step();
  const double settled = world.kinetic_energy();
  EXPECT_LT(settled, 1e-6 * reference_energy) << "kinetic energy after 2 s of settling";

  const std::vector<Vec3> at_rest = world.particles().position;
  const double potential = world.potential_energy();
  while (world.time() < 3.0) world.step();
  // In the cross-section nothing moves. Along the axis a ball may still roll: one lying in the
  // groove between a lifter's side and the shell (or along a straight row of balls) rolls along
  // z without slipping, which the contact law (MODEL.md §3, no rolling resistance) does not
  // damp. Such a ball keeps the speed it had when the charge came to rest (up to 1.2 mm/s seen
  // in runs of this scene, 1e-8 of m g d); it is not creep, so the axial bound allows it, but
  // no more than a few balls doing it.
  double largest_planar_move = 0.0;
  double largest_axial_move = 0.0;
  int rolling_along_the_axis = 0;
  for (std::size_t i = 0; i < at_rest.size(); ++i) {
    const Vec3 move = world.particles().position[i] - at_rest[i];
    largest_planar_move = std::max(largest_planar_move, std::hypot(move[0], move[1]));
    largest_axial_move = std::max(largest_axial_move, std::abs(move[2]));
    if (std::abs(move[2]) > 1e-4 * plan.largest_ball) ++rolling_along_the_axis;
  }
  EXPECT_LT(largest_planar_move, 1e-4 * plan.largest_ball)
      << "a ball crept in the cross-section during a further second";
  EXPECT_LT(largest_axial_move, 0.05 * plan.largest_ball);
  EXPECT_LE(rolling_along_the_axis, 5);
  EXPECT_LT(world.kinetic_energy(), 1e-6 * reference_energy);
  // The bed neither sinks nor heaves: its potential energy stays within 1e-6 of m g d (a mean
  // height change of 50 nm; seen: +5e-6 J, 8e-8 of m g d, as the contacts relax).
  EXPECT_NEAR(world.potential_energy(), potential, 1e-6 * reference_energy);
}

TEST(Mill3D, TumblesBelowCriticalAndCentrifugesAboveIt) {
  // Short runs of case 3D-g: 0.6 s to settle (the balls fall at most 0.9 m, 0.43 s), then two
  // revolutions at 60 % of critical speed, four at 150 % and 200 %, measuring the last one.
  const auto at_speed = [](double fraction, int revolutions) {
    return run_3d(
        lab_mill_config({fmt::format("mill.speed={}", fraction),
                         fmt::format("simulation.revolutions={}", revolutions),
                         "simulation.measure_revolutions=1", "simulation.settle_time=0.6"}));
  };
  const MillResult tumbling = at_speed(0.6, 2);
  const MillResult centrifuging = at_speed(1.5, 4);
  const MillResult far_above = at_speed(2.0, 4);
  const double radius = tumbling.plan.radius;

  // Tumbling: the charge is held up on the rising side (+x), its centre of mass well off the
  // axis, and the mill draws a power like the lab mill's 0.6 kW (seen: 0.64 kW, centre
  // (0.168, −0.113) m, orbital speed ratio 0.74: the bed turns with the shell, the balls
  // cascading down its surface against the turn).
  EXPECT_GT(tumbling.power_kw, 0.3);
  EXPECT_GT(tumbling.charge_centre[0], 0.1 * radius);
  EXPECT_LT(tumbling.orbital_speed_ratio, 0.9);

  // Centrifuged: the charge rides round with the shell (seen: 0.996 and 0.999), its centre of
  // mass on the axis (seen: 0.0063 and 0.0027 m, against 0.204 m tumbling), so lifting it
  // takes no torque. What power is left is the inner layers rolling to and fro in the bays
  // as gravity turns round them, still dying away in the fourth revolution and chaotic (seen:
  // 73 W at 150 % and 41 W at 200 %, 11 % and 6.5 % of tumbling; 11 to 17 % in the third
  // revolution), so the bounds say "far below tumbling", not a measured value.
  const double tumbling_offset = norm(tumbling.charge_centre);
  EXPECT_NEAR(centrifuging.orbital_speed_ratio, 1.0, 0.03);
  EXPECT_NEAR(far_above.orbital_speed_ratio, 1.0, 0.01);
  EXPECT_LT(norm(centrifuging.charge_centre), 0.1 * tumbling_offset);
  EXPECT_LT(norm(far_above.charge_centre), 0.05 * tumbling_offset);
  EXPECT_LT(std::abs(centrifuging.power_kw), 0.25 * tumbling.power_kw);
  EXPECT_LT(std::abs(far_above.power_kw), 0.15 * tumbling.power_kw);
}

TEST(Mill3D, EnergyAccountClosesAndBothPowersAgree) {
  // Case 3D-g, settled 0.6 s, turned three revolutions, measured over the last two, at the
  // default time step (what users run; the issue's bound is 1 %), and at half of it. The account's
  // error is the integration's, not noise: at the default it closes to 0.60 % here (0.60 % and
  // 0.61 % in the 3D validation runs), at half the step to 0.057 %, about a tenth. The leapfrog's
  // energy error is second order in the step, so halving it must take the error to a quarter or
  // less: held to 0.35 of the default's.
  const MillPlan default_plan = plan_mill(lab_mill_config());
  const std::vector<std::string> run_settings = {
      "simulation.settle_time=0.6", "simulation.revolutions=3", "simulation.measure_revolutions=2"};
  const MillResult at_default = run_3d(lab_mill_config(run_settings));
  testing::expect_energy_account_closes(at_default);
  EXPECT_GT(at_default.power_kw, 0.3);
  std::vector<std::string> halved = run_settings;
  halved.push_back(fmt::format("simulation.time_step={}", 0.5 * default_plan.time_step));
  const MillResult at_half = run_3d(lab_mill_config(halved));
  testing::expect_energy_account_closes(at_half);
  EXPECT_LT(at_half.energy_balance_error, 0.35 * at_default.energy_balance_error);
  ::testing::Test::RecordProperty("energy_balance_error_default_step",
                                  fmt::format("{:.3g}", at_default.energy_balance_error));
  ::testing::Test::RecordProperty("energy_balance_error_half_step",
                                  fmt::format("{:.3g}", at_half.energy_balance_error));
}

/// Steps `world`, its mill turning at a constant ω, and checks every step that the drive's power
/// times the step is the work the shell, its lifters and its end plates did on the balls in it:
/// each wall contact's point p moves with the mill at ω ẑ × p = ω (−p_y, p_x, 0), so the work of
/// its force F in the step is F·(ω ẑ × p) Δt = ω (p_x F_y − p_y F_x) Δt = ω (p × F)_z Δt, its
/// moment about the axis times ω Δt; summed over the contacts, T ω Δt. Both sides come from the
/// same forces, so they agree to round-off. Returns the time integral of the torque, Σ T Δt.
double step_checking_torque_power(World<3>& world, long steps) {
  const double omega = world.walls().mill->angular_speed;
  const double time_step = world.settings().time_step;
  double torque_time = 0.0;
  for (long n = 0; n < steps; ++n) {
    const double before = world.energy_account().shell_work;
    world.step();
    const double work = world.energy_account().shell_work - before;
    const double power_times_step = world.shell_torque() * omega * time_step;
    torque_time += world.shell_torque() * time_step;
    // Round-off: a few ulps of the terms, and of shell_work, to which the step's work is added
    // (seen: 3e-4 of this bound at most).
    const double round_off =
        1e-12 * (std::abs(power_times_step) + std::abs(world.energy_account().shell_work));
    EXPECT_NEAR(power_times_step, work, round_off) << "step " << n;
    if (std::abs(power_times_step - work) > round_off) break;  // one message is enough
  }
  return torque_time;
}

TEST(Mill3D, DriveTorqueTimesSpeedIsTheShellsWorkAndDrawsPower) {
  // Case 3D-g at 70 % of critical speed (case 3D-e's, for a shorter revolution): critical is
  // sqrt(2 g / (D − d)) = sqrt(19.62 / 0.8492) = 4.8067 rad/s, so ω = 3.3647 rad/s. Settled 0.6 s
  // with the shell still (which does no work), then turned at once for an eighth of a revolution
  // (0.23 s, 1793 steps): every step's T ω Δt is the work the walls did in it (above), to
  // round-off. The charge is settled once for both halves of the test: a copy turns here, and
  // run_mill, given it at the end of its settle time, turns it at once.
  const MillPlan plan =
      plan_mill(lab_mill_config({"mill.speed=0.7", "simulation.settle_time=0.6",
                                 "simulation.revolutions=1", "simulation.measure_revolutions=1"}));
  World<3> settled = build_mill_world<3>(plan);
  while (settled.time() + 0.5 * plan.time_step < plan.config.settle_time) settled.step();
  ASSERT_EQ(settled.energy_account().shell_work, 0.0);
  World<3> world = settled;
  world.walls().mill->angular_speed = plan.angular_speed;
  const double start = world.time();
  const long steps = std::lround(0.25 * pi / plan.angular_speed / plan.time_step);
  const double torque_time = step_checking_torque_power(world, steps);
  // The shell drags the charge at rest up its rising side (+x, the mill turning
  // counter-clockwise): the torque is with the turning and draws power, T ω > 0 (seen: 289 N m,
  // 972 W). The power by torque is the shell's work over the time, the sum of the steps above.
  const double duration = world.time() - start;
  const double mean_torque = torque_time / duration;
  const double power = world.energy_account().shell_work / duration;
  EXPECT_GT(mean_torque * plan.angular_speed, 0.0);
  EXPECT_NEAR(mean_torque * plan.angular_speed, power, 1e-9 * std::abs(power));

  // What a run writes, one revolution. Its torque in power.csv (the integral of T over the
  // revolution, divided by its time) is with the turning (seen: 206 N m), and the summary's
  // power draws from the drive (seen: 0.642 kW). The shell comes up to speed over the first
  // quarter of it (spin_up_time), so there the mean torque times the final ω is not the power;
  // after it ω is constant, and each row of power_timeseries.csv (50 a revolution) has torque
  // × ω = power, the shell's work over the row's time, to the round-off of summing ~290 steps
  // (seen: 1.5e-13), and a torque with the turning (seen: 143 to 321 N m as the lifters pass).
  const MillResult result = run_mill<3>(plan, settled, {});
  ASSERT_EQ(result.revolutions.size(), 1U);
  EXPECT_GT(result.revolutions[0].torque, 0.0) << "power.csv's torque_nm";
  EXPECT_GT(result.power_kw, 0.3);
  const double up_to_speed = result.revolutions[0].start_time + plan.spin_up_time;
  const auto at_speed = [&](const PowerInterval& row) { return row.start_time >= up_to_speed; };
  // 50 rows less those of the spin-up, in which the shell turns ω/2 × (a quarter period), an
  // eighth of a revolution: 43 or 44.
  EXPECT_GE(std::count_if(result.series.begin(), result.series.end(), at_speed), 43);
  for (const PowerInterval& row : result.series) {
    if (!at_speed(row)) continue;
    const double tolerance = 1e-9 * std::abs(row.power);
    EXPECT_GT(row.torque, 0.0) << "power_timeseries.csv row from " << row.start_time << " s";
    EXPECT_NEAR(row.torque * plan.angular_speed, row.power, tolerance)
        << "power_timeseries.csv row from " << row.start_time << " s";
    // One row's messages are enough.
    if (row.torque <= 0.0 || std::abs(row.torque * plan.angular_speed - row.power) > tolerance) {
      break;
    }
  }
}

TEST(Mill3D, PeriodicSlabScalesToTheMillLength) {
  // A 0.64 m long lab mill simulated as a periodic slab of 0.16 m (3.15 ball diameters): the
  // slab holds the charge of 0.16 m of mill, ρ (1 − porosity) J π R² × 0.16 / m_ball
  // = 7800 × 0.6 × 0.3 × π × 0.2025 × 0.16 / 0.53540739 = 266.9, so 267 balls, as many as a
  // whole 0.16 m mill with end plates; its power is scaled by 0.64 / 0.16 = 4.
  const std::vector<std::string> short_run = {
      "simulation.settle_time=0.6", "simulation.revolutions=2", "simulation.measure_revolutions=1"};
  const auto with = [&](std::vector<std::string> overrides) {
    overrides.insert(overrides.end(), short_run.begin(), short_run.end());
    return lab_mill_config(overrides);
  };
  const MillPlan plan =
      plan_mill(with({"mill.length=0.64", "mill.periodic=true", "mill.slab_length=0.16"}));
  const MillPlan whole_plan = plan_mill(with({"mill.length=0.16"}));
  EXPECT_DOUBLE_EQ(plan.power_scale, 4.0);
  EXPECT_EQ(plan.simulated_length, 0.16);
  EXPECT_EQ(plan.particle_count, 267);
  EXPECT_EQ(plan.particle_count, whole_plan.particle_count);
  EXPECT_EQ(whole_plan.power_scale, 1.0);
  // The same slab out of a mill half as long is the same simulation, scaled by 2.
  const MillPlan half_plan =
      plan_mill(with({"mill.length=0.32", "mill.periodic=true", "mill.slab_length=0.16"}));
  EXPECT_EQ(half_plan.particle_count, plan.particle_count);
  EXPECT_EQ(half_plan.time_step, plan.time_step);
  EXPECT_DOUBLE_EQ(half_plan.power_scale, 2.0);

  // Every ball stays in [0, 0.16) along the axis, step by step, while balls cross the ends of
  // the period and come back at the other end (seen: 150 crossings in 1.5 s).
  {
    World<3> world = build_mill_world<3>(plan);
    ASSERT_TRUE(world.walls().mill->periodic);
    ASSERT_EQ(world.walls().mill->length, 0.16);
    std::vector<Vec3> before = world.particles().position;
    long crossings = 0;
    while (world.time() < 1.5) {
      if (world.time() >= 0.6) world.walls().mill->angular_speed = plan.angular_speed;
      world.step();
      const auto& x = world.particles().position;
      for (std::size_t i = 0; i < x.size(); ++i) {
        ASSERT_GE(x[i][2], 0.0) << "ball " << i << " at t = " << world.time();
        ASSERT_LT(x[i][2], 0.16) << "ball " << i << " at t = " << world.time();
        if (std::abs(x[i][2] - before[i][2]) > 0.08) ++crossings;
      }
      before = x;
    }
    EXPECT_GT(crossings, 10);
  }

  // The summary's power is the slab's times 4, and per metre of mill about that of the whole
  // 0.16 m mill with its end plates (seen: 3.50 and 3.59 kW/m; one revolution each, so the
  // bound is loose).
  const MillResult slab = run_mill<3>(plan, build_mill_world<3>(plan), {});
  const MillResult whole = run_3d(whole_plan.config);
  const double slab_watts = (slab.window_end.shell_work - slab.window_start.shell_work) /
                            (slab.window_end.time - slab.window_start.time);
  EXPECT_GT(slab_watts, 0.0);
  EXPECT_NEAR(slab.power_kw, 4.0 * slab_watts / 1000.0, 1e-12 * slab.power_kw);
  const double per_metre = slab.power_kw / 0.64;
  const double whole_per_metre = whole.power_kw / 0.16;
  EXPECT_GT(per_metre, 1.0);  // kW/m
  EXPECT_NEAR(per_metre, whole_per_metre, 0.15 * whole_per_metre);
}

TEST(Mill3D, SlabShorterThanThreeBallDiametersIsRefused) {
  // A ball must not meet two images of another across the period: the slab must be at least
  // three of the largest balls long, 3 × 0.0508 = 0.1524 m. 0.15 m and 0.1 m are refused by
  // plan_mill, naming the key and the limit; 0.16 m is planned.
  for (const char* slab : {"0.15", "0.1"}) {
    const MillConfig config = lab_mill_config(
        {"mill.length=0.64", "mill.periodic=true", fmt::format("mill.slab_length={}", slab)});
    try {
      plan_mill(config);
      ADD_FAILURE() << "slab of " << slab << " m was planned";
    } catch (const InputError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("mill.slab_length"), std::string::npos) << message;
      // The limit, 3 × 0.0508 m, printed to four figures.
      EXPECT_NE(message.find("0.1524 m"), std::string::npos) << message;
      EXPECT_NE(message.find(slab), std::string::npos) << message;
    }
  }
  EXPECT_NO_THROW(plan_mill(
      lab_mill_config({"mill.length=0.64", "mill.periodic=true", "mill.slab_length=0.16"})));
  // The limit is set by the largest ball of a mixed charge: 6 cm and 3 cm balls need 0.18 m.
  MillConfig mixed =
      lab_mill_config({"mill.length=0.64", "mill.periodic=true", "mill.slab_length=0.17"});
  mixed.sizes = {{0.06, 0.5}, {0.03, 0.5}};
  EXPECT_THROW(plan_mill(mixed), InputError);
  mixed.slab_length = 0.19;
  EXPECT_NO_THROW(plan_mill(mixed));
}

}  // namespace
}  // namespace millsim
