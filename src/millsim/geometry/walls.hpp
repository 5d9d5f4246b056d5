// The walls particles touch: a turning mill (shell and lifters) and fixed planes.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <type_traits>
#include <vector>

#include "millsim/core/vec.hpp"

namespace millsim {

enum class WallKind : std::uint8_t { shell, lifter, end_plate, plane };

/// One particle–wall contact, as seen from the wall.
template <int D>
struct WallContact {
  /// 0 the shell, 1..n the lifters, in 3D then the end walls unless the mill is periodic
  /// (n + 1 at z = 0 and n + 2 at z = length: the flat plates or the cones; with cones, n + 3
  /// and n + 4 their trunnion plates), then the planes
  int wall_id = -1;
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

/// A 3D mill: the cross-section of Mill2D (shell, lifters, angle, speed) extruded along the
/// axis z from 0 to `length`, the lifters running its full length. With end plates it is a
/// whole mill; periodic, it is an axial slab whose ends wrap round (the World does the
/// wrapping) and has no end plates.
///
/// The ends are flat discs at z = 0 and z = length, or, with cone_length > 0, cones: each end
/// is a conical wall from the shell (radius R at z = 0, or z = length) to the trunnion radius
/// R − cone_length / tan(cone_angle) at cone_length beyond, closed there by a flat plate.
/// cone_angle is the angle between the cone and the plane of a flat end. Everything turns
/// with the shell. The lifters stop at the ends of the cylinder.
struct Mill3D : Mill2D {
  double length = 0.0;  ///< m, of the cylinder (between the cones, if any)
  bool periodic = false;
  double cone_length = 0.0;  ///< m along the axis, each end; 0 for flat ends
  double cone_angle = 0.0;   ///< rad, between the cone and the plane of a flat end

  bool has_cones() const { return !periodic && cone_length > 0.0; }
  /// Radius of the flat plate that closes a cone (the trunnion), m.
  double trunnion_radius() const {
    return has_cones() ? radius - cone_length / std::tan(cone_angle) : radius;
  }
  /// End walls: none (periodic), two flat plates, or two cones and their two trunnion plates.
  int end_plate_count() const { return periodic ? 0 : has_cones() ? 4 : 2; }
};

/// The mill type of each dimension.
template <int D>
using MillShape = std::conditional_t<D == 2, Mill2D, Mill3D>;

/// The lifters a particle may touch for a while, found once so that each step tests those
/// alone instead of looking up the nearest lifter by angle and testing it and its two
/// neighbours (World keeps one per wall candidate: see World::refresh_nearby_lifters).
struct NearbyLifters {
  static constexpr int capacity = 3;
  std::array<std::int16_t, capacity> index{};  ///< in the order the full search visits them
  /// How many of `index` are in use; `unknown` when they were not found (too few lifters,
  /// too many within reach, or never looked up): the step then searches as usual.
  std::int8_t count = unknown;
  static constexpr std::int8_t unknown = -1;
};

/// The lifters within `reach` of a centre (distance from the centre to the bar < reach), or
/// NearbyLifters::unknown. Every lifter a particle of radius r can touch while it stays within
/// d of `planar_centre` and the mill turns its lifters by at most s (arc length at the shell)
/// is among those within r + d + s. In mill_geometry.cpp.
NearbyLifters nearby_lifters(const Mill2D& mill, const Vec2& planar_centre, double reach);

/// The widest particle whose lifter contacts are all among those the contact search tests (the
/// lifter nearest the particle by angle and its two neighbours: mill_contacts), for `count` ≥ 4
/// lifters of the given height and width in a shell of `radius`. A particle nearest lifter k
/// has its centre within π/n of k's middle, so at least 3π/n from lifter k + 2's (and k − 2's);
/// the distance from such a centre to that lifter is least on the ray 3π/n off its middle
/// (it grows with the angle), where it is ρ sin(3π/n − β) to the lifter's inner corner,
/// ρ = hypot(R − h, w/2) from the axis at β = atan(w/2 / (R − h)) off its middle, or R − h,
/// from the axis (the ray starts there), whichever is less; once the ray turns away from that
/// corner (3π/n − β > π/2), R − h. (With five wide lifters, R − h is the less.) Twice that is
/// the widest particle. plan_mill refuses a mill whose largest ball is wider. In mill_geometry.cpp.
double widest_particle_for_lifters(double radius, int count, double height, double width);

/// An infinite plane (a line in 2D): the particle side is where (x − point)·normal > 0.
template <int D>
struct Plane {
  Vec<D> point{};
  Vec<D> normal{};
};

template <int D>
struct Walls {
  std::optional<MillShape<D>> mill;
  std::vector<Plane<D>> planes;

  int mill_wall_count() const {
    if (!mill) return 0;
    if constexpr (D == 3) return 1 + mill->lifter_count + mill->end_plate_count();
    return 1 + mill->lifter_count;
  }
  int wall_count() const { return mill_wall_count() + static_cast<int>(planes.size()); }
  /// The kind of wall `wall_id` (as numbered in WallContact).
  WallKind kind_of(int wall_id) const {
    if (wall_id >= mill_wall_count()) return WallKind::plane;
    if (wall_id == 0) return WallKind::shell;
    return wall_id <= mill->lifter_count ? WallKind::lifter : WallKind::end_plate;
  }
  /// False when no wall can come within `margin` of the particle, however the mill turns: it
  /// then needs no wall search until it has moved `margin` (the contact search's skin).
  bool may_touch(const Vec<D>& centre, double particle_radius, double margin) const;
  /// Calls emit(const WallContact<D>&) for every wall the particle overlaps. With `nearby`
  /// known, only those lifters are tested (see NearbyLifters); the contacts and their order
  /// are the same.
  template <typename Emit>
  void for_each_contact(const Vec<D>& centre, double particle_radius, Emit&& emit,
                        const NearbyLifters* nearby = nullptr) const;
  /// The same contacts in the same order, written into `out` (room for max_contacts()); returns
  /// how many. The wall stage's way: each contact is made where the contact law reads it.
  int contacts_of(const Vec<D>& centre, double particle_radius, WallContact<D>* out,
                  const NearbyLifters* nearby = nullptr) const;
  /// Most contacts one particle can have with these walls.
  std::size_t max_contacts() const;
};

/// Closest-feature contact of a disc with the mill; in mill_geometry.cpp.
/// Writes at most 4 contacts (shell and up to three lifters) and returns how many. With
/// `nearby` known (nearby_lifters() of a centre near enough), only those lifters are tested.
int mill_contacts(const Mill2D& mill, const Vec2& centre, double particle_radius,
                  WallContact<2>* out, const NearbyLifters* nearby = nullptr);
/// The same for a sphere in a 3D mill: the shell, up to three lifters (rectangular prisms,
/// touched on a face, an edge or a corner, whichever is closest) and the walls of the end it
/// is at (a flat plate, or a cone and its trunnion plate). Writes at most 6 contacts and
/// returns how many. `nearby` as in 2D.
int mill_contacts(const Mill3D& mill, const Vec3& centre, double particle_radius,
                  WallContact<3>* out, const NearbyLifters* nearby = nullptr);
/// Most wall contacts one particle can have with a mill (a 3D mill is at least one ball
/// diameter long, so a ball touches the walls of one end at most).
template <int D>
inline constexpr int max_mill_contacts = D == 2 ? 4 : 6;

template <int D>
bool Walls<D>::may_touch(const Vec<D>& centre, double particle_radius, double margin) const {
  const double reach = particle_radius + margin;
  if (mill) {
    // Lifters sweep the ring between R − h and R as the mill turns.
    const double inner = mill->radius - (mill->lifter_count > 0 ? mill->lifter_height : 0.0);
    if (std::sqrt(centre[0] * centre[0] + centre[1] * centre[1]) + reach > inner) return true;
    if constexpr (D == 3) {
      if (!mill->periodic && (centre[2] < reach || centre[2] > mill->length - reach)) return true;
    }
  }
  for (const Plane<D>& plane : planes) {
    if (dot(centre - plane.point, plane.normal) < reach) return true;
  }
  return false;
}

template <int D>
template <typename Emit>
void Walls<D>::for_each_contact(const Vec<D>& centre, double particle_radius, Emit&& emit,
                                const NearbyLifters* nearby) const {
  // One buffer per thread, grown once: a fresh array here was zeroed for every call.
  static thread_local std::vector<WallContact<D>> found;
  if (found.size() < max_contacts()) found.resize(max_contacts());
  const int count = contacts_of(centre, particle_radius, found.data(), nearby);
  for (int k = 0; k < count; ++k) emit(found[static_cast<std::size_t>(k)]);
}

template <int D>
int Walls<D>::contacts_of(const Vec<D>& centre, double particle_radius, WallContact<D>* out,
                          const NearbyLifters* nearby) const {
  // mill_contacts and the planes below write every field of each contact they report, so
  // nothing of an earlier call is read.
  int count = 0;
  int id_offset = 0;
  if (mill) {
    count = mill_contacts(*mill, centre, particle_radius, out, nearby);
    id_offset = mill_wall_count();
  }
  for (std::size_t p = 0; p < planes.size(); ++p) {
    const Plane<D>& plane = planes[p];
    const double distance = dot(centre - plane.point, plane.normal);
    if (distance >= particle_radius) continue;
    WallContact<D>& contact = out[count++];
    contact.wall_id = id_offset + static_cast<int>(p);
    contact.kind = WallKind::plane;
    contact.normal = plane.normal;
    contact.overlap = particle_radius - distance;
    contact.point = centre - distance * plane.normal;
    contact.wall_velocity = Vec<D>{};
  }
  return count;
}

template <int D>
std::size_t Walls<D>::max_contacts() const {
  return (mill ? static_cast<std::size_t>(max_mill_contacts<D>) : 0) + planes.size();
}

}  // namespace millsim
