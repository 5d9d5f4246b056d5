// The walls particles touch: a turning mill (shell and lifters) and fixed planes.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "millsim/core/vec.hpp"

namespace millsim {

enum class WallKind : std::uint8_t { shell, lifter, plane };

/// One particle–wall contact, as seen from the wall.
template <int D>
struct WallContact {
  int wall_id = -1;  ///< 0 the shell, 1..n the lifters, then the planes
  WallKind kind = WallKind::shell;
  Vec<D> normal{};         ///< unit, from the wall into the particle
  double overlap = 0.0;    ///< m
  Vec<D> point{};          ///< contact point on the wall, m
  Vec<D> wall_velocity{};  ///< velocity of the wall at that point, m/s
};

/// A cylindrical shell about the origin with equally spaced rectangular lifters, turning
/// counter-clockwise (seen from the front, gravity down) at angular_speed.
struct Mill2D {
  double radius = 0.0;  ///< inside the shell, m
  int lifter_count = 0;
  double lifter_height = 0.0;  ///< radial, m
  double lifter_width = 0.0;   ///< tangential, m
  double angle = 0.0;          ///< shell orientation, rad (lifter 0 sits at this angle)
  double angular_speed = 0.0;  ///< ω, rad/s
  /// Unit radial vector of each lifter at `angle`; refreshed by turn_to() (sin and cos once a
  /// step instead of once a contact).
  std::vector<Vec2> lifter_direction;

  /// Sets the shell orientation and the lifter directions that follow from it.
  void turn_to(double new_angle);
};

/// An infinite plane (a line in 2D): the particle side is where (x − point)·normal > 0.
template <int D>
struct Plane {
  Vec<D> point{};
  Vec<D> normal{};
};

template <int D>
struct Walls {
  std::optional<Mill2D> mill;
  std::vector<Plane<D>> planes;

  int wall_count() const {
    return (mill ? 1 + mill->lifter_count : 0) + static_cast<int>(planes.size());
  }
  /// False when no wall can come within `margin` of the particle, however the mill turns: it
  /// then needs no wall search until it has moved `margin` (the contact search's skin).
  bool may_touch(const Vec<D>& centre, double particle_radius, double margin) const;
  /// Calls emit(const WallContact<D>&) for every wall the particle overlaps.
  template <typename Emit>
  void for_each_contact(const Vec<D>& centre, double particle_radius, Emit&& emit) const;
};

/// Closest-feature contact of a disc with the mill; in mill_geometry.cpp.
/// Writes at most 4 contacts (shell and up to three lifters) and returns how many.
int mill_contacts(const Mill2D& mill, const Vec2& centre, double particle_radius,
                  WallContact<2>* out);

template <int D>
bool Walls<D>::may_touch(const Vec<D>& centre, double particle_radius, double margin) const {
  const double reach = particle_radius + margin;
  if constexpr (D == 2) {
    if (mill) {
      // Lifters sweep the ring between R − h and R as the mill turns.
      const double inner = mill->radius - (mill->lifter_count > 0 ? mill->lifter_height : 0.0);
      if (norm(centre) + reach > inner) return true;
    }
  }
  for (const Plane<D>& plane : planes) {
    if (dot(centre - plane.point, plane.normal) < reach) return true;
  }
  return false;
}

template <int D>
template <typename Emit>
void Walls<D>::for_each_contact(const Vec<D>& centre, double particle_radius, Emit&& emit) const {
  int id_offset = 0;
  if constexpr (D == 2) {
    if (mill) {
      WallContact<2> found[4];
      const int count = mill_contacts(*mill, centre, particle_radius, found);
      for (int k = 0; k < count; ++k) emit(found[k]);
      id_offset = 1 + mill->lifter_count;
    }
  }
  for (std::size_t p = 0; p < planes.size(); ++p) {
    const Plane<D>& plane = planes[p];
    const double distance = dot(centre - plane.point, plane.normal);
    if (distance >= particle_radius) continue;
    WallContact<D> contact;
    contact.wall_id = id_offset + static_cast<int>(p);
    contact.kind = WallKind::plane;
    contact.normal = plane.normal;
    contact.overlap = particle_radius - distance;
    contact.point = centre - distance * plane.normal;
    emit(contact);
  }
}

}  // namespace millsim
