#include <algorithm>
#include <cmath>

#include "millsim/core/constants.hpp"
#include "millsim/geometry/walls.hpp"

namespace millsim {
namespace {

/// Closest point of lifter `index` to a particle centre, in the lifter's own frame: radial
/// axis a, tangential axis b (and the mill axis z in 3D). The bar spans a ∈ [R − h, R + h],
/// b ∈ [−w/2, w/2] (the part beyond the shell, a > R, is out of reach and only closes the
/// shape) and, with end plates, z ∈ [0, L]. Clamping each coordinate to the bar gives the
/// closest point on a face, an edge or a corner, whichever it is. `axial` is the particle's
/// distance along z from the bar (0 when it is beside it or the mill is periodic); the normal's
/// component along it, axial / distance, goes to `axial_normal` if given.
bool lifter_contact(const Mill2D& mill, int index, const Vec2& planar_centre, double axial,
                    double particle_radius, WallContact<2>& contact,
                    double* axial_normal = nullptr) {
  const Vec2 radial = mill.lifter_direction[static_cast<std::size_t>(index)];
  const Vec2 tangential{{-radial[1], radial[0]}};
  const double a = dot(planar_centre, radial);
  const double b = dot(planar_centre, tangential);
  const double inner = mill.radius - mill.lifter_height;
  const double outer = mill.radius + mill.lifter_height;
  const double half_width = 0.5 * mill.lifter_width;

  const double closest_a = std::clamp(a, inner, outer);
  const double closest_b = std::clamp(b, -half_width, half_width);
  double normal_a = a - closest_a;
  double normal_b = b - closest_b;
  double point_a = closest_a;
  double point_b = closest_b;
  // sqrt rather than hypot: no overflow is possible at mill scales, and hypot is slow.
  const double planar_distance = std::sqrt(normal_a * normal_a + normal_b * normal_b);
  const double distance = std::sqrt(planar_distance * planar_distance + axial * axial);
  if (distance >= particle_radius) return false;
  if (planar_distance > 0.0) {
    // The in-plane part of the normal; the caller adds the axial part for an end edge.
    normal_a /= distance;
    normal_b /= distance;
    contact.overlap = particle_radius - distance;
    if (axial_normal != nullptr) *axial_normal = axial / distance;
  } else if (axial > 0.0) {
    // Beyond the bar's end, level with its end face: the normal is along the axis, exactly (the
    // distance may be next to nothing, and the overlap r − distance then rounds to r).
    contact.overlap = particle_radius - distance;
    if (axial_normal != nullptr) *axial_normal = 1.0;
  } else {
    // Centre inside the bar (only after a violent step): push out through the nearest face.
    const double to_inner_face = a - inner;
    const double to_side_face = half_width - std::abs(b);
    if (to_inner_face <= to_side_face) {
      normal_a = -1.0;
      normal_b = 0.0;
      point_a = inner;
      contact.overlap = particle_radius + to_inner_face;
    } else {
      normal_a = 0.0;
      normal_b = b >= 0.0 ? 1.0 : -1.0;
      point_b = normal_b * half_width;
      contact.overlap = particle_radius + to_side_face;
    }
  }
  contact.wall_id = 1 + index;
  contact.kind = WallKind::lifter;
  contact.normal = normal_a * radial + normal_b * tangential;
  contact.point = point_a * radial + point_b * tangential;
  contact.wall_velocity = cross(mill.angular_speed, contact.point);
  return true;
}

/// atan2(y, x) to within 2e-8 rad, several times cheaper than std::atan2: the polynomial of
/// Abramowitz & Stegun 4.4.49, atan t = t (1 + a₂ t² + … + a₁₆ t¹⁶) for |t| ≤ 1, taken of
/// min(|x|, |y|) / max(|x|, |y|) and turned into the right octant.
double approximate_atan2(double y, double x) {
  const double ax = std::abs(x);
  const double ay = std::abs(y);
  const double larger = std::max(ax, ay);
  if (larger == 0.0) return 0.0;
  const double t = std::min(ax, ay) / larger;
  const double s = t * t;
  constexpr double a[] = {-0.3333314528, 0.1999355085, -0.1420889944, 0.1065626393,
                          -0.0752896400, 0.0429096138, -0.0161657367, 0.0028662257};
  double series = a[7];
  for (int k = 6; k >= 0; --k) series = series * s + a[k];
  double angle = t + t * s * series;
  if (ay > ax) angle = 0.5 * pi - angle;
  if (x < 0.0) angle = pi - angle;
  return y < 0.0 ? -angle : angle;
}

/// The lifters a particle at `planar_centre` may touch: the one nearest to it by angle and
/// that lifter's two neighbours (any lifter further round is out of reach of particles no
/// wider than widest_particle_for_lifters, which plan_mill checks). Calls
/// visit(index) for each. The nearest one is found from an approximate angle: it can differ
/// from the exact one's only for a centre within 2e-8 rad of half-way between two lifters,
/// which then touches neither of the two lifters beyond them that the choice decides between.
template <typename Visit>
void for_each_nearby_lifter(const Mill2D& mill, const Vec2& planar_centre, Visit&& visit) {
  const double spacing = 2.0 * pi / mill.lifter_count;
  const double relative = approximate_atan2(planar_centre[1], planar_centre[0]) - mill.angle;
  const double turns = relative / spacing;  // rounded half away from zero, as std::lround does
  const int nearest = static_cast<int>(turns + (turns >= 0.0 ? 0.5 : -0.5));
  const int reach = std::min(1, (mill.lifter_count - 1) / 2);
  const int last = mill.lifter_count == 2 ? nearest + 1 : nearest + reach;
  for (int k = nearest - reach; k <= last; ++k) {
    visit(((k % mill.lifter_count) + mill.lifter_count) % mill.lifter_count);
  }
}

/// The lifters to test for a particle at `planar_centre`: `nearby`'s if known, else those of
/// for_each_nearby_lifter.
template <typename Visit>
void for_each_lifter_to_test(const Mill2D& mill, const Vec2& planar_centre,
                             const NearbyLifters* nearby, Visit&& visit) {
  if (nearby != nullptr && nearby->count != NearbyLifters::unknown) {
    for (int k = 0; k < nearby->count; ++k) visit(static_cast<int>(nearby->index[k]));
    return;
  }
  for_each_nearby_lifter(mill, planar_centre, visit);
}

/// Contact with the shell, a circle (2D) or a cylinder (3D) of radius R about the z axis.
bool shell_contact(const Mill2D& mill, const Vec2& planar_centre, double particle_radius,
                   WallContact<2>& shell) {
  const double distance = norm(planar_centre);
  if (distance + particle_radius <= mill.radius || distance <= 0.0) return false;
  const Vec2 outward = planar_centre * (1.0 / distance);
  shell.wall_id = 0;
  shell.kind = WallKind::shell;
  shell.normal = -outward;
  shell.overlap = distance + particle_radius - mill.radius;
  shell.point = mill.radius * outward;
  shell.wall_velocity = cross(mill.angular_speed, shell.point);
  return true;
}

bool beyond_lifter_reach(const Mill2D& mill, const Vec2& planar_centre, double particle_radius) {
  return mill.lifter_count == 0 ||
         norm(planar_centre) + particle_radius <= mill.radius - mill.lifter_height;
}

/// With conical ends the shell is the cylinder 0 ≤ z ≤ length only. A centre beyond an end of
/// it is in front of the cone (shell_rim_contact) unless it has been pushed out through the
/// corner, beyond the cone's extent (past the line through the rim along the cone's normal);
/// the shell then sends it back.
bool on_shell_side(const Mill3D& mill, const Vec2& planar_centre, double z) {
  if (!mill.has_cones() || (z >= 0.0 && z <= mill.length)) return true;
  const double beyond = z < 0.0 ? -z : z - mill.length;
  return norm(planar_centre) - mill.radius > beyond * std::tan(mill.cone_angle);
}

/// The shell's contact with a centre in front of a cone (beyond an end of the cylinder, not
/// on_shell_side): the shell's closest point is then its rim, where the cone begins. The shell–
/// cone corner is concave, so a sphere pressed into the cone near it can reach over the rim
/// into the shell; the contact begins with no overlap as the rim comes within r, and as the
/// centre crosses the rim's plane into the cylinder it becomes the shell's contact with no
/// jump. A centre pushed out through the cone's face (behind it) gets none: the cone sends it
/// back.
bool shell_rim_contact(const Mill3D& mill, const Vec2& planar_centre, double z,
                       double particle_radius, WallContact<3>& contact) {
  const double rho = norm(planar_centre);
  const double beyond = z < 0.0 ? -z : z - mill.length;  // > 0: not on_shell_side
  const double in_front_of_cone =
      (mill.radius - rho) * std::sin(mill.cone_angle) - beyond * std::cos(mill.cone_angle);
  if (in_front_of_cone < 0.0 || rho <= 0.0) return false;
  const double rim_z = z < 0.0 ? 0.0 : mill.length;
  const double radial = rho - mill.radius;  // ≤ 0 in front of the cone
  const double axial = z - rim_z;
  const double distance = std::hypot(radial, axial);
  if (distance >= particle_radius || distance <= 0.0) return false;
  const Vec2 outward = planar_centre * (1.0 / rho);
  contact.wall_id = 0;
  contact.kind = WallKind::shell;
  contact.normal =
      Vec3{{radial / distance * outward[0], radial / distance * outward[1], axial / distance}};
  contact.overlap = particle_radius - distance;
  const Vec2 point = mill.radius * outward;
  contact.point = Vec3{{point[0], point[1], rim_z}};
  const Vec2 velocity = cross(mill.angular_speed, point);
  contact.wall_velocity = Vec3{{velocity[0], velocity[1], 0.0}};
  return true;
}

/// A 3D contact from the in-plane one found on the cross-section, at height z, written into
/// `contact` field by field. (Returned by value, it was made in a zeroed temporary and copied
/// in pieces wider than the stores that had just made them, which the processor cannot forward:
/// bench/results.md.)
void extrude(const WallContact<2>& planar, double z, WallContact<3>& contact) {
  contact.wall_id = planar.wall_id;
  contact.kind = planar.kind;
  contact.normal = Vec3{{planar.normal[0], planar.normal[1], 0.0}};
  contact.overlap = planar.overlap;
  contact.point = Vec3{{planar.point[0], planar.point[1], z}};
  contact.wall_velocity = Vec3{{planar.wall_velocity[0], planar.wall_velocity[1], 0.0}};
}

/// A contact with an end wall of a 3D mill, a surface of revolution about the z axis, from
/// its closest point in the meridian plane of the centre: `radial` and `axial` are that point's
/// distance from the axis and its z, (normal_radial, normal_axial) the unit normal from the
/// wall into the particle in that plane, `outward` the unit radial direction of the centre.
WallContact<3> end_wall_contact(const Mill3D& mill, int wall_id, const Vec2& outward, double radial,
                                double axial, double normal_radial, double normal_axial,
                                double overlap) {
  WallContact<3> contact;
  contact.wall_id = wall_id;
  contact.kind = WallKind::end_plate;
  contact.normal = Vec3{{normal_radial * outward[0], normal_radial * outward[1], normal_axial}};
  contact.overlap = overlap;
  contact.point = Vec3{{radial * outward[0], radial * outward[1], axial}};
  const Vec2 velocity = cross(mill.angular_speed, Vec2{{contact.point[0], contact.point[1]}});
  contact.wall_velocity = Vec3{{velocity[0], velocity[1], 0.0}};
  return contact;
}

/// Contacts with the conical end of a 3D mill on `side` (0: beyond z = 0, 1: beyond z =
/// length): the cone and the trunnion plate that closes it. Works in the meridian plane of the
/// centre, in coordinates (ρ, s): ρ the distance from the axis, s the distance beyond the end
/// of the cylinder. The cone runs from (R, 0) to (r_t, c) along d = (−cos α, sin α), its
/// inward normal is (−sin α, −cos α); the plate is s = c for ρ ≤ r_t. Each face's contact is
/// with its closest point to the centre: the foot on the face where the foot lies across it,
/// else its rim (the shell–cone or the cone–plate corner) for a centre inside the mill. Only a
/// centre pushed out beyond the cone–plate corner (by a violent step) is sent back towards the
/// corner itself, by the plate.
int cone_contacts(const Mill3D& mill, int side, const Vec3& centre, double particle_radius,
                  WallContact<3>* out) {
  const double rho = std::sqrt(centre[0] * centre[0] + centre[1] * centre[1]);
  const double s = side == 0 ? -centre[2] : centre[2] - mill.length;
  // Beyond z = 0 the outward axial direction is −z, beyond z = length it is +z.
  const double axial_sign = side == 0 ? -1.0 : 1.0;
  const double end_z = side == 0 ? 0.0 : mill.length;
  const Vec2 outward = rho > 0.0 ? Vec2{{centre[0] / rho, centre[1] / rho}} : Vec2{{1.0, 0.0}};
  const double sin_a = std::sin(mill.cone_angle);
  const double cos_a = std::cos(mill.cone_angle);
  const double c = mill.cone_length;
  const double r_t = mill.trunnion_radius();
  const double slant = c / sin_a;
  const int cone_id = 1 + mill.lifter_count + side;
  const int plate_id = cone_id + 2;
  int count = 0;

  // Along the cone from the shell, and the signed distance from it (positive inside).
  const double along = -(rho - mill.radius) * cos_a + s * sin_a;
  const double inside_cone = -(rho - mill.radius) * sin_a - s * cos_a;
  const double inside_plate = c - s;
  // A face's rim (radial, beyond) as the closest point of a centre in front of the face's
  // neighbour whose foot on the face's line falls past the rim: its contact, if within reach.
  // The corners of the profile are concave, so a sphere pressed into one face near a corner can
  // reach over the rim of the next; the contact begins with no overlap, and it becomes the
  // face's own contact with no jump as the foot crosses onto the face.
  const auto rim_contact = [&](int wall_id, double radial, double beyond) {
    const double to_radial = rho - radial;
    const double to_beyond = s - beyond;
    const double distance = std::hypot(to_radial, to_beyond);
    if (distance >= particle_radius || distance <= 0.0) return;
    out[count++] = end_wall_contact(mill, wall_id, outward, radial, end_z + axial_sign * beyond,
                                    to_radial / distance, axial_sign * to_beyond / distance,
                                    particle_radius - distance);
  };
  if (along >= 0.0 && along <= slant) {
    if (inside_cone < particle_radius) {
      out[count++] = end_wall_contact(mill, cone_id, outward, mill.radius - along * cos_a,
                                      end_z + axial_sign * along * sin_a, -sin_a,
                                      -axial_sign * cos_a, particle_radius - inside_cone);
    }
  } else if (along < 0.0 && rho <= mill.radius) {
    rim_contact(cone_id, mill.radius, 0.0);  // in the cylinder, near the shell's rim
  } else if (along > slant && rho <= r_t && inside_plate >= 0.0) {
    rim_contact(cone_id, r_t, c);  // in front of the plate, near its rim
  }
  if (rho <= r_t) {
    if (inside_plate < particle_radius) {
      out[count++] = end_wall_contact(mill, plate_id, outward, rho, end_z + axial_sign * c, 0.0,
                                      -axial_sign, particle_radius - inside_plate);
    }
  } else if (along <= slant && inside_cone >= 0.0 && inside_plate >= 0.0) {
    rim_contact(plate_id, r_t, c);  // in front of the cone, near the plate's rim
  }
  if (along > slant && rho > r_t) {
    // Beyond the corner between cone and plate: outside the mill (see above).
    const double to_corner_radial = r_t - rho;
    const double to_corner_axial = c - s;
    const double distance =
        std::sqrt(to_corner_radial * to_corner_radial + to_corner_axial * to_corner_axial);
    out[count++] = end_wall_contact(
        mill, plate_id, outward, r_t, end_z + axial_sign * c, to_corner_radial / distance,
        axial_sign * to_corner_axial / distance, particle_radius + distance);
  }
  return count;
}

}  // namespace

void Mill2D::turn_to(double new_angle) {
  angle = new_angle;
  lifter_direction.resize(static_cast<std::size_t>(lifter_count));
  for (int k = 0; k < lifter_count; ++k) {
    const double lifter_angle = angle + 2.0 * pi * k / lifter_count;
    lifter_direction[static_cast<std::size_t>(k)] =
        Vec2{{std::cos(lifter_angle), std::sin(lifter_angle)}};
  }
}

double widest_particle_for_lifters(double radius, int count, double height, double width) {
  const double inner = radius - height;
  const double half_width = 0.5 * width;
  const double corner_radius = std::hypot(inner, half_width);
  const double corner_angle = std::atan2(half_width, inner);
  // The nearest lifter is found from an approximate angle, within 2e-8 rad of the exact one
  // (for_each_nearby_lifter): the ray is taken that much nearer.
  constexpr double angle_error = 1e-7;
  const double off_corner = 3.0 * pi / count - angle_error - corner_angle;
  // The ray starts at the axis, R − h from the lifter's inner face: never further than that.
  const double half =
      off_corner <= 0.5 * pi ? std::min(inner, corner_radius * std::sin(off_corner)) : inner;
  return 2.0 * half;
}

NearbyLifters nearby_lifters(const Mill2D& mill, const Vec2& planar_centre, double reach) {
  NearbyLifters nearby;
  const int lifters = mill.lifter_count;
  // With fewer than five lifters the full search's three may wrap round onto each other.
  if (lifters < 5) return nearby;
  if (beyond_lifter_reach(mill, planar_centre, reach)) {
    nearby.count = 0;
    return nearby;
  }
  // A centre within `reach` of a lifter is at least `closest` from the axis, and within an
  // angle asin((w/2 + reach) / closest) of the lifter's axis (its offset across the bar is
  // ρ sin φ, at most w/2 + reach); the nearest lifter by angle is within half a spacing.
  const double closest = mill.radius - mill.lifter_height - reach;
  if (closest <= 0.0) return nearby;
  const double across = (0.5 * mill.lifter_width + reach) / closest;
  if (across >= 1.0) return nearby;
  const double spacing = 2.0 * pi / lifters;
  const int window = static_cast<int>(std::lround(std::asin(across) / spacing)) + 1;
  if (2 * window + 1 >= lifters) return nearby;
  const double relative = approximate_atan2(planar_centre[1], planar_centre[0]) - mill.angle;
  const double turns = relative / spacing;
  const int nearest = static_cast<int>(turns + (turns >= 0.0 ? 0.5 : -0.5));
  int count = 0;
  for (int k = nearest - window; k <= nearest + window; ++k) {
    const int index = ((k % lifters) + lifters) % lifters;
    WallContact<2> contact;
    if (!lifter_contact(mill, index, planar_centre, 0.0, reach, contact)) continue;
    if (count == NearbyLifters::capacity) return NearbyLifters{};
    nearby.index[static_cast<std::size_t>(count++)] = static_cast<std::int16_t>(index);
  }
  nearby.count = static_cast<std::int8_t>(count);
  return nearby;
}

int mill_contacts(const Mill2D& mill, const Vec2& centre, double particle_radius,
                  WallContact<2>* out, const NearbyLifters* nearby) {
  int count = 0;
  if (shell_contact(mill, centre, particle_radius, out[count])) ++count;
  if (nearby != nullptr && nearby->count == 0) return count;
  if (beyond_lifter_reach(mill, centre, particle_radius)) return count;
  for_each_lifter_to_test(mill, centre, nearby, [&](int index) {
    if (lifter_contact(mill, index, centre, 0.0, particle_radius, out[count])) ++count;
  });
  return count;
}

int mill_contacts(const Mill3D& mill, const Vec3& centre, double particle_radius,
                  WallContact<3>* out, const NearbyLifters* nearby) {
  int count = 0;
  const Vec2 planar{{centre[0], centre[1]}};
  const double z = centre[2];
  WallContact<2> found;
  if (shell_contact(mill, planar, particle_radius, found)) {
    if (on_shell_side(mill, planar, z)) {
      extrude(found, z, out[count++]);
    } else if (shell_rim_contact(mill, planar, z, particle_radius, out[count])) {
      ++count;
    }
  }
  if ((nearby == nullptr || nearby->count != 0) &&
      !beyond_lifter_reach(mill, planar, particle_radius)) {
    // Beyond an end of the bars (only while a sphere presses into an end plate) the closest
    // point is on the bar's end edge or corner, out of the plane of the centre.
    const double bar_z = mill.periodic ? z : std::clamp(z, 0.0, mill.length);
    const double axial = z - bar_z;
    for_each_lifter_to_test(mill, planar, nearby, [&](int index) {
      double axial_normal = 0.0;
      if (!lifter_contact(mill, index, planar, std::abs(axial), particle_radius, found,
                          &axial_normal)) {
        return;
      }
      WallContact<3>& contact = out[count++];
      extrude(found, bar_z, contact);
      if (axial != 0.0) contact.normal[2] = axial < 0.0 ? -axial_normal : axial_normal;
    });
  }
  if (mill.has_cones()) {
    // A cone is within reach only of a centre less than a radius from the end of the cylinder.
    if (z < particle_radius) count += cone_contacts(mill, 0, centre, particle_radius, out + count);
    if (z > mill.length - particle_radius && count < max_mill_contacts<3> - 1) {
      count += cone_contacts(mill, 1, centre, particle_radius, out + count);
    }
  } else if (!mill.periodic) {
    // End plates: flat discs at z = 0 (normal +z) and z = L (normal −z), turning with the shell.
    const int first_plate = 1 + mill.lifter_count;
    for (int side = 0; side < 2; ++side) {
      const double gap = side == 0 ? z : mill.length - z;
      if (gap >= particle_radius) continue;
      WallContact<3>& plate = out[count++];
      plate.wall_id = first_plate + side;
      plate.kind = WallKind::end_plate;
      plate.normal = Vec3{{0.0, 0.0, side == 0 ? 1.0 : -1.0}};
      plate.overlap = particle_radius - gap;
      plate.point = Vec3{{centre[0], centre[1], side == 0 ? 0.0 : mill.length}};
      const Vec2 velocity = cross(mill.angular_speed, planar);
      plate.wall_velocity = Vec3{{velocity[0], velocity[1], 0.0}};
    }
  }
  return count;
}

}  // namespace millsim
