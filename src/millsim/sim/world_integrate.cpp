// World's integration: each particle's forces summed (pairs, walls, gravity) and the particle
// advanced by leapfrog, with the next step's velocity estimates made in the same pass.

#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "millsim/sim/world.hpp"
#include "millsim/sim/world_detail.hpp"

namespace millsim {

using namespace world_detail;

template <int D>
template <class Body>
bool World<D>::for_each_particle_run(Body&& body) {
  const std::size_t count = particles_.size();
  bool any = false;
  if (count == neighbours_.built_count() && pairs_split_among_threads()) {
    const auto ranges = static_cast<std::size_t>(split_threads_);
#pragma omp parallel num_threads(split_threads_) reduction(|| : any)
    {
      const auto team = static_cast<std::size_t>(omp_get_num_threads());
      for (auto t = static_cast<std::size_t>(omp_get_thread_num()); t < ranges; t += team) {
        any = body(std::size_t{split_particle_[t]}, std::size_t{split_particle_[t + 1]}) || any;
      }
    }
    return any;
  }
#pragma omp parallel if (count >= parallel_threshold) reduction(|| : any)
  {
    const auto team = static_cast<std::size_t>(omp_get_num_threads());
    const auto t = static_cast<std::size_t>(omp_get_thread_num());
    any = body(count * t / team, count * (t + 1) / team);
  }
  return any;
}

template <int D>
bool World<D>::estimate_current_velocities() {
  const std::size_t count = particles_.size();
  velocity_now_.resize(count);
  rim_speed_now_.resize(count);
  if constexpr (keeps_step_rim) rim_speed_step_.resize(count);
  const double half_step = 0.5 * settings_.time_step;
  const auto& p = particles_;
  // Particles added since the last list: it must be made again.
  const bool added = count != neighbours_.built_count();
  const bool moved = for_each_particle_run([&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      velocity_now_[i] = estimate_now(p.velocity[i], p.inverse_mass[i], p.force[i], half_step);
      rim_speed_now_[i] = p.radius[i] * estimate_now(p.angular_velocity[i], p.inverse_inertia[i],
                                                     p.torque[i], half_step);
      if constexpr (keeps_step_rim) rim_speed_step_[i] = p.radius[i] * p.angular_velocity[i];
    }
    return !added && neighbours_.moved_too_far(p.position, begin, end);
  });
  return added || moved;
}

template <int D>
void World<D>::check_estimates_made() const {
#ifndef NDEBUG
  const double half_step = 0.5 * settings_.time_step;
  const auto& p = particles_;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec<D> velocity = estimate_now(p.velocity[i], p.inverse_mass[i], p.force[i], half_step);
    const Spin<D> spin =
        estimate_now(p.angular_velocity[i], p.inverse_inertia[i], p.torque[i], half_step);
    bool step_rim_kept = true;
    if constexpr (keeps_step_rim) {
      step_rim_kept = p.radius[i] * p.angular_velocity[i] == rim_speed_step_[i];
    }
    if (!(velocity == velocity_now_[i]) || !(p.radius[i] * spin == rim_speed_now_[i]) ||
        !step_rim_kept || (neighbours_.moved_too_far(i, p.position[i]) && !moved_half_skin_)) {
      std::fprintf(stderr,
                   "millsim: World::step: particle %zu was changed after the last step through a "
                   "reference to World::particles() kept from before it; ask particles() again "
                   "after each step\n",
                   i);
      std::abort();
    }
  }
#endif
}

template <int D>
bool World<D>::accumulate_forces_and_integrate() {
  // Each particle's forces are summed in a fixed order, so the sums are the same on every run
  // and thread count: its pairs in pair order, then walls (the pair and wall stages have added
  // them into force and torque), then gravity. Then the particle is advanced, in the same pass (one
  // read of its arrays instead of two): leapfrog u̇(n+½) = u̇(n−½) + ü(n) Δt,
  // u(n+1) = u(n) + u̇(n+½) Δt; the same for rotation. Still in the same pass, the next step's
  // estimates u̇(n+1) ≈ u̇(n+½) + ½ ü(n) Δt (as estimate_current_velocities makes them), and
  // whether the particle has moved half a skin since the neighbour list was made.
  return for_each_particle_run(
      [&](std::size_t begin, std::size_t end) { return integrate_run(begin, end); });
}

template <int D>
typename World<D>::IntegrationArrays World<D>::integration_arrays() {
  auto& p = particles_;
  return {.force = p.force.data(),
          .torque = p.torque.data(),
          .velocity = p.velocity.data(),
          .position = p.position.data(),
          .spin = p.angular_velocity.data(),
          .mass = p.mass.data(),
          .inverse_mass = p.inverse_mass.data(),
          .inverse_inertia = p.inverse_inertia.data(),
          .radius = p.radius.data(),
          .velocity_now = velocity_now_.data(),
          .rim_now = rim_speed_now_.data(),
          .rim_step = rim_speed_step_.data(),
          .reference = neighbours_.reference_position().data()};
}

template <int D>
bool World<D>::integrate_run(std::size_t begin, std::size_t end) {
#if defined(__x86_64__)
  if (avx2_lanes_) return integrate_particles_avx2(begin, end);
#endif
  if (neighbours_.period() > 0.0) return integrate_particles<true>(begin, end);
  return integrate_particles<false>(begin, end);
}

#if defined(__x86_64__)
namespace {

/// Four doubles from p, and back (unaligned).
[[gnu::always_inline]] inline Lanes load_four(const double* p) {
  Lanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
[[gnu::always_inline]] inline void store_four(double* p, Lanes v) {
  std::memcpy(p, &v, sizeof v);
}

/// Four spheres' 3D vectors side by side, as they lie in memory: x0 y0 z0 x1 | y1 z1 x2 y2 |
/// z2 x3 y3 z3.
struct FourVectors {
  Lanes part[3];
};
[[gnu::always_inline]] inline FourVectors load_vectors(const Vec3* p) {
  const double* d = p->c.data();
  return {{load_four(d), load_four(d + 4), load_four(d + 8)}};
}
[[gnu::always_inline]] inline void store_vectors(Vec3* p, const FourVectors& v) {
  double* d = p->c.data();
  store_four(d, v.part[0]);
  store_four(d + 4, v.part[1]);
  store_four(d + 8, v.part[2]);
}
/// One value per sphere spread over its three components: s0 s0 s0 s1 | s1 s1 s2 s2 | s2 s3 s3 s3.
[[gnu::always_inline]] inline FourVectors spread(Lanes s) {
  return {{__builtin_shufflevector(s, s, 0, 0, 0, 1), __builtin_shufflevector(s, s, 1, 1, 2, 2),
           __builtin_shufflevector(s, s, 2, 3, 3, 3)}};
}
/// a + s b, component by component, s spread as above.
[[gnu::always_inline]] inline FourVectors add_scaled(const FourVectors& a, const FourVectors& s,
                                                     const FourVectors& b) {
  return {{a.part[0] + s.part[0] * b.part[0], a.part[1] + s.part[1] * b.part[1],
           a.part[2] + s.part[2] * b.part[2]}};
}
/// s a, component by component, s spread as above.
[[gnu::always_inline]] inline FourVectors times(const FourVectors& s, const FourVectors& a) {
  return {{s.part[0] * a.part[0], s.part[1] * a.part[1], s.part[2] * a.part[2]}};
}

}  // namespace

template <int D>
bool World<D>::integrate_particles_avx2(std::size_t begin, std::size_t end) {
  if constexpr (D == 2) {
    // integrate_particles four discs at a time (a 2D world is never periodic): their vectors
    // are two registers as they lie in memory, x0 y0 x1 y1 | x2 y2 x3 y3, each disc's factors
    // spread over its two components, and its spins and rim speeds one register. Each
    // operation is the one the scalar loop does on each component, so the bits are the same.
    // The compiler's own vectorisation of the scalar loop took the vectors apart into x and y
    // registers and back (about thirty instructions a disc).
    const auto [force, torque, velocity, position, spin, mass, inverse_mass, inverse_inertia,
                radius, velocity_now, rim_now, rim_step, reference] = integration_arrays();
    const Lanes limit = splat<Lanes>(neighbours_.half_skin_squared());
    const Vec2 g = settings_.gravity;
    const Lanes gravity{g[0], g[1], g[0], g[1]};
    const Lanes dt = splat<Lanes>(settings_.time_step);
    const Lanes half_step = splat<Lanes>(0.5 * settings_.time_step);
    // One value per disc over its two components: s0 s0 s1 s1 | s2 s2 s3 s3.
    const auto low = [](Lanes s) __attribute__((always_inline)) {
      return __builtin_shufflevector(s, s, 0, 0, 1, 1);
    };
    const auto high = [](Lanes s) __attribute__((always_inline)) {
      return __builtin_shufflevector(s, s, 2, 2, 3, 3);
    };
    Mask<Lanes> moved{};
    std::size_t i = begin;
    for (; i + 4 <= end; i += 4) {
      const Lanes m = load_four(&mass[i]);
      const Lanes im = load_four(&inverse_mass[i]);
      const Lanes ii = load_four(&inverse_inertia[i]);
      const Lanes r = load_four(&radius[i]);
      // force += m g
      const Lanes f0 = load_four(force[i].c.data()) + low(m) * gravity;
      const Lanes f1 = load_four(force[i + 2].c.data()) + high(m) * gravity;
      store_four(force[i].c.data(), f0);
      store_four(force[i + 2].c.data(), f1);
      // u̇ += (m⁻¹ Δt) F, u += Δt u̇, ω += (I⁻¹ Δt) M
      const Lanes step = im * dt;
      const Lanes v0 = load_four(velocity[i].c.data()) + low(step) * f0;
      const Lanes v1 = load_four(velocity[i + 2].c.data()) + high(step) * f1;
      store_four(velocity[i].c.data(), v0);
      store_four(velocity[i + 2].c.data(), v1);
      const Lanes x0 = load_four(position[i].c.data()) + dt * v0;
      const Lanes x1 = load_four(position[i + 2].c.data()) + dt * v1;
      store_four(position[i].c.data(), x0);
      store_four(position[i + 2].c.data(), x1);
      const Lanes t = load_four(&torque[i]);
      const Lanes w = load_four(&spin[i]) + (ii * dt) * t;
      store_four(&spin[i], w);
      store_four(&rim_step[i], r * w);
      // The estimates, as estimate_now makes them.
      const Lanes ahead = half_step * im;
      store_four(velocity_now[i].c.data(), v0 + low(ahead) * f0);
      store_four(velocity_now[i + 2].c.data(), v1 + high(ahead) * f1);
      store_four(&rim_now[i], r * (w + (half_step * ii) * t));
      // Moved half a skin: each disc's dx² + dy², as norm_squared sums them.
      const Lanes d0 = x0 - load_four(reference[i].c.data());
      const Lanes d1 = x1 - load_four(reference[i + 2].c.data());
      const Lanes q0 = d0 * d0;
      const Lanes q1 = d1 * d1;
      const Lanes xs = __builtin_shufflevector(q0, q1, 0, 2, 4, 6);
      const Lanes ys = __builtin_shufflevector(q0, q1, 1, 3, 5, 7);
      moved |= xs + ys > limit;
    }
    bool any_moved = any(moved);
    if (i < end) any_moved = integrate_particles<false>(i, end) || any_moved;
    return any_moved;
  } else {
    // integrate_particles four spheres at a time: their vectors are three registers, each
    // operation the one the scalar loop does on each component (the per-sphere factors spread
    // over the components), so the bits are the same. The scalar loop, one sphere at a time
    // through SSE2 halves, was bound by its instructions (about ninety a sphere).
    const auto [force, torque, velocity, position, spin, mass, inverse_mass, inverse_inertia,
                radius, velocity_now, rim_now, rim_step, reference] = integration_arrays();
    const Lanes limit = splat<Lanes>(neighbours_.half_skin_squared());
    const Vec3 g = settings_.gravity;
    const FourVectors gravity{{Lanes{g[0], g[1], g[2], g[0]}, Lanes{g[1], g[2], g[0], g[1]},
                               Lanes{g[2], g[0], g[1], g[2]}}};
    const Lanes dt = splat<Lanes>(settings_.time_step);
    const Lanes half_step = splat<Lanes>(0.5 * settings_.time_step);
    // A periodic slab: each sphere's z (lane 2, 1, and 0 and 3 of the three registers) kept in
    // [0, period) as the scalar loop keeps it.
    const double period = neighbours_.period();
    const bool periodic = period > 0.0;
    const Lanes period_lanes = splat<Lanes>(period);
    const Lanes crossed_lanes = splat<Lanes>(0.49 * period);
    const std::array<Mask<Lanes>, 3> axial{{Lanes{0.0, 0.0, 1.0, 0.0} > 0.0,
                                            Lanes{0.0, 1.0, 0.0, 0.0} > 0.0,
                                            Lanes{1.0, 0.0, 0.0, 1.0} > 0.0}};
    constexpr std::size_t prefetch_distance = 12;
    const bool prefetch = prefetch_pairs_;
    const std::size_t last = particles_.size() - 1;
    Mask<Lanes> moved{};
    bool moved_one_by_one = false;
    std::size_t i = begin;
    for (; i + 4 <= end; i += 4) {
      if (prefetch) {
        for (const std::size_t ahead : {i + prefetch_distance, i + prefetch_distance + 2}) {
          const std::size_t a = std::min(ahead, last);
          __builtin_prefetch(&reference[a]);
          __builtin_prefetch(&position[a], 1);
          __builtin_prefetch(&velocity[a], 1);
          __builtin_prefetch(&spin[a], 1);
          __builtin_prefetch(&velocity_now[a], 1);
          __builtin_prefetch(&rim_now[a], 1);
        }
        const std::size_t a = std::min(i + prefetch_distance, last);
        __builtin_prefetch(&inverse_mass[a]);
        __builtin_prefetch(&inverse_inertia[a]);
      }
      const Lanes m = load_four(&mass[i]);
      const FourVectors r = spread(load_four(&radius[i]));
      const Lanes im = load_four(&inverse_mass[i]);
      const Lanes ii = load_four(&inverse_inertia[i]);
      FourVectors f = load_vectors(&force[i]);
      const FourVectors t = load_vectors(&torque[i]);
      // force += m g
      f = add_scaled(f, spread(m), gravity);
      store_vectors(&force[i], f);
      // u̇ += (m⁻¹ Δt) F, u += Δt u̇, ω += (I⁻¹ Δt) M
      const FourVectors v = add_scaled(load_vectors(&velocity[i]), spread(im * dt), f);
      store_vectors(&velocity[i], v);
      FourVectors x = add_scaled(load_vectors(&position[i]), spread(dt), v);
      if (periodic) {
        for (int k = 0; k < 3; ++k) {
          Lanes& z = x.part[k];
          z = select(axial[k] & (z < 0.0), z + period_lanes, z);
          z = select(axial[k] & (z >= period_lanes), z - period_lanes, z);
        }
      }
      store_vectors(&position[i], x);
      const FourVectors w = add_scaled(load_vectors(&spin[i]), spread(ii * dt), t);
      store_vectors(&spin[i], w);
      // The estimates, as estimate_now makes them.
      store_vectors(&velocity_now[i], add_scaled(v, spread(half_step * im), f));
      store_vectors(&rim_now[i], times(r, add_scaled(w, spread(half_step * ii), t)));
      // Moved half a skin: each sphere's (dx² + dy²) + dz², as norm_squared sums them.
      const FourVectors at_rebuild = load_vectors(&reference[i]);
      const Lanes d0 = x.part[0] - at_rebuild.part[0];
      const Lanes d1 = x.part[1] - at_rebuild.part[1];
      const Lanes d2 = x.part[2] - at_rebuild.part[2];
      if (periodic && any((axial[0] & (lane_abs(d0) >= crossed_lanes)) |
                          (axial[1] & (lane_abs(d1) >= crossed_lanes)) |
                          (axial[2] & (lane_abs(d2) >= crossed_lanes)))) {
        // A sphere has crossed an end since the list was made (rare): the nearest image's
        // offset, one by one, as NeighbourList::displacement takes it.
        for (std::size_t s = i; s < i + 4; ++s) {
          moved_one_by_one = moved_one_by_one || neighbours_.moved_too_far(s, position[s]);
        }
        continue;
      }
      const Lanes q0 = d0 * d0;
      const Lanes q1 = d1 * d1;
      const Lanes q2 = d2 * d2;
      // q0 = x0 y0 z0 x1, q1 = y1 z1 x2 y2, q2 = z2 x3 y3 z3 (squares).
      const Lanes xy01 = __builtin_shufflevector(q0, q1, 0, 3, 6, 1);  // x0 x1 x2 y0
      const Lanes xs = __builtin_shufflevector(xy01, q2, 0, 1, 2, 5);  // x0 x1 x2 x3
      const Lanes yz01 = __builtin_shufflevector(q0, q1, 1, 4, 7, 2);  // y0 y1 y2 z0
      const Lanes ys = __builtin_shufflevector(yz01, q2, 0, 1, 2, 6);  // y0 y1 y2 y3
      const Lanes zs01 = __builtin_shufflevector(q0, q1, 2, 5, 0, 0);  // z0 z1 . .
      const Lanes zs = __builtin_shufflevector(zs01, q2, 0, 1, 4, 7);  // z0 z1 z2 z3
      moved |= (xs + ys) + zs > limit;
    }
    bool any_moved = any(moved) || moved_one_by_one;
    if (i < end) {
      any_moved =
          (periodic ? integrate_particles<true>(i, end) : integrate_particles<false>(i, end)) ||
          any_moved;
    }
    return any_moved;
  }
}
#endif

template <int D>
template <bool periodic>
bool World<D>::integrate_particles(std::size_t begin, std::size_t end) {
  // The arrays by pointer, and the constants in locals: the compiler cannot tell that the
  // stores below leave the vectors' and the list's members unchanged.
  const auto [force, torque, velocity, position, spin, mass, inverse_mass, inverse_inertia, radius,
              velocity_now, rim_now, rim_step, reference] = integration_arrays();
  const double limit = neighbours_.half_skin_squared();
  const Vec<D> gravity = settings_.gravity;
  const double dt = settings_.time_step;
  const double half_step = 0.5 * dt;
  // Keeps positions in [0, period) along the axis of a periodic slab.
  const double period = neighbours_.period();
  unsigned moved = 0;
  // In 3D worlds large enough for the pair kernel to prefetch, the arrays the pair stage has not
  // brought into the cache (it reads a particle's velocities only where it touches another, and
  // never the inverse masses or the rebuild's positions) are fetched a few particles ahead: the
  // 1e6-ball slab of the scaling series, one thread, 1.36–1.38e7 → 1.41–1.42e7 particle-steps/s.
  // (A 2D world that large would take the plain loop too, at the cost of its second build.)
  constexpr std::size_t prefetch_distance = 12;
  const bool prefetch = D == 3 && prefetch_pairs_;
  const std::size_t last = particles_.size() - 1;
#if !defined(__clang__)  // GCC's; `omp simd` left this loop unvectorised
#pragma GCC ivdep
#endif
  for (std::size_t i = begin; i < end; ++i) {
    if (prefetch) {
      const std::size_t ahead = std::min(i + prefetch_distance, last);
      __builtin_prefetch(&reference[ahead]);
      __builtin_prefetch(&inverse_mass[ahead]);
      __builtin_prefetch(&inverse_inertia[ahead]);
      __builtin_prefetch(&position[ahead], 1);
      __builtin_prefetch(&velocity[ahead], 1);
      __builtin_prefetch(&spin[ahead], 1);
      __builtin_prefetch(&velocity_now[ahead], 1);
      __builtin_prefetch(&rim_now[ahead], 1);
    }
    force[i] += mass[i] * gravity;
    velocity[i] += (inverse_mass[i] * dt) * force[i];
    position[i] += dt * velocity[i];
    spin[i] += (inverse_inertia[i] * dt) * torque[i];
    if constexpr (periodic) {
      double& z = position[i][D - 1];
      z = z < 0.0 ? z + period : z;
      z = z >= period ? z - period : z;
    }
    // As NeighbourList::moved_too_far asks it (the plain difference where no axis is periodic).
    const Vec<D> offset =
        periodic ? neighbours_.displacement(reference[i], position[i]) : position[i] - reference[i];
    velocity_now[i] = estimate_now(velocity[i], inverse_mass[i], force[i], half_step);
    if constexpr (keeps_step_rim) rim_step[i] = radius[i] * spin[i];
    rim_now[i] = radius[i] * estimate_now(spin[i], inverse_inertia[i], torque[i], half_step);
    moved |= norm_squared(offset) > limit ? 1U : 0U;
  }
  return moved != 0;
}

// The members defined in this file, for both dimensions (world.hpp declares World<2> and
// World<3> extern; world.cpp instantiates the rest).
template bool World<2>::estimate_current_velocities();
template bool World<3>::estimate_current_velocities();
template void World<2>::check_estimates_made() const;
template void World<3>::check_estimates_made() const;
template bool World<2>::accumulate_forces_and_integrate();
template bool World<3>::accumulate_forces_and_integrate();
template typename World<2>::IntegrationArrays World<2>::integration_arrays();
template typename World<3>::IntegrationArrays World<3>::integration_arrays();
template bool World<2>::integrate_run(std::size_t, std::size_t);
template bool World<3>::integrate_run(std::size_t, std::size_t);
#if defined(__x86_64__)
template bool World<2>::integrate_particles_avx2(std::size_t, std::size_t);
template bool World<3>::integrate_particles_avx2(std::size_t, std::size_t);
#endif

}  // namespace millsim
