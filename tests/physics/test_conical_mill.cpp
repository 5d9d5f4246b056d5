// 3D mills with conical ends (mill.cone_angle, mill.cone_length): the exact closest-feature
// contact with the cones and the trunnion plates that close them, checked against hand-placed
// spheres and against a brute-force distance to the mill's profile; no leaks through the cones,
// the trunnion rim or the lifters' ends under fast impacts; the charge volume of a cone; config
// errors; and a running conical mill that keeps its energy account.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
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

// The lab mill of case 3D-g (R = 0.45 m, L = 0.15 m, eight 4 × 4 cm lifters, 5.08 cm balls)
// with cones of 20° and 0.1 m at both ends: trunnion radius r_t = R − c / tan α = 0.17525 m,
// slant length c / sin α = 0.29238 m. In the meridian plane of a centre, (ρ, s) with s the
// distance beyond the end of the cylinder, the cone runs from (R, 0) along (−cos α, sin α) and
// its inward normal is (−sin α, −cos α); the trunnion plate is s = c, ρ ≤ r_t.
constexpr double shell_radius = 0.45;
constexpr double mill_length = 0.15;
constexpr double cone_length = 0.1;
const double cone_angle = 20.0 * pi / 180.0;
const double sin_a = std::sin(cone_angle);
const double cos_a = std::cos(cone_angle);
const double trunnion = shell_radius - cone_length / std::tan(cone_angle);
const double slant = cone_length / sin_a;
constexpr double ball_radius = 0.0254;
constexpr int lifter_count = 8;
constexpr int first_end = 1 + lifter_count;  // the cone at z = 0; then z = L, then the plates
constexpr double tolerance = 1e-12;

Mill3D conical_mill(double angle, double angular_speed, int lifters = lifter_count,
                    double angle_of_cones = cone_angle) {
  Mill3D mill;
  mill.radius = shell_radius;
  mill.lifter_count = lifters;
  mill.lifter_height = 0.04;
  mill.lifter_width = 0.04;
  mill.angular_speed = angular_speed;
  mill.length = mill_length;
  mill.cone_length = cone_length;
  mill.cone_angle = angle_of_cones;
  mill.turn_to(angle);
  return mill;
}

/// A point given in the meridian plane at azimuth phi: distance ρ from the axis, s beyond the
/// end `side` of the cylinder (0: z = −s, 1: z = L + s).
Vec3 meridian_point(double phi, double rho, double s, int side) {
  return Vec3{{rho * std::cos(phi), rho * std::sin(phi), side == 0 ? -s : mill_length + s}};
}
/// A direction in the meridian plane: (radial, along s) components.
Vec3 meridian_direction(double phi, double radial, double along_s, int side) {
  return Vec3{{radial * std::cos(phi), radial * std::sin(phi), side == 0 ? -along_s : along_s}};
}

struct Expected {
  int wall_id;
  WallKind kind;
  double overlap;
  Vec3 normal;
  Vec3 point;
};

void expect_near(const Vec3& actual, const Vec3& expected, const std::string& what) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(actual[i], expected[i], tolerance) << what << " " << i;
}

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
    EXPECT_NEAR(c->overlap, e.overlap, tolerance) << with;
    expect_near(c->normal, e.normal, with + " normal");
    expect_near(c->point, e.point, with + " point");
    // The wall turns with the shell: ω ẑ × p.
    expect_near(c->wall_velocity,
                Vec3{{-mill.angular_speed * c->point[1], mill.angular_speed * c->point[0], 0.0}},
                with + " wall velocity");
  }
}

// Azimuths half-way between two lifters of the mill turned to `angle`, away from every bar.
constexpr double test_angles[] = {0.0, 0.3, -2.0};
double between_lifters(double angle, int k) {
  return angle + 2.0 * pi * (k + 0.5) / lifter_count;
}

TEST(ConicalMillWall, SphereOnAConeTouchesItAlongTheConeNormal) {
  // A sphere pressed 1 mm into the cone half-way along it, at z < 0 and z > L: its centre sits
  // at r − δ along the inward normal from a point of the cone, which is its only contact.
  const double depth = 1e-3;
  for (const double angle : test_angles) {
    const Mill3D mill = conical_mill(angle, 2.0);
    for (int side = 0; side < 2; ++side) {
      for (int k = 0; k < lifter_count; k += 3) {
        const double phi = between_lifters(angle, k);
        const double u = 0.5 * slant;
        const Vec3 point = meridian_point(phi, shell_radius - u * cos_a, u * sin_a, side);
        const Vec3 normal = meridian_direction(phi, -sin_a, -cos_a, side);
        const Vec3 centre = point + (ball_radius - depth) * normal;
        expect_contacts(mill, centre,
                        {{first_end + side, WallKind::end_plate, depth, normal, point}},
                        fmt::format("cone side {} angle {} k {}", side, angle, k));
      }
    }
  }
}

TEST(ConicalMillWall, SphereOnATrunnionPlateTouchesItAlongTheAxis) {
  const double depth = 2e-3;
  const Mill3D mill = conical_mill(0.3, 2.0);
  for (int side = 0; side < 2; ++side) {
    for (const double rho : {0.0, 0.05, 0.12}) {
      const double phi = 1.1;
      const Vec3 point = meridian_point(phi, rho, cone_length, side);
      const Vec3 normal = meridian_direction(phi, 0.0, -1.0, side);
      const Vec3 centre = point + (ball_radius - depth) * normal;
      expect_contacts(mill, centre,
                      {{first_end + 2 + side, WallKind::end_plate, depth, normal, point}},
                      fmt::format("plate side {} rho {}", side, rho));
    }
  }
}

TEST(ConicalMillWall, SphereInTheTrunnionCornerTouchesConeAndPlate) {
  // s = c − (r − δ₁) puts the sphere δ₁ into the plate; ρ = R − (r − δ₂ + s cos α) / sin α
  // puts it δ₂ into the cone (its signed distance from the cone is (R − ρ) sin α − s cos α).
  // ρ = 0.1709 m < r_t and the foot on the cone, at (R − ρ) cos α + s sin α = 0.2881 m, lies
  // within its 0.2924 m: the sphere touches both faces of the concave corner.
  const double plate_depth = 1e-3;
  const double cone_depth = 1.5e-3;
  const Mill3D mill = conical_mill(0.0, 1.5);
  for (int side = 0; side < 2; ++side) {
    const double phi = between_lifters(0.0, 2);
    const double s = cone_length - (ball_radius - plate_depth);
    const double rho = shell_radius - (ball_radius - cone_depth + s * cos_a) / sin_a;
    ASSERT_LT(rho, trunnion);
    const double u = (shell_radius - rho) * cos_a + s * sin_a;
    ASSERT_LT(u, slant);
    const Vec3 centre = meridian_point(phi, rho, s, side);
    expect_contacts(
        mill, centre,
        {{first_end + side, WallKind::end_plate, cone_depth,
          meridian_direction(phi, -sin_a, -cos_a, side),
          meridian_point(phi, shell_radius - u * cos_a, u * sin_a, side)},
         {first_end + 2 + side, WallKind::end_plate, plate_depth,
          meridian_direction(phi, 0.0, -1.0, side), meridian_point(phi, rho, cone_length, side)}},
        fmt::format("trunnion corner side {}", side));
  }
}

TEST(ConicalMillWall, SphereAtTheEndOfTheCylinderTouchesShellAndCone) {
  // A sphere 1 mm into the shell with its centre 18 mm inside the cylinder from z = 0 reaches
  // past the end of the cylinder to the cone: signed distance (R − ρ) sin α + 0.018 cos α =
  // 0.02526 m < r. Seen from inside the corner between shell and cone is concave, so each face
  // is touched on its face.
  const double shell_depth = 1e-3;
  const Mill3D mill = conical_mill(0.0, 1.5);
  const double phi = between_lifters(0.0, 5);
  const double rho = shell_radius - (ball_radius - shell_depth);
  const double s = -0.018;
  const Vec3 centre = meridian_point(phi, rho, s, 0);
  const double inside_cone = (shell_radius - rho) * sin_a - s * cos_a;
  ASSERT_LT(inside_cone, ball_radius);
  const double u = (shell_radius - rho) * cos_a + s * sin_a;
  expect_contacts(mill, centre,
                  {{0, WallKind::shell, shell_depth, meridian_direction(phi, -1.0, 0.0, 0),
                    meridian_point(phi, shell_radius, s, 0)},
                   {first_end, WallKind::end_plate, ball_radius - inside_cone,
                    meridian_direction(phi, -sin_a, -cos_a, 0),
                    meridian_point(phi, shell_radius - u * cos_a, u * sin_a, 0)}},
                  "shell and cone");
}

TEST(ConicalMillWall, SphereAgainstALifterEndInTheConeTouchesTheBarsEndFace) {
  // The lifters stop at the ends of the cylinder. A 20° cone narrows too fast for a sphere to
  // reach a bar's end face head-on (at s = r the cone's radius is 0.383 m, inside the bars'
  // 0.41 m), so this takes cones of 80° (r_t = 0.4324 m): a sphere in the cone right in front
  // of lifter 0's end face (centre at a = 0.415 m, z = −(r − δ)) touches that face along −z,
  // and nothing else (its signed distance from the cone is 0.035 sin 80° − (r − δ) cos 80° =
  // 0.0302 m > r).
  const double depth = 1e-3;
  const Mill3D mill = conical_mill(0.0, 1.5, lifter_count, 80.0 * pi / 180.0);
  const double a = 0.415;
  const Vec3 centre{{a, 0.0, -(ball_radius - depth)}};
  expect_contacts(mill, centre,
                  {{1, WallKind::lifter, depth, Vec3{{0.0, 0.0, -1.0}}, Vec3{{a, 0.0, 0.0}}}},
                  "lifter end face");
}

TEST(ConicalMillWall, SphereCentredAHairBeyondALifterEndHasAFiniteAxialNormal) {
  // The same sphere with its centre next to nothing beyond the bar's end face (z = −1e-100 m,
  // −1e-160 m) touches the face along −z with overlap r (r − distance rounds to r); its normal
  // was once axial / (r − overlap) = axial / 0, infinite.
  const Mill3D mill = conical_mill(0.0, 1.5, lifter_count, 80.0 * pi / 180.0);
  for (const double z : {-1e-100, -1e-160}) {
    WallContact<3> found[max_mill_contacts<3>];
    const int count = mill_contacts(mill, Vec3{{0.415, 0.0, z}}, ball_radius, found);
    const auto lifter = std::find_if(
        found, found + count, [](const WallContact<3>& c) { return c.kind == WallKind::lifter; });
    ASSERT_NE(lifter, found + count) << "z = " << z;
    EXPECT_EQ(lifter->wall_id, 1) << "z = " << z;
    EXPECT_EQ(lifter->normal[0], 0.0) << "z = " << z;
    EXPECT_EQ(lifter->normal[1], 0.0) << "z = " << z;
    EXPECT_EQ(lifter->normal[2], -1.0) << "z = " << z;
    EXPECT_DOUBLE_EQ(lifter->overlap, ball_radius) << "z = " << z;
  }
}

/// Distance in the meridian plane from (ρ, s) to the segment from p to q, found by ternary
/// search on the squared distance along it (convex in the parameter): a brute-force answer
/// independent of the closest-point algebra.
double searched_distance(double rho, double s, double p_rho, double p_s, double q_rho, double q_s) {
  const auto squared = [&](double t) {
    const double dr = rho - (p_rho + t * (q_rho - p_rho));
    const double ds = s - (p_s + t * (q_s - p_s));
    return dr * dr + ds * ds;
  };
  double low = 0.0;
  double high = 1.0;
  for (int n = 0; n < 200; ++n) {
    const double a = low + (high - low) / 3.0;
    const double b = high - (high - low) / 3.0;
    (squared(a) < squared(b) ? high : low) = squared(a) < squared(b) ? b : a;
  }
  return std::sqrt(squared(0.5 * (low + high)));
}

TEST(ConicalMillWall, EveryFaceOfTheProfileWithinReachIsTouchedAtItsClosestPoint) {
  // 20 000 random centres inside a lifterless conical mill near its ends (up to 0.05 m into the
  // cylinder and anywhere in the cones, both sides), for cones of 20° and of 10° and 80°, whose
  // corners are sharper. The wall of a surface of revolution closest to a point lies in the
  // point's meridian plane, so the distance to each face there is the distance to its segment
  // of the profile: the shell (ρ = R, −L ≤ s ≤ 0), the cone and the trunnion plate, each
  // searched for its closest point. A sphere touches a face exactly when that distance is below
  // r, with overlap r minus it. Near a corner (concave) a sphere pressed into one face reaches
  // over the rim of the next: that contact must begin at no overlap, not appear with a finite
  // one when the centre crosses the rim's normal line (it once did, at up to 2 % of r here).
  for (const double degrees : {20.0, 10.0, 80.0}) {
    SCOPED_TRACE(fmt::format("cones of {} degrees", degrees));
    const double angle = degrees * pi / 180.0;
    const double sin_angle = std::sin(angle);
    const double cos_angle = std::cos(angle);
    const double cone = std::min(cone_length, 0.9 * (shell_radius - 0.1) * std::tan(angle));
    Mill3D mill = conical_mill(0.0, 1.0, 0, angle);
    mill.cone_length = cone;
    const double r_t = mill.trunnion_radius();
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    int touching = 0;
    int rim_contacts = 0;
    int checked = 0;
    while (checked < 20000) {
      const int side = uniform(random) < 0.5 ? 0 : 1;
      const double s = -0.05 + (cone + 0.05) * uniform(random);
      const double rho = shell_radius * std::sqrt(uniform(random));
      // Inside: within the shell, in front of the cone and the plate.
      if ((shell_radius - rho) * sin_angle - s * cos_angle < 0.0 || s > cone) continue;
      ++checked;
      const double phi = 2.0 * pi * uniform(random);
      const Vec3 centre = meridian_point(phi, rho, s, side);
      const std::array<double, 3> distance = {
          searched_distance(rho, s, shell_radius, -0.05 - ball_radius, shell_radius, 0.0),
          searched_distance(rho, s, shell_radius, 0.0, r_t, cone),
          searched_distance(rho, s, r_t, cone, 0.0, cone)};
      // Wall ids: the shell, then the lifters (none here), the two cones and the two plates.
      const std::array<int, 3> wall_id = {0, 1 + side, 3 + side};
      WallContact<3> found[max_mill_contacts<3>];
      const int count = mill_contacts(mill, centre, ball_radius, found);
      const std::string where = fmt::format("rho {} s {} side {}", rho, s, side);
      touching += count > 0 ? 1 : 0;
      for (int c = 0; c < count; ++c) {
        // Each contact point is on the mill's wall, the centre r − δ from it along the normal.
        expect_near(centre, found[c].point + (ball_radius - found[c].overlap) * found[c].normal,
                    where + " centre from point");
        EXPECT_NEAR(norm(found[c].normal), 1.0, tolerance) << where;
      }
      for (std::size_t face = 0; face < 3; ++face) {
        const auto contact = std::find_if(found, found + count, [&](const WallContact<3>& c) {
          return c.wall_id == wall_id[face];
        });
        if (distance[face] > ball_radius + 1e-9) {
          EXPECT_EQ(contact, found + count) << where << ": face " << face;
        } else if (distance[face] < ball_radius - 1e-9) {
          ASSERT_NE(contact, found + count)
              << where << ": face " << face << " within " << ball_radius - distance[face] << " m";
          EXPECT_NEAR(contact->overlap, ball_radius - distance[face], 1e-9)
              << where << ": face " << face;
          // Touched at its rim: the contact's point is a corner of the profile.
          const double point_rho = std::hypot(contact->point[0], contact->point[1]);
          const bool at_rim = std::abs(point_rho - shell_radius) < 1e-12 ? face != 0
                              : std::abs(point_rho - r_t) < 1e-12        ? face == 1
                                                                         : false;
          rim_contacts += at_rim ? 1 : 0;
        }
      }
    }
    // Seen at 20°: 5 901 of the 20 000 touch a wall, and some touch a face at its rim.
    EXPECT_GT(touching, 3000);
    EXPECT_GT(rim_contacts, 10);
  }
}

/// Where a centre lies that no wall should let it reach: outside the surface of revolution of
/// the shell and cones, beyond a trunnion plate, or inside a lifter bar. Empty inside.
std::string leak_of(const Mill3D& mill, const Vec3& centre) {
  const double rho = std::sqrt(centre[0] * centre[0] + centre[1] * centre[1]);
  if (rho > mill.radius) return "outside the shell";
  const double s = std::max(-centre[2], centre[2] - mill.length);
  if (s > 0.0) {
    if (s > mill.cone_length) return "beyond a trunnion plate";
    if ((mill.radius - rho) * std::sin(mill.cone_angle) - s * std::cos(mill.cone_angle) < 0.0) {
      return "outside a cone";
    }
    return {};
  }
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

TEST(ConicalMillWall, FastImpactsOnConesTrunnionsAndLifterEndsNeverLeak) {
  // 4 000 shots, one ball each, in the conical lab mill turning at 8 rad/s (1.7 × critical),
  // as the flat mill's leak test: each aims at a random point within 5 mm of a feature of the
  // ends — the rim where shell meets cone, the rim where cone meets trunnion plate, the cone's
  // face, the plate near the axis, a lifter's end face and its corners — at 0.5 to 20 m/s
  // relative to the wall, spinning at up to 50 rad/s, under gravity, for 0.02 s (154 steps
  // of the engine's default 1.30e-4 s). The centre must never leave the mill's free space.
  const ContactMaterial ball_ball{4.0e5, 3.0e5, 0.6, 0.6};
  const ContactMaterial ball_wall{4.0e5, 3.0e5, 0.5, 0.6};
  const double ball_mass = 7800.0 * pi / 6.0 * 0.0508 * 0.0508 * 0.0508;
  WorldSettings<3> settings;
  settings.time_step = std::min(contact_duration(ball_ball, reduced_mass(ball_mass, ball_mass)),
                                contact_duration(ball_wall, ball_mass)) /
                       steps_per_contact;
  settings.gravity = Vec3{{0.0, -standard_gravity, 0.0}};
  settings.ball_ball = ball_ball;
  settings.ball_wall = ball_wall;
  constexpr int shots = 4000;
  constexpr int steps_per_shot = 154;
  constexpr double angular_speed = 8.0;
  std::mt19937_64 random(20261201);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const auto random_unit = [&] {
    for (;;) {
      const Vec3 v{
          {2.0 * uniform(random) - 1.0, 2.0 * uniform(random) - 1.0, 2.0 * uniform(random) - 1.0}};
      const double length = norm(v);
      if (length > 0.1 && length <= 1.0) return v * (1.0 / length);
    }
  };
  int hits = 0;
  double fastest = 0.0;
  for (int shot = 0; shot < shots; ++shot) {
    const double angle = 2.0 * pi * uniform(random);
    const Mill3D mill = conical_mill(angle, angular_speed);
    const int side = uniform(random) < 0.5 ? 0 : 1;
    const auto feature = [&]() -> Vec3 {
      const double phi = 2.0 * pi * uniform(random);
      const int lifter = static_cast<int>(uniform(random) * lifter_count) % lifter_count;
      const Vec2 radial = mill.lifter_direction[static_cast<std::size_t>(lifter)];
      const Vec3 a{{radial[0], radial[1], 0.0}};
      const Vec3 b{{-radial[1], radial[0], 0.0}};
      const double end_z = side == 0 ? 0.0 : mill_length;
      switch (static_cast<int>(uniform(random) * 6.0)) {
        case 0:  // the rim between shell and cone
          return meridian_point(phi, shell_radius, 0.0, side);
        case 1:  // the rim between cone and trunnion plate
          return meridian_point(phi, trunnion, cone_length, side);
        case 2: {  // anywhere on the cone
          const double u = slant * uniform(random);
          return meridian_point(phi, shell_radius - u * cos_a, u * sin_a, side);
        }
        case 3:  // the trunnion plate
          return meridian_point(phi, trunnion * uniform(random), cone_length, side);
        case 4:  // a lifter's end face
          return (0.41 + 0.04 * uniform(random)) * a + (0.04 * uniform(random) - 0.02) * b +
                 Vec3{{0.0, 0.0, end_z}};
        default:  // a corner of a lifter's end
          return 0.41 * a + (uniform(random) < 0.5 ? -0.02 : 0.02) * b + Vec3{{0.0, 0.0, end_z}};
      }
    };
    Vec3 target{};
    Vec3 direction{};
    Vec3 start{};
    for (;;) {
      target = feature() + 0.005 * Vec3{{2.0 * uniform(random) - 1.0, 2.0 * uniform(random) - 1.0,
                                         2.0 * uniform(random) - 1.0}};
      direction = random_unit();
      start = target - (ball_radius + 0.005 * uniform(random)) * direction;
      WallContact<3> found[max_mill_contacts<3>];
      if (leak_of(mill, start).empty() && mill_contacts(mill, start, ball_radius, found) == 0) {
        break;
      }
    }
    const double speed = 0.5 + 19.5 * uniform(random);
    const Vec3 velocity =
        Vec3{{-angular_speed * target[1], angular_speed * target[0], 0.0}} + speed * direction;
    Walls<3> walls;
    walls.mill = mill;
    World<3> world(settings, walls);
    world.particles().add(start, ball_radius, ball_mass, velocity,
                          (50.0 * uniform(random)) * random_unit());
    bool hit = false;
    for (int n = 0; n < steps_per_shot; ++n) {
      world.step();
      const Vec3& centre = world.particles().position[0];
      const std::string leak = leak_of(*world.walls().mill, centre);
      ASSERT_TRUE(leak.empty()) << "shot " << shot << " step " << n << ": centre (" << centre[0]
                                << ", " << centre[1] << ", " << centre[2] << ") " << leak;
      WallContact<3> found[max_mill_contacts<3>];
      hit = hit || mill_contacts(*world.walls().mill, centre, ball_radius, found) > 0;
    }
    if (hit) {
      ++hits;
      fastest = std::max(fastest, speed);
    }
  }
  // Seen: all 4 000 hit a wall, the fastest at 19.9985 m/s.
  EXPECT_GT(hits, 0.9 * shots);
  EXPECT_GT(fastest, 19.5);
}

// ---- The charge and the config ----------------------------------------------------------------

TEST(ConicalMillCharge, CircleAreaBelowALevel) {
  const double r = 0.3;
  EXPECT_NEAR(circle_area_below(r, 0.0), 0.5 * pi * r * r, 1e-15);
  EXPECT_EQ(circle_area_below(r, -r), 0.0);
  EXPECT_NEAR(circle_area_below(r, r), pi * r * r, 1e-15);
  // Below a chord r/2 above the centre: the circle less the segment above it, r² (π/3 − √3/4).
  EXPECT_NEAR(circle_area_below(r, 0.5 * r), pi * r * r - r * r * (pi / 3.0 - std::sqrt(3.0) / 4.0),
              1e-15);
  EXPECT_NEAR(circle_area_below(r, -0.5 * r), r * r * (pi / 3.0 - std::sqrt(3.0) / 4.0), 1e-15);
}

TEST(ConicalMillCharge, ConeBedVolume) {
  // A bed at the centre (J = 1/2) fills half of every cross-section: half the frustum,
  // π c (R² + R r_t + r_t²) / 6.
  const double R = 0.45;
  const double r_t = 0.2;
  const double c = 0.12;
  EXPECT_NEAR(cone_bed_volume(R, r_t, c, 0.5), pi * c * (R * R + R * r_t + r_t * r_t) / 6.0, 1e-12);
  // A "cone" that does not narrow is a cylinder: J of it, for any J.
  for (const double J : {0.1, 0.3, 0.45, 0.7}) {
    EXPECT_NEAR(cone_bed_volume(R, R, c, J), J * pi * R * R * c, 1e-12) << J;
  }
  // The narrowing cone holds less than J of its volume below a level under the centre (its
  // sections are smaller circles cut by the same chord), more above it.
  const double frustum = pi * c * (R * R + R * r_t + r_t * r_t) / 3.0;
  EXPECT_LT(cone_bed_volume(R, r_t, c, 0.3), 0.3 * frustum);
  EXPECT_GT(cone_bed_volume(R, r_t, c, 0.7), 0.7 * frustum);
}

/// MODEL.md Table 3's steel and no snapshots: the end of each config below.
constexpr const char* table3_materials_and_output = R"(
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
snapshot_interval = 0
)";

/// The conical lab mill as a config: case 3D-g's mill with 20°, 0.1 m cones.
const std::string conical_toml = R"([simulation]
dimension = 3
settle_time = 0.5
revolutions = 2
measure_revolutions = 1

[mill]
diameter = 0.9
length = 0.15
speed = 0.5
cone_angle = 20
cone_length = 0.1

[mill.lifters]
count = 8
height = 0.04
width = 0.04

[charge]
filling = 0.3
ball_diameter = 0.0508

)" + std::string(table3_materials_and_output);

TEST(ConicalMillCharge, ThePlanCountsTheBedInTheCones) {
  const MillPlan plan = plan_mill(parse_mill_config(conical_toml, "conical.toml"));
  EXPECT_NEAR(plan.trunnion_radius, trunnion, 1e-12);
  EXPECT_NEAR(plan.cone_volume,
              pi * cone_length *
                  (shell_radius * shell_radius + shell_radius * trunnion + trunnion * trunnion) /
                  3.0,
              1e-12);
  EXPECT_NEAR(plan.cone_bed_volume, cone_bed_volume(shell_radius, trunnion, cone_length, 0.3),
              1e-15);
  // And against an independent integration (midpoint rule, 10^5 slices, of the circle segment
  // below the bed's level in each cross-section of the cone): 7.70432e-3 m³.
  EXPECT_NEAR(plan.cone_bed_volume, 7.70432e-3, 1e-7);
  // ρ (1 − φ) (J π R² L + 2 V_bed) = 4680 × (0.028628 + 2 × 0.0077041) = 206.09 kg, 385 balls
  // of 0.53541 kg (the flat mill: 250).
  const double bed =
      0.3 * pi * shell_radius * shell_radius * mill_length + 2.0 * plan.cone_bed_volume;
  EXPECT_NEAR(plan.mill_charge_mass, 7800.0 * 0.6 * bed, 1e-9);
  EXPECT_EQ(plan.particle_count, 385);
  EXPECT_DOUBLE_EQ(plan.power_scale, 1.0);
}

std::string error_of(const std::string& text) {
  try {
    plan_mill(parse_mill_config(text, "conical.toml"));
  } catch (const InputError& error) {
    return error.what();
  }
  return "(accepted)";
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

void expect_has(const std::string& message, const std::vector<std::string>& parts) {
  for (const std::string& part : parts) {
    EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  }
}

TEST(ConicalMillConfig, BadConesAreRefusedNamingTheKey) {
  const std::string base = conical_toml;
  // Line numbers in conical_toml: dimension 2, cone_angle 11, cone_length 12.
  expect_has(error_of(replaced(base, "dimension = 3", "dimension = 2")),
             {"conical.toml:11", "mill.cone_angle", "simulation.dimension = 3"});
  expect_has(error_of(replaced(base, "speed = 0.5\n",
                               "speed = 0.5\nperiodic = true\n"
                               "slab_length = 0.15\n")),
             {"mill.cone_angle", "mill.periodic = true", "only for a whole mill"});
  expect_has(error_of(replaced(base, "cone_length = 0.1\n", "")), {"mill.cone_length", "together"});
  expect_has(error_of(replaced(base, "cone_angle = 20\n", "")), {"mill.cone_angle", "together"});
  expect_has(error_of(replaced(base, "cone_angle = 20", "cone_angle = 90")),
             {"conical.toml:11", "mill.cone_angle", "> 0 and < 90"});
  // tan 20° × 0.45 m = 0.16379 m: a longer cone would reach the axis.
  expect_has(error_of(replaced(base, "cone_length = 0.1", "cone_length = 0.17")),
             {"conical.toml:12", "mill.cone_length", "< 0.1637866 ", "reach the axis"});
  // The limit in as few digits as keep it below the true one: to four it read "< 0.1638",
  // which 0.1638 seemed to meet.
  expect_has(error_of(replaced(base, "cone_length = 0.1", "cone_length = 0.1638")),
             {"conical.toml:12", "mill.cone_length", "< 0.1637866 "});
  // Shorter than that, but the trunnion narrower than a ball: (0.45 − 0.0254) tan 20° =
  // 0.15454176 m at most (the meridian-plane contact sees one side of the axis only).
  expect_has(error_of(replaced(base, "cone_length = 0.1", "cone_length = 0.163786")),
             {"conical.toml:12", "mill.cone_length", "trunnion radius of 1.66",
              "at most 0.15454176 ", "0.0254 m"});
  expect_has(error_of(replaced(base, "cone_length = 0.1", "cone_length = 0.154542")),
             {"conical.toml:12", "mill.cone_length", "at most 0.15454176 "});
  EXPECT_GT(
      plan_mill(parse_mill_config(replaced(base, "cone_length = 0.1", "cone_length = 0.15454176"),
                                  "conical.toml"))
          .particle_count,
      0);
  expect_has(error_of(replaced(base, "cone_length = 0.1", "cone_length = \"long\"")),
             {"conical.toml:12", "mill.cone_length"});
  expect_has(error_of(replaced(base, "length = 0.15", "length = 0.04")),
             {"mill.length", "too short for balls", "at least 1.1 largest ball diameters"});
}

// ---- A running conical mill --------------------------------------------------------------------

TEST(ConicalMill, ChargeFillsTheConesAndTheEnergyAccountCloses) {
  // A small mill (0.5 m × 0.1 m, six 3 × 3 cm lifters, 25°, 0.06 m cones, 165 balls of 4 cm,
  // 60 % of critical) settled 0.5 s, turned two revolutions, the second measured, at the default
  // time step (what users run: seen 0.49 %, against the issue's 1 %; 0.12 % at half the step, as
  // the flat mill's energy test falls with the step). The settled charge lies inside the mill and
  // partly in the cones, the shell's work equals the change of energy plus what is dissipated,
  // and the two powers agree.
  const std::string text = R"([simulation]
dimension = 3
settle_time = 0.5
revolutions = 2
measure_revolutions = 1

[mill]
diameter = 0.5
length = 0.1
speed = 0.6
cone_angle = 25
cone_length = 0.06

[mill.lifters]
count = 6
height = 0.03
width = 0.03

[charge]
filling = 0.3
ball_diameter = 0.04

)" + std::string(table3_materials_and_output);
  const MillPlan plan = plan_mill(parse_mill_config(text, "small-conical.toml"));
  ASSERT_EQ(plan.particle_count, 165);
  World<3> world = build_mill_world<3>(plan);
  while (world.time() + 0.5 * plan.time_step < plan.config.settle_time) world.step();
  const Mill3D& mill = *world.walls().mill;
  int in_cones = 0;
  for (const Vec3& x : world.particles().position) {
    EXPECT_EQ(leak_of(mill, x), "") << x[0] << " " << x[1] << " " << x[2];
    if (x[2] < 0.0 || x[2] > mill.length) ++in_cones;
  }
  // Their share of the bed at rest is 2 × 0.001658 m³ of 0.005890 + 0.003316 m³, 36 %, i.e.
  // 59 of the 165 balls (seen: 61). The bound leaves room for seeds and packing.
  EXPECT_GT(in_cones, 45);
  EXPECT_LT(in_cones, 75);
  const MillResult r = run_mill<3>(plan, std::move(world), {});
  testing::expect_energy_account_closes(r);
  EXPECT_GT(r.power_kw, 0.1);
}

}  // namespace
}  // namespace millsim
