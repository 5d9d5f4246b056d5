// The linear spring–dashpot contact law with Coulomb friction of MODEL.md §3.
#pragma once

#include <algorithm>
#include <cmath>

#include "millsim/contact/contact.hpp"
#include "millsim/core/lanes.hpp"
#include "millsim/particles/material.hpp"

namespace millsim {

/// The dashpot coefficients of one contact, c = 2 ζ sqrt(k m*). They depend on the effective
/// mass alone: World works out a wall contact's once per particle at each neighbour-list
/// rebuild, and a pair's when it touches, from the two masses it has at hand (a per-pair array
/// made at each rebuild missed the cache, bench/results.md).
template <class T>
struct ContactDampingOf {
  T normal{};      ///< c_n, N s/m
  T tangential{};  ///< c_s, N s/m
};
using ContactDamping = ContactDampingOf<double>;

/// Stateless: its members are parameters, all state lives in the ContactHistory it is given.
/// Particle–particle and particle–wall contacts use this same law; only the inputs differ.
/// It is written once for a number type T: double for one contact, Lanes (core/lanes.hpp) for
/// several at once, each lane getting the same bits a double would. Hence no branches: where the
/// contact breaks or slips, both outcomes are worked out and the right one chosen.
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
        half_tangential_compliance_(0.5 / material.tangential_stiffness),
        friction_(material.friction),
        allow_tension_(allow_tension) {}

  double normal_stiffness() const { return normal_stiffness_; }
  double tangential_stiffness() const { return tangential_stiffness_; }

  /// Energy held by the springs of a contact, J: F_n²/(2 k_n) + |F_s|²/(2 k_s).
  template <int D>
  double stored_energy(const ContactHistory<D>& history, double overlap) const {
    const double spring =
        std::max(0.0, normal_stiffness_ * (overlap - history.normal_spring_origin));
    double tangential_squared = 0.0;
    if constexpr (D == 2) {
      tangential_squared = history.tangential_spring * history.tangential_spring;
    } else {
      tangential_squared = norm_squared(history.tangential_spring);
    }
    return spring * spring / (2.0 * normal_stiffness_) +
           tangential_squared / (2.0 * tangential_stiffness_);
  }

  /// c_n = 2 ζ sqrt(k_n) sqrt(m*) and c_s = 2 ζ sqrt(k_s) sqrt(m*) for effective mass m*.
  template <class T>
  [[gnu::always_inline]] ContactDampingOf<T> damping(T effective_mass) const {
    const T sqrt_mass = lane_sqrt(effective_mass);
    return {splat<T>(2.0 * damping_ratio_ * sqrt_normal_stiffness_) * sqrt_mass,
            splat<T>(2.0 * damping_ratio_ * sqrt_tangential_stiffness_) * sqrt_mass};
  }

  template <int D>
  ContactOutput<D> evaluate(const ContactInput<D>& in, ContactHistory<D>& history,
                            double time_step) const {
    return evaluate(in, damping(in.effective_mass), history, time_step);
  }

  /// The same with the dashpot coefficients given (from damping(in.effective_mass)).
  /// Always inlined: the pair and wall loops call it once per contact (or four) and step, the
  /// inputs and outputs then stay in registers, and Lanes never cross a call (core/vec.hpp).
  template <int D, class T>
  [[gnu::always_inline]] ContactOutput<D, T> evaluate(const ContactInput<D, T>& in,
                                                      const ContactDampingOf<T>& damping,
                                                      ContactHistory<D, T>& history,
                                                      double time_step) const {
    if constexpr (D == 2) {
      return evaluate_2d(in, damping, history, time_step);
    } else {
      return evaluate_3d(in, damping, history, time_step);
    }
  }

 private:
  /// 2D: the tangential spring is a signed length along the tangent t (contact.hpp), so that
  /// R, turning it with the normal, is exact and free, and the Coulomb cap a comparison of
  /// lengths: the same law as evaluate_3d's, with no square root, and no division on the way to
  /// the force (the energy accounts still divide by 2 k).
  template <class T>
  [[gnu::always_inline]] ContactOutput<2, T> evaluate_2d(const ContactInput<2, T>& in,
                                                         const ContactDampingOf<T>& damping,
                                                         ContactHistory<2, T>& history,
                                                         double time_step) const {
    using V = Vec<2, T>;
    const T dt = splat<T>(time_step);
    const T k_n = splat<T>(normal_stiffness_);
    const T k_s = splat<T>(tangential_stiffness_);
    const V& n = in.normal;
    const V t = tangent_of(n);
    const T normal_speed = dot(in.velocity, n);                // v·n < 0 while the pair approaches
    const T sliding = dot(in.velocity, t) + in.spin_velocity;  // v_s = sliding t
    const T step_sliding = dot(in.step_velocity, t) + in.step_spin_velocity;

    // Normal: spring k_n (δ − origin) and dashpot D_n = −c_n v_n, c_n = 2 ζ sqrt(k_n m*).
    const T normal_damping = damping.normal;
    const T normal_spring = k_n * (in.overlap - history.normal_spring_origin);
    const T normal_force = normal_spring - normal_damping * normal_speed;

    // R(F_s): the stored length along the tangent, which has turned with the normal.
    const T spring_before = history.tangential_spring;

    // No tension (as in evaluate_3d).
    const Mask<T> breaks = allow_tension_ ? Mask<T>{} : normal_force <= 0.0;
    const T held = select(T{} < normal_spring, normal_spring, T{});  // max(0, spring)
    T broken_dissipated{};
    if (any(breaks)) {
      broken_dissipated = held * held / (2.0 * k_n) + spring_before * spring_before / (2.0 * k_s);
    }
    const T dashpot_dissipated = normal_damping * normal_speed * normal_speed * dt;

    // Tangential spring and dashpot, capped at μ F_N as a whole (as in evaluate_3d); slipping,
    // the force is μ F_N with the trial force's sign, carried by the spring alone.
    const T spring = spring_before - k_s * (dt * step_sliding);
    const T friction_limit = splat<T>(friction_) * lane_abs(normal_force);
    const T tangential_damping = damping.tangential;
    const T trial = spring - tangential_damping * sliding;
    const Mask<T> slips = lane_abs(trial) > friction_limit;
    const T slipping_spring = lane_copysign(friction_limit, trial);
    const T slipping_dissipated =
        dashpot_dissipated + (-dt * (slipping_spring * sliding) +
                              (spring_before * spring_before - slipping_spring * slipping_spring) *
                                  splat<T>(half_tangential_compliance_));
    const T sticking_dissipated =
        dashpot_dissipated + tangential_damping * (sliding * sliding) * dt;
    const T tangential = select(slips, slipping_spring, trial);
    return conclude(in, history, {breaks, slips}, normal_force, tangential * t,
                    {broken_dissipated, slipping_dissipated, sticking_dissipated},
                    select(slips, slipping_spring, spring));
  }

  template <class T>
  [[gnu::always_inline]] ContactOutput<3, T> evaluate_3d(const ContactInput<3, T>& in,
                                                         const ContactDampingOf<T>& damping,
                                                         ContactHistory<3, T>& history,
                                                         double time_step) const {
    constexpr int D = 3;
    using V = Vec<D, T>;
    const T dt = splat<T>(time_step);
    const T k_n = splat<T>(normal_stiffness_);
    const T k_s = splat<T>(tangential_stiffness_);
    const V& n = in.normal;
    const T normal_speed = dot(in.velocity, n);  // v·n < 0 while the pair approaches
    const V sliding_velocity = in.velocity - normal_speed * n + in.spin_velocity;  // v_s
    const V step_sliding_velocity =
        in.step_velocity - dot(in.step_velocity, n) * n + in.step_spin_velocity;

    // Normal: spring k_n (δ − origin) and dashpot D_n = −c_n v_n, c_n = 2 ζ sqrt(k_n m*).
    const T normal_damping = damping.normal;
    const T normal_spring = k_n * (in.overlap - history.normal_spring_origin);
    const T normal_force = normal_spring - normal_damping * normal_speed;

    // R(F_s): turn the stored tangential spring into the current tangent plane, keeping its
    // length (a first-order rotation).
    const V stored = history.tangential_spring;
    const T spring_length_squared = norm_squared(stored);
    const V projected_spring = stored - dot(stored, n) * n;
    const T projected = norm_squared(projected_spring);
    const T rescale = select(projected > 0.0, lane_sqrt(spring_length_squared / projected), T{});
    V spring = select(spring_length_squared > 0.0, projected_spring * rescale, stored);

    // No tension: where the total normal force would pull, the contact breaks and forgets its
    // springs; what they held is lost.
    const Mask<T> breaks = allow_tension_ ? Mask<T>{} : normal_force <= 0.0;
    const T held = select(T{} < normal_spring, normal_spring, T{});  // max(0, spring)
    // Worked out only where some contact breaks, which few do in a step: its two divisions cost
    // as much as the rest of the law's arithmetic (the divider is what the law waits on).
    T broken_dissipated{};
    if (any(breaks)) {
      broken_dissipated = held * held / (2.0 * k_n) + norm_squared(spring) / (2.0 * k_s);
    }
    const T dashpot_dissipated = normal_damping * normal_speed * normal_speed * dt;  // |D_n·v_n| Δt

    // Tangential spring F_s ← R(F_s) − k_s v_s Δt, dashpot D_s = −c_s v_s. Coulomb: when the
    // trial tangential force F_s + D_s exceeds μ F_N (F_N the total normal force) the contact
    // slips: the force is μ F_N along the trial force, carried by the spring alone (dashpot
    // dropped). Capping the whole force, not only the spring, keeps the friction impulse at
    // most μ times the normal one: at the touch of an oblique impact the spring is still small
    // while the dashpot already carries c_s times the whole incoming slip.
    const V spring_before = spring;
    const V step_slip = dt * step_sliding_velocity;  // Δs, B relative to A
    spring -= k_s * step_slip;
    const T friction_limit = splat<T>(friction_) * lane_abs(normal_force);
    const T tangential_damping = damping.tangential;
    const V trial = spring - tangential_damping * sliding_velocity;
    // Compared squared. (The root below is needed only where the contact slips, but without
    // branches every contact works it out; in lanes it costs one instruction for four.)
    const T trial_length_squared = norm_squared(trial);
    const Mask<T> slips = trial_length_squared > friction_limit * friction_limit;
    // Slipping. The friction work is the work the force does against the slip at the time
    // of the positions (the work the leapfrog update sees, as for the dashpots) less what the
    // spring took up: −F_t·v_s Δt − (|F_s|² − |F_s,before|²) / (2 k_s). (With the half-step
    // slip instead, every slipping step books F_t·a_s Δt²/2 too much, a sum that does not
    // cancel: 4 % of the power of a 3D mill.) In steady sliding it is μ F_N |v_s| Δt.
    const V slipping_spring = trial * (friction_limit / lane_sqrt(trial_length_squared));
    const T slipping_dissipated =
        dashpot_dissipated + (-dt * dot(slipping_spring, sliding_velocity) +
                              (norm_squared(spring_before) - norm_squared(slipping_spring)) *
                                  splat<T>(half_tangential_compliance_));
    // Sticking: the dashpot dissipates c_s |v_s|² Δt.
    const T sticking_dissipated =
        dashpot_dissipated + tangential_damping * norm_squared(sliding_velocity) * dt;
    const V tangential_force = select(slips, slipping_spring, trial);
    return conclude(in, history, {breaks, slips}, normal_force, tangential_force,
                    {broken_dissipated, slipping_dissipated, sticking_dissipated},
                    select(slips, slipping_spring, spring));
  }

  /// Which way a contact went: it broke (no tension), or it slips.
  template <class T>
  struct Outcome {
    Mask<T> breaks;
    Mask<T> slips;
  };
  /// The energy it dissipated this step if it broke, slipped or stuck.
  template <class T>
  struct Dissipated {
    T broken;
    T slipping;
    T sticking;
  };
  /// The law's last part in 2D and 3D: the force (none where the contact broke) and the
  /// energy of its outcome; the history forgets the springs where it broke and keeps the
  /// tangential spring `kept` otherwise.
  template <int D, class T>
  [[gnu::always_inline]] static ContactOutput<D, T> conclude(
      const ContactInput<D, T>& in, ContactHistory<D, T>& history, const Outcome<T>& outcome,
      T normal_force, const Vec<D, T>& tangential_force, const Dissipated<T>& dissipated,
      const SpinOf<D, T>& kept) {
    ContactOutput<D, T> out;
    out.tangential_force = select(outcome.breaks, Vec<D, T>{}, tangential_force);
    out.force = select(outcome.breaks, Vec<D, T>{}, normal_force * in.normal + tangential_force);
    out.dissipated = select(outcome.breaks, dissipated.broken,
                            select(outcome.slips, dissipated.slipping, dissipated.sticking));
    history.normal_spring_origin = select(outcome.breaks, in.overlap, history.normal_spring_origin);
    history.tangential_spring = select(outcome.breaks, SpinOf<D, T>{}, kept);
    history.dissipated += out.dissipated;
    return out;
  }

  double normal_stiffness_;
  double tangential_stiffness_;
  double damping_ratio_;
  double sqrt_normal_stiffness_;
  double sqrt_tangential_stiffness_;
  /// 1 / (2 k_s): the energy a slipping contact's spring gives up is worked out for every
  /// contact (without branches), and multiplying by it spares the divider, which the law waits
  /// on, one of its operations in every step (the last bit of that energy may differ from a
  /// division's; the forces do not depend on it).
  double half_tangential_compliance_;
  double friction_;
  bool allow_tension_;
};

}  // namespace millsim
