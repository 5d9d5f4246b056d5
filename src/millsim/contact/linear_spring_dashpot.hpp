// The linear spring–dashpot contact law with Coulomb friction of MODEL.md §3.
#pragma once

#include <algorithm>
#include <cmath>

#include "millsim/contact/contact.hpp"
#include "millsim/particles/material.hpp"

namespace millsim {

/// The dashpot coefficients of one contact, c = 2 ζ sqrt(k m*). They depend on the effective
/// mass alone: World works out a wall contact's once per particle at each neighbour-list
/// rebuild, and a pair's when it touches, from the two masses it has at hand (a per-pair array
/// made at each rebuild missed the cache, bench/results.md).
struct ContactDamping {
  double normal = 0.0;      ///< c_n, N s/m
  double tangential = 0.0;  ///< c_s, N s/m
};

/// Stateless: its members are parameters, all state lives in the ContactHistory it is given.
/// Particle–particle and particle–wall contacts use this same law; only the inputs differ.
class LinearSpringDashpot {
 public:
  /// allow_tension = false is the model of MODEL.md (the total normal force never pulls; the
  /// contact forgets its springs when it would). true lets the dashpot pull at the end of an
  /// impact, the case for which Corkum's relation is exact; tests use it to check that relation.
  explicit LinearSpringDashpot(const ContactMaterial& material, bool allow_tension = false)
      : normal_stiffness_(material.normal_stiffness),
        tangential_stiffness_(material.tangential_stiffness),
        damping_ratio_(damping_ratio(material.restitution)),
        sqrt_normal_stiffness_(std::sqrt(material.normal_stiffness)),
        sqrt_tangential_stiffness_(std::sqrt(material.tangential_stiffness)),
        friction_(material.friction),
        allow_tension_(allow_tension) {}

  double normal_stiffness() const { return normal_stiffness_; }
  double tangential_stiffness() const { return tangential_stiffness_; }

  /// Energy held by the springs of a contact, J: F_n²/(2 k_n) + |F_s|²/(2 k_s).
  template <int D>
  double stored_energy(const ContactHistory<D>& history, double overlap) const {
    const double spring =
        std::max(0.0, normal_stiffness_ * (overlap - history.normal_spring_origin));
    return spring * spring / (2.0 * normal_stiffness_) +
           norm_squared(history.tangential_spring) / (2.0 * tangential_stiffness_);
  }

  /// c_n = 2 ζ sqrt(k_n) sqrt(m*) and c_s = 2 ζ sqrt(k_s) sqrt(m*) for effective mass m*.
  ContactDamping damping(double effective_mass) const {
    const double sqrt_mass = std::sqrt(effective_mass);
    return {2.0 * damping_ratio_ * sqrt_normal_stiffness_ * sqrt_mass,
            2.0 * damping_ratio_ * sqrt_tangential_stiffness_ * sqrt_mass};
  }

  template <int D>
  ContactOutput<D> evaluate(const ContactInput<D>& in, ContactHistory<D>& history,
                            double time_step) const {
    return evaluate(in, damping(in.effective_mass), history, time_step);
  }

  /// The same with the dashpot coefficients given (from damping(in.effective_mass)).
  /// Always inlined: the pair and wall loops call it once per contact and step, and the
  /// inputs and outputs then stay in registers.
  template <int D>
  ContactOutput<D> evaluate(const ContactInput<D>& in, const ContactDamping& damping,
                            ContactHistory<D>& history, double time_step) const {
    const Vec<D>& n = in.normal;
    const double normal_speed = dot(in.velocity, n);  // v·n < 0 while the pair approaches
    const Vec<D> sliding_velocity = in.velocity - normal_speed * n + in.spin_velocity;  // v_s
    const Vec<D> step_sliding_velocity =
        in.step_velocity - dot(in.step_velocity, n) * n + in.step_spin_velocity;

    // Normal: spring k_n (δ − origin) and dashpot D_n = −c_n v_n, c_n = 2 ζ sqrt(k_n m*).
    const double normal_damping = damping.normal;
    const double normal_spring = normal_stiffness_ * (in.overlap - history.normal_spring_origin);
    const double normal_force = normal_spring - normal_damping * normal_speed;

    // R(F_s): turn the stored tangential spring into the current tangent plane, keeping its
    // length (in 2D this is the exact rotation; in 3D a first-order one).
    Vec<D> spring = history.tangential_spring;
    const double spring_length_squared = norm_squared(spring);
    if (spring_length_squared > 0.0) {
      spring -= dot(spring, n) * n;
      const double projected = norm_squared(spring);
      spring *= projected > 0.0 ? std::sqrt(spring_length_squared / projected) : 0.0;
    }

    ContactOutput<D> out;
    if (normal_force <= 0.0 && !allow_tension_) {
      // No tension: the contact breaks and forgets its springs; what they held is lost.
      const double held = std::max(0.0, normal_spring);
      out.dissipated = held * held / (2.0 * normal_stiffness_) +
                       norm_squared(spring) / (2.0 * tangential_stiffness_);
      history.normal_spring_origin = in.overlap;
      history.tangential_spring = Vec<D>{};
      history.dissipated += out.dissipated;
      return out;
    }
    out.dissipated = normal_damping * normal_speed * normal_speed * time_step;  // |D_n·v_n| Δt

    // Tangential spring F_s ← R(F_s) − k_s v_s Δt, dashpot D_s = −c_s v_s. Coulomb: when the
    // trial tangential force F_s + D_s exceeds μ F_N (F_N the total normal force) the contact
    // slips: the force is μ F_N along the trial force, carried by the spring alone (dashpot
    // dropped). Capping the whole force, not only the spring, keeps the friction impulse at
    // most μ times the normal one: at the touch of an oblique impact the spring is still small
    // while the dashpot already carries c_s times the whole incoming slip.
    const Vec<D> spring_before = spring;
    const Vec<D> step_slip = time_step * step_sliding_velocity;  // Δs, B relative to A
    spring -= tangential_stiffness_ * step_slip;
    const double friction_limit = friction_ * std::abs(normal_force);
    const double tangential_damping = damping.tangential;
    const Vec<D> trial = spring - tangential_damping * sliding_velocity;
    // Compared squared, so that a sticking contact (most of them) needs no square root.
    const double trial_length_squared = norm_squared(trial);
    if (trial_length_squared > friction_limit * friction_limit) {
      // Slipping. The friction work is the work the force does against the slip at the time
      // of the positions (the work the leapfrog update sees, as for the dashpots) less what the
      // spring took up: −F_t·v_s Δt − (|F_s|² − |F_s,before|²) / (2 k_s). (With the half-step
      // slip instead, every slipping step books F_t·a_s Δt²/2 too much, a sum that does not
      // cancel: 4 % of the power of a 3D mill.) In steady sliding it is μ F_N |v_s| Δt.
      spring = trial * (friction_limit / std::sqrt(trial_length_squared));
      out.tangential_force = spring;
      out.dissipated +=
          -time_step * dot(spring, sliding_velocity) +
          (norm_squared(spring_before) - norm_squared(spring)) / (2.0 * tangential_stiffness_);
    } else {
      out.tangential_force = trial;
      out.dissipated += tangential_damping * norm_squared(sliding_velocity) * time_step;
    }
    history.tangential_spring = spring;
    history.dissipated += out.dissipated;
    out.force = normal_force * n + out.tangential_force;
    return out;
  }

 private:
  double normal_stiffness_;
  double tangential_stiffness_;
  double damping_ratio_;
  double sqrt_normal_stiffness_;
  double sqrt_tangential_stiffness_;
  double friction_;
  bool allow_tension_;
};

}  // namespace millsim
