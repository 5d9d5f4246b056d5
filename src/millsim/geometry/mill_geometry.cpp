#include <algorithm>
#include <cmath>

#include "millsim/core/constants.hpp"
#include "millsim/geometry/walls.hpp"

namespace millsim {
namespace {

/// Contact of a disc with lifter `index`, a rectangle that in the lifter's own frame (radial
/// axis a, tangential axis b) spans a ∈ [R − h, R + h], b ∈ [−w/2, w/2]; the part beyond the
/// shell (a > R) is out of reach and only closes the shape. Returns false when not touching.
bool lifter_contact(const Mill2D& mill, int index, const Vec2& centre, double particle_radius,
                    WallContact<2>& contact) {
  const Vec2 radial = mill.lifter_direction[static_cast<std::size_t>(index)];
  const Vec2 tangential{{-radial[1], radial[0]}};
  const double a = dot(centre, radial);
  const double b = dot(centre, tangential);
  const double inner = mill.radius - mill.lifter_height;
  const double outer = mill.radius + mill.lifter_height;
  const double half_width = 0.5 * mill.lifter_width;

  const double closest_a = std::clamp(a, inner, outer);
  const double closest_b = std::clamp(b, -half_width, half_width);
  double normal_a = a - closest_a;
  double normal_b = b - closest_b;
  double point_a = closest_a;
  double point_b = closest_b;
  const double distance = std::hypot(normal_a, normal_b);
  if (distance > 0.0) {
    if (distance >= particle_radius) return false;
    normal_a /= distance;
    normal_b /= distance;
    contact.overlap = particle_radius - distance;
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

int mill_contacts(const Mill2D& mill, const Vec2& centre, double particle_radius,
                  WallContact<2>* out) {
  int count = 0;
  const double distance = norm(centre);
  if (distance + particle_radius > mill.radius && distance > 0.0) {
    WallContact<2>& shell = out[count++];
    const Vec2 outward = centre * (1.0 / distance);
    shell.wall_id = 0;
    shell.kind = WallKind::shell;
    shell.normal = -outward;
    shell.overlap = distance + particle_radius - mill.radius;
    shell.point = mill.radius * outward;
    shell.wall_velocity = cross(mill.angular_speed, shell.point);
  }
  if (mill.lifter_count == 0 || distance + particle_radius <= mill.radius - mill.lifter_height) {
    return count;
  }
  // A disc can only reach the lifter nearest to it by angle and that lifter's two neighbours:
  // any lifter further round lies behind one of those.
  const double spacing = 2.0 * pi / mill.lifter_count;
  const double relative = std::atan2(centre[1], centre[0]) - mill.angle;
  const int nearest = static_cast<int>(std::lround(relative / spacing));
  const int reach = std::min(1, (mill.lifter_count - 1) / 2);
  const int last = mill.lifter_count == 2 ? nearest + 1 : nearest + reach;
  for (int k = nearest - reach; k <= last; ++k) {
    const int index = ((k % mill.lifter_count) + mill.lifter_count) % mill.lifter_count;
    if (lifter_contact(mill, index, centre, particle_radius, out[count])) ++count;
  }
  return count;
}

}  // namespace millsim
