// What every contact law sees and returns, and the history a contact carries between steps.
#pragma once

#include "millsim/core/vec.hpp"

namespace millsim {

/// Remembered from step to step while two bodies overlap (MODEL.md §3).
template <int D>
struct ContactHistory {
  /// Overlap at which the normal spring was last (re)started: F_n,spring = k_n (δ − origin).
  /// This is the incremental normal spring F_n ← F_n − k_n (v·n) Δt integrated exactly.
  double normal_spring_origin = 0.0;
  Vec<D> tangential_spring{};  ///< F_s, kept perpendicular to the current normal
  double dissipated = 0.0;     ///< energy dissipated since the bodies first touched, J
  double overlap = 0.0;        ///< δ at the last evaluation, m (for the stored-energy account)
};

/// Geometry and relative motion of one contact, body B relative to body A.
template <int D>
struct ContactInput {
  Vec<D> normal{};       ///< unit vector from A towards B (from a wall into the particle)
  double overlap = 0.0;  ///< δ > 0, m
  /// u̇_B − u̇_A at the time of the positions (for a wall: minus the wall's velocity there);
  /// the dashpots use it.
  Vec<D> velocity{};
  Vec<D> spin_velocity{};  ///< n × (r_A ω_A + r_B ω_B) at that time: rotation's part of v_s
  /// The same two over the last step (leapfrog half-step velocities): the tangential spring
  /// grows by the sliding displacement they make, so that it is the exact integral of it.
  Vec<D> step_velocity{};
  Vec<D> step_spin_velocity{};
  /// m* = m_A m_B / (m_A + m_B); m of the particle for a wall. Read only by the evaluate()
  /// that works out the dashpot coefficients itself; World passes them precomputed.
  double effective_mass = 0.0;
};

/// What a law returns: the force on B (A gets the opposite), its tangential part (the one that
/// makes torques) and the energy it dissipated during this step.
template <int D>
struct ContactOutput {
  Vec<D> force{};
  Vec<D> tangential_force{};
  double dissipated = 0.0;  ///< J, this step
};

}  // namespace millsim
