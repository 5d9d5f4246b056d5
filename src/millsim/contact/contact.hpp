// What every contact law sees and returns, and the history a contact carries between steps.
#pragma once

#include "millsim/core/vec.hpp"

namespace millsim {

// Each holds one contact's values in doubles (T = double), or those of several contacts, one per
// lane (T = Lanes, core/lanes.hpp), for the law's evaluation of several contacts at once.

/// Remembered from step to step while two bodies overlap (MODEL.md §3).
template <int D, class T = double>
struct ContactHistory {
  /// Overlap at which the normal spring was last (re)started: F_n,spring = k_n (δ − origin).
  /// This is the incremental normal spring F_n ← F_n − k_n (v·n) Δt integrated exactly.
  T normal_spring_origin{};
  /// F_s. In 3D the force, kept perpendicular to the current normal. In 2D its signed length
  /// along the tangent t = tangent_of(n) (the force is F_s t): it turns with the normal
  /// exactly, with no length to restore.
  SpinOf<D, T> tangential_spring{};
  T dissipated{};  ///< energy dissipated since the bodies first touched, J
};

/// Geometry and relative motion of one contact, body B relative to body A.
template <int D, class T = double>
struct ContactInput {
  Vec<D, T> normal{};  ///< unit vector from A towards B (from a wall into the particle)
  T overlap{};         ///< δ > 0, m
  /// u̇_B − u̇_A at the time of the positions (for a wall: minus the wall's velocity there);
  /// the dashpots use it.
  Vec<D, T> velocity{};
  /// Rotation's part of v_s at that time, as spin_sliding(n, r_A ω_A + r_B ω_B) gives it: in 3D
  /// the vector n × (r_A ω_A + r_B ω_B); in 2D the scalar r_A ω_A + r_B ω_B, the velocity being
  /// that times the tangent.
  SpinOf<D, T> spin_velocity{};
  /// The same two over the last step (leapfrog half-step velocities): the tangential spring
  /// grows by the sliding displacement they make, so that it is the exact integral of it.
  Vec<D, T> step_velocity{};
  SpinOf<D, T> step_spin_velocity{};
  /// m* = m_A m_B / (m_A + m_B); m of the particle for a wall. Read only by the evaluate()
  /// that works out the dashpot coefficients itself; World passes them precomputed.
  T effective_mass{};
};

/// The tangent of a 2D contact of normal n: t = (n_y, −n_x), the direction in which a positive
/// spin s about +z moves the contact point (n × s = s t).
template <class T>
[[gnu::always_inline]] constexpr Vec<2, T> tangent_of(const Vec<2, T>& n) {
  return Vec<2, T>{{n[1], -n[0]}};
}

/// The sliding velocity that the spins make at a contact of normal n, as ContactInput holds
/// it, from s = r_A ω_A + r_B ω_B: s itself in 2D, n × s in 3D.
template <int D, class T>
[[gnu::always_inline]] constexpr SpinOf<D, T> spin_sliding(const Vec<D, T>& n,
                                                           const SpinOf<D, T>& s) {
  if constexpr (D == 2) {
    return s;
  } else {
    return cross(n, s);
  }
}

/// What a law returns: the force on B (A gets the opposite), its tangential part (the one that
/// makes torques) and the energy it dissipated during this step.
template <int D, class T = double>
struct ContactOutput {
  Vec<D, T> force{};
  Vec<D, T> tangential_force{};
  T dissipated{};  ///< J, this step
};

}  // namespace millsim
