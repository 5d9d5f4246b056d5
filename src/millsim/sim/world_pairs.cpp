// World's pair stage: each listed pair's distance tested (the first pass), the contact law on
// those that touch or did until now, four at a time, their forces added to both particles in
// pair order.

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>

#include "millsim/core/prefetch.hpp"
#include "millsim/sim/world.hpp"
#include "millsim/sim/world_detail.hpp"

namespace millsim {

using namespace world_detail;

template <int D>
void World<D>::evaluate_pair_contacts() {
  // Each particle sums its pairs in pair order (pairs where it is second come first, as their
  // first particle has the lower index): the order in which one thread going down the list
  // meets them. The pairs add their forces to the particles as they go.
  zero_sums(0, particles_.size());
  const std::size_t blocks = pair_block_ended_.size();
  for (std::size_t b = 0; b < blocks; ++b) evaluate_pair_block(b);
  finish_pair_stage();
}

template <int D>
void World<D>::finish_pair_stage() {
  last_step_dissipation_ = 0.0;
  for (const double d : pair_block_dissipated_) last_step_dissipation_ += d;
  record_ended(pair_ended_, pair_block_ended_, pair_block_);
}

template <int D>
std::size_t World<D>::list_pairs_for_law(std::size_t begin, std::size_t end, std::size_t below,
                                         std::uint32_t* listed) const {
  // Four loops, so that each pair costs only the instructions its world needs (the loop is
  // bound by their number: about 37 a pair, five a cycle, in the 3D 20 k scene before), and with
  // AVX2 the same loops taking four pairs at a time: in 3D worlds, periodic or not, and in 2D
  // worlds small enough for the caches (a larger one keeps the one-by-one loop, which fetches
  // the position of the pair 64 ahead's second particle; bench/results.md).
  const bool every_pair = below >= particles_.size();
  const bool periodic = neighbours_.period() > 0.0;
  std::size_t count = 0;
  bool in_lanes = false;
#if defined(__x86_64__)
  if (avx2_lanes_ && (D == 3 || !prefetch_pairs_)) {
    if constexpr (D == 3) {  // (a 2D world is never periodic)
      if (periodic) {
        count = every_pair ? list_pairs_avx2<true, true>(begin, end, below, listed)
                           : list_pairs_avx2<true, false>(begin, end, below, listed);
        in_lanes = true;
      }
    }
    if (!in_lanes) {
      count = every_pair ? list_pairs_avx2<false, true>(begin, end, below, listed)
                         : list_pairs_avx2<false, false>(begin, end, below, listed);
      in_lanes = true;
    }
  }
#endif
  if (in_lanes) {
    // Listed above.
  } else if (periodic) {
    count = every_pair ? list_pairs_of<true, true>(begin, end, below, listed)
                       : list_pairs_of<true, false>(begin, end, below, listed);
  } else {
    count = every_pair ? list_pairs_of<false, true>(begin, end, below, listed)
                       : list_pairs_of<false, false>(begin, end, below, listed);
  }
  // The kernel takes them lane_count at a time: the last group is filled up with copies of the
  // last pair (evaluate_listed_pairs_in_lanes).
  for (std::size_t l = count; count > 0 && l % lane_count != 0; ++l) listed[l] = listed[count - 1];
  return count;
}

#if defined(__x86_64__)
namespace {

/// Four pair numbers in one register.
using FourIndices = std::uint32_t __attribute__((vector_size(4 * sizeof(std::uint32_t))));

/// For each set of four lanes (bit l for lane l): the kept lanes in order, and how many.
struct KeptLanes {
  std::array<std::uint32_t, 4> lanes;
  std::uint32_t count;
};
constexpr std::array<KeptLanes, 16> kept_lanes_table() {
  std::array<KeptLanes, 16> table{};
  for (unsigned set = 0; set < 16; ++set) {
    std::uint32_t count = 0;
    for (std::uint32_t l = 0; l < 4; ++l) {
      if ((set >> l) & 1U) table[set].lanes[count++] = l;
    }
    table[set].count = count;
  }
  return table;
}
constexpr std::array<KeptLanes, 16> kept_lanes = kept_lanes_table();

}  // namespace

template <int D>
template <bool periodic, bool every_pair>
std::size_t World<D>::list_pairs_avx2(std::size_t begin, std::size_t end, std::size_t below,
                                      std::uint32_t* listed) const {
  {
    constexpr auto lanes = static_cast<std::size_t>(lane_count);
    const auto& first = neighbours_.first();
    const auto& second = neighbours_.second();
    const auto& x = particles_.position;
    const double* const pair_reach = neighbours_.reach().data();
    const TouchState* touching = neighbours_.touching().data();
    static_assert(static_cast<std::uint8_t>(TouchState::apart) == 0 &&
                  static_cast<std::uint8_t>(TouchState::touching) == 1);
    [[maybe_unused]] const Lanes period = splat<Lanes>(neighbours_.period());
    std::size_t count = 0;
    std::size_t q = begin;
    for (; q + lanes <= end; q += lanes) {
      std::array<std::uint32_t, lanes> i{}, j{};
      unsigned own = 0xFU;  // bit l: lane l's second particle is below `below`
      for (std::size_t l = 0; l < lanes; ++l) {
        i[l] = first[q + l];
        j[l] = second[q + l];
        if constexpr (!every_pair) {
          // As list_pairs_of: another thread's particle is not read, the first stands in.
          const unsigned owned = j[l] < below ? 1U : 0U;
          own &= ~((1U - owned) << l);
          j[l] = owned != 0U ? j[l] : i[l];
        }
      }
      // The operations of list_pairs_of, in the same order, each lane a pair.
      Lanes distance_squared{};
      if constexpr (D == 2) {
        const Vec<2, Lanes> offset =
            lanes_of([&](std::size_t l) { return pair_of(x[j[l]]) - pair_of(x[i[l]]); });
        distance_squared = offset[0] * offset[0] + offset[1] * offset[1];
      } else {
        const Vec<2, Lanes> planar = lanes_of(
            [&](std::size_t l) { return planar_pair_of(x[j[l]]) - planar_pair_of(x[i[l]]); });
        Lanes dz = gather_lanes([&](std::size_t l) { return x[j[l]][2] - x[i[l]][2]; });
        if constexpr (periodic) {
          // The nearest image along the axis, as NeighbourList::separation makes it:
          // dz − period · nearest_integer(dz / period), each operation as core/vec.hpp's.
          dz = dz - period * lane_nearest_integer(dz / period);
        }
        distance_squared = (planar[0] * planar[0] + planar[1] * planar[1]) + dz * dz;
      }
      Lanes reach;
      std::memcpy(&reach, pair_reach + q, sizeof reach);
      auto keep = static_cast<unsigned>(
          __builtin_ia32_movmskpd256(reinterpret_cast<Lanes>(distance_squared < reach * reach)));
      // The four pairs' touch states, one byte each (0 or 1), gathered into bits 24 to 27.
      std::uint32_t states = 0;
      std::memcpy(&states, touching + q, sizeof states);
      keep |= ((states * 0x01020408U) >> 24) & 0xFU;
      keep &= own;
      // The kept pairs' numbers written at once, in order; the rest of the four is overwritten
      // by the next ones (or repeats, or is left beyond the count).
      FourIndices numbers{};
      std::memcpy(&numbers, kept_lanes[keep].lanes.data(), sizeof numbers);
      numbers += static_cast<std::uint32_t>(q);
      std::memcpy(listed + count, &numbers, sizeof numbers);
      count += kept_lanes[keep].count;
    }
    return count + list_pairs_of<periodic, every_pair>(q, end, below, listed + count);
  }
}
#endif

template <int D>
template <bool periodic, bool every_pair>
std::size_t World<D>::list_pairs_of(std::size_t begin, std::size_t end, std::size_t below,
                                    std::uint32_t* listed) const {
  const auto& first = neighbours_.first();
  const auto& second = neighbours_.second();
  const auto& touching = neighbours_.touching();
  const auto& x = particles_.position;
  const auto& pair_reach = neighbours_.reach();
  // Pairs that overlap now or did until now, in pair order: the rest need nothing. Listed
  // without a branch (a third of the 2D SAG scene's listed pairs touch, scattered among the
  // others, which the processor could only mispredict).
  std::size_t count = 0;
  // In a large world (prefetch_pairs_) the second particle's position, 64 pairs ahead: this
  // pass is the step's first to read it, out of memory order and, beyond the caches, from
  // memory (the 1e6-ball slab: +2.5 to 4 %; 16 pairs ahead gained half that, the radius too
  // lost it all).
  constexpr std::size_t position_ahead = 64;
  const bool prefetch = prefetch_pairs_;
  const std::size_t pairs = second.size();
  for (std::size_t q = begin; q < end; ++q) {
    if (prefetch && q + position_ahead < pairs) __builtin_prefetch(&x[second[q + position_ahead]]);
    const std::uint32_t i = first[q];
    std::uint32_t j = second[q];
    // Only the pairs whose second particle is below `below`: one at or beyond it belongs to
    // another thread, which may be moving it now. Its position is not read (a data race,
    // though the distance would be dropped): the pair's first particle stands in for it.
    unsigned own = 1U;
    if constexpr (!every_pair) {
      own = j < below ? 1U : 0U;
      j = own != 0U ? j : i;
    }
    double distance_squared = 0.0;
    if constexpr (D == 2) {
      // Both components at once (never periodic in 2D): the same bits as norm_squared.
      const Pair2 offset = pair_of(x[j]) - pair_of(x[i]);
      const Pair2 squares = offset * offset;
      distance_squared = squares[0] + squares[1];
    } else if constexpr (periodic) {
      distance_squared = norm_squared(neighbours_.separation(x[i], x[j]));
    } else {
      // x and y at once, then z: the same operations in the same order as
      // norm_squared(x[j] − x[i]) (whose first sum, +0 + dx², is dx²).
      const Pair2 planar = planar_pair_of(x[j]) - planar_pair_of(x[i]);
      const Pair2 squares = planar * planar;
      const double dz = x[j][2] - x[i][2];
      distance_squared = (squares[0] + squares[1]) + dz * dz;
    }
    const double reach = pair_reach[q];
    const unsigned keep = ((distance_squared < reach * reach ? 1U : 0U) |
                           (touching[q] == TouchState::touching ? 1U : 0U)) &
                          own;
    listed[count] = static_cast<std::uint32_t>(q);
    count += keep;
  }
  return count;
}

template <int D>
void World<D>::evaluate_pair_block(std::size_t b) {
  // Block b, all of it, on one thread: each pair's force added in pair order, the block's
  // dissipation summed and its ended collisions listed in pair order.
  const std::size_t pairs = neighbours_.first().size();
  double dissipated = 0.0;
  std::uint32_t ended = 0;
  const std::size_t begin = b * pair_block_;
  const std::size_t end = std::min(pairs, begin + pair_block_);
  std::array<std::uint32_t, max_pair_block + lane_count> listed;
  const std::size_t count = list_pairs_for_law(begin, end, particles_.size(), listed.data());
  evaluate_listed_pairs(b, listed.data(), count, dissipated, ended);
  pair_block_dissipated_[b] = dissipated;
  pair_block_ended_[b] = ended;
}

template <int D>
void World<D>::evaluate_listed_pairs(std::size_t block, const std::uint32_t* listed,
                                     std::size_t count, double& dissipated, std::uint32_t& ended,
                                     bool each_apart, PairForce* stored) {
#if defined(__x86_64__)
  if (avx2_lanes_) {
    evaluate_listed_pairs_avx2(block, listed, count, dissipated, ended, each_apart, stored);
    return;
  }
#endif
  evaluate_listed_pairs_each_way(block, listed, count, dissipated, ended, each_apart, stored);
}

#if defined(__x86_64__)
template <int D>
void World<D>::evaluate_listed_pairs_avx2(std::size_t block, const std::uint32_t* listed,
                                          std::size_t count, double& dissipated,
                                          std::uint32_t& ended, bool each_apart,
                                          PairForce* stored) {
  evaluate_listed_pairs_each_way(block, listed, count, dissipated, ended, each_apart, stored);
}
#endif

template <int D>
void World<D>::evaluate_listed_pairs_each_way(std::size_t block, const std::uint32_t* listed,
                                              std::size_t count, double& dissipated,
                                              std::uint32_t& ended, bool each_apart,
                                              PairForce* stored) {
  // Compiled for each way of keeping the outcomes (the kernel is inlined), so that no pair asks.
  if (stored != nullptr) {
    evaluate_listed_pairs_in_lanes(block, listed, count, dissipated, ended, true, stored);
  } else if (each_apart) {
    evaluate_listed_pairs_in_lanes(block, listed, count, dissipated, ended, true, nullptr);
  } else {
    evaluate_listed_pairs_in_lanes(block, listed, count, dissipated, ended, false, nullptr);
  }
}

template <int D>
void World<D>::prefetch_pairs(const std::uint32_t* listed, std::size_t begin, std::size_t end) {
  const auto& p = particles_;
  for (std::size_t k = begin; k < end; ++k) {
    const std::uint32_t q = listed[k];
    prefetch_record(neighbours_.history()[q]);
    for (const std::uint32_t i : {neighbours_.first()[q], neighbours_.second()[q]}) {
      __builtin_prefetch(&velocity_now_[i]);
      __builtin_prefetch(&rim_speed_now_[i]);
      __builtin_prefetch(&p.velocity[i]);
      if constexpr (keeps_step_rim) {
        __builtin_prefetch(&rim_speed_step_[i]);
      } else {
        __builtin_prefetch(&p.angular_velocity[i]);
      }
      if (!uniform_mass_) __builtin_prefetch(&p.mass[i]);
      __builtin_prefetch(&p.force[i], 1);
      __builtin_prefetch(&p.torque[i], 1);
    }
  }
}

template <int D>
void World<D>::prefetch_particles(std::size_t from, std::size_t to) {
  // Into the second-level cache: the window is larger than the first-level cache, into which
  // prefetch_pairs brings each pair's lines just before the kernel reads them. The sums too are
  // only read: a line no other core holds arrives exclusive, and the kernel's write then needs
  // no second fetch. (Near the end of a thread's run the window reaches into the next run's
  // particles, whose lines another core writes; a prefetch changes no value.)
  if (from >= to) return;
  const auto lines = [ from, to ](const auto& array) __attribute__((always_inline)) {
    prefetch_lines_for_l2(array.data() + from, to - from);
  };
  const auto& p = particles_;
  lines(p.position);
  lines(p.radius);
  lines(velocity_now_);
  lines(rim_speed_now_);
  lines(p.velocity);
  if constexpr (keeps_step_rim) {
    lines(rim_speed_step_);
  } else {
    lines(p.angular_velocity);
  }
  if (!uniform_mass_) lines(p.mass);
  lines(p.force);
  lines(p.torque);
}

template <int D>
void World<D>::evaluate_listed_pairs_in_lanes(std::size_t block, const std::uint32_t* listed,
                                              std::size_t count, double& dissipated_sum,
                                              std::uint32_t& ended_count, bool each_apart,
                                              PairForce* stored) {
  // The block's dissipation and ended count are kept in registers and written back at the
  // end: through the references each touching pair's addition was a load and a store the
  // compiler could not keep apart from the force sums' (the same additions, in the same order).
  double dissipated = dissipated_sum;
  std::uint32_t ended = ended_count;
  using T = Lanes;
  constexpr auto lanes = static_cast<std::size_t>(lane_count);
  // The particles' arrays the step reads, by the names the law uses: v and ω at the time of the
  // positions, and over the last step.
  const auto& p = particles_;
  const auto& v = velocity_now_;
  const auto& rim = rim_speed_now_;
  const auto& r = particles_.radius;
  auto& history = neighbours_.history();
  auto& touching = neighbours_.touching();
  const double dt = settings_.time_step;
  const std::size_t begin = block * pair_block_;
  const bool periodic = neighbours_.period() > 0.0;
  [[maybe_unused]] const T period = splat<T>(neighbours_.period());

  // The window of prefetched particles (pair_window_) ends here: the earlier blocks of the run
  // have fetched up to it. (A run's first block starts with the window not yet fetched.)
  const std::size_t particle_count = particles_.size();
  std::size_t window_end =
      count > 0 ? std::min(particle_count, neighbours_.first()[listed[0]] + pair_window_) : 0;
  for (std::size_t k = 0; k < count; k += lanes) {
    if (pair_window_ > 0) {
      const std::size_t ahead =
          std::min(particle_count, neighbours_.first()[listed[k]] + pair_window_);
      if (ahead > window_end) {
        prefetch_particles(window_end, ahead);
        window_end = ahead;
      }
    }
    if (prefetch_pairs_)
      prefetch_pairs(listed, std::min(count, k + 2 * lanes), std::min(count, k + 3 * lanes));
    // The pairs of the lanes; where fewer remain, the last one fills the rest (the caller has
    // listed it again up to a whole group).
    std::array<std::uint32_t, lanes> q{}, i{}, j{};
    const std::size_t filled = std::min(lanes, count - k);
    for (std::size_t l = 0; l < lanes; ++l) {
      q[l] = listed[k + l];
      i[l] = neighbours_.first()[q[l]];
      j[l] = neighbours_.second()[q[l]];
    }
    Vec<D, T> separation;
    Vec<D, T> velocity, step_velocity;
    if constexpr (D == 2) {
      // Each particle's two components in one register, the pair's difference taken in it (a 2D
      // world is never periodic: World::axial_period), and four such differences turned into
      // lanes: the same subtractions as one by one.
      separation = lanes_of(
          [&](std::size_t l) { return pair_of(p.position[j[l]]) - pair_of(p.position[i[l]]); });
      velocity = lanes_of([&](std::size_t l) { return pair_of(v[j[l]]) - pair_of(v[i[l]]); });
      step_velocity = lanes_of(
          [&](std::size_t l) { return pair_of(p.velocity[j[l]]) - pair_of(p.velocity[i[l]]); });
    } else {
      // The same in 3D for x and y, z apart: the same subtractions as one by one.
      const auto planar_lanes = [&](const std::vector<Vec3>& a) __attribute__((always_inline)) {
        return lanes_of(
            [&](std::size_t l) { return planar_pair_of(a[j[l]]) - planar_pair_of(a[i[l]]); });
      };
      const auto axial_lanes = [&](const std::vector<Vec3>& a) __attribute__((always_inline)) {
        return gather_lanes([&](std::size_t l) { return a[j[l]][2] - a[i[l]][2]; });
      };
      const Vec<2, T> planar = planar_lanes(p.position);
      separation = {{planar[0], planar[1], axial_lanes(p.position)}};
      if (periodic) {
        // The nearest image along the axis, as NeighbourList::separation makes it.
        separation[2] = separation[2] - period * lane_nearest_integer(separation[2] / period);
      }
      const Vec<2, T> planar_velocity = planar_lanes(v);
      velocity = {{planar_velocity[0], planar_velocity[1], axial_lanes(v)}};
      const Vec<2, T> planar_step = planar_lanes(p.velocity);
      step_velocity = {{planar_step[0], planar_step[1], axial_lanes(p.velocity)}};
    }
    const T reach = gather_lanes([&](std::size_t l) { return r[i[l]] + r[j[l]]; });
    const T distance_squared = norm_squared(separation);
    const Mask<T> overlaps = distance_squared < reach * reach;
    const T distance = lane_sqrt(distance_squared);
    ContactInput<D, T> in;
    in.normal = separation * (splat<T>(1.0) / distance);
    in.overlap = reach - distance;
    in.velocity = velocity;
    in.step_velocity = step_velocity;
    // The spins' sliding velocity from r_i ω_i + r_j ω_j, at the time of the positions and over
    // the last step.
    in.spin_velocity = spin_sliding(
        in.normal, gather_spin_lanes<D>([&](std::size_t l) { return rim[i[l]] + rim[j[l]]; }));
    in.step_spin_velocity = spin_sliding(in.normal, gather_spin_lanes<D>([&](std::size_t l) {
                                           return step_rim(i[l]) + step_rim(j[l]);
                                         }));

    ContactHistory<D, T> held;
    held.normal_spring_origin =
        gather_lanes([&](std::size_t l) { return history[q[l]].normal_spring_origin; });
    held.tangential_spring =
        gather_spin_lanes<D>([&](std::size_t l) { return history[q[l]].tangential_spring; });
    held.dissipated = gather_lanes([&](std::size_t l) { return history[q[l]].dissipated; });
    ContactDampingOf<T> damping;
    if (uniform_mass_) {
      damping.normal = splat<T>(uniform_pair_damping_.normal);
      damping.tangential = splat<T>(uniform_pair_damping_.tangential);
    } else {
      const T mass_i = gather_lanes([&](std::size_t l) { return p.mass[i[l]]; });
      const T mass_j = gather_lanes([&](std::size_t l) { return p.mass[j[l]]; });
      damping = ball_ball_law_.damping(mass_i * mass_j / (mass_i + mass_j));
    }
    const ContactOutput<D, T> out = ball_ball_law_.evaluate(in, damping, held, dt);
    const auto moment = -cross(in.normal, out.tangential_force);

    // Each pair's outcome, in pair order: a pair that no longer overlaps has ended (it is
    // listed, so it touched until now); the others add their forces. Most groups are four
    // pairs that all touch: for them the same operations in the same order, without asking
    // each pair (a loop of four the compiler unrolls, each lane's values taken from its
    // registers).
    const bool all_touch = filled == lanes && all(overlaps);
    // touches(l) for each lane that touches; a lane that ended is recorded, marked apart and
    // handed to ended(l).
    const auto apply_outcomes = [&](auto&& touches, auto&& ended_lane)
        __attribute__((always_inline)) {
      if (all_touch) {
        for (std::size_t l = 0; l < lanes; ++l) touches(l);
        return;
      }
      for (std::size_t l = 0; l < filled; ++l) {
        if (overlaps[l] == 0) {
          record_pair_end(q[l], history[q[l]].dissipated, begin, ended, each_apart);
          ended_lane(l);
          touching[q[l]] = TouchState::apart;
          continue;
        }
        touches(l);
      }
    };
    if constexpr (D == 2) {
      // The histories of the four lanes, written without a branch after the ended pairs'
      // energies are read: those of ended pairs zeroed, the rest the law's (a lane that repeats
      // the last pair writes what that one does).
      // (No lambda for the choice: one that takes Lanes by value would be a call in the debug
      // build, from AVX2 code into baseline code: core/vec.hpp.)
      const T zero{};
      const std::array<Pair2, lanes> force_of = pairs_of(out.force);
      const auto touches = [&](std::size_t l) __attribute__((always_inline)) {
        touching[q[l]] = TouchState::touching;
        if (stored != nullptr) {
          std::memcpy(stored[k + l].force.c.data(), &force_of[l], sizeof force_of[l]);
          stored[k + l].moment = moment[l];
        } else {
          subtract_from(particles_.force[i[l]], force_of[l]);
          add_to(particles_.force[j[l]], force_of[l]);
          particles_.torque[i[l]] += r[i[l]] * moment[l];
          particles_.torque[j[l]] += r[j[l]] * moment[l];
        }
        record_pair_touch(q[l], out.dissipated[l], dissipated, each_apart);
      };
      // (An ended lane's history is zeroed with the others' below.)
      apply_outcomes(touches, [](std::size_t) __attribute__((always_inline)){});
      const T origin = select(overlaps, held.normal_spring_origin, zero);
      const T spring = select(overlaps, held.tangential_spring, zero);
      const T energy = select(overlaps, held.dissipated, zero);
      for (std::size_t l = 0; l < lanes; ++l) {
        ContactHistory<D>& h = history[q[l]];
        h.normal_spring_origin = origin[l];
        h.tangential_spring = spring[l];
        h.dissipated = energy[l];
      }
    } else {
      const auto touches = [&](std::size_t l) __attribute__((always_inline)) {
        const std::uint32_t pair = q[l];
        touching[pair] = TouchState::touching;
        ContactHistory<D>& h = history[pair];
        h.normal_spring_origin = held.normal_spring_origin[l];
        for (int d = 0; d < D; ++d) h.tangential_spring[d] = held.tangential_spring[d][l];
        h.dissipated = held.dissipated[l];
        Vec<D> f;
        for (int d = 0; d < D; ++d) f[d] = out.force[d][l];
        Vec3 turn;
        for (int d = 0; d < 3; ++d) turn[d] = moment[d][l];
        if (stored != nullptr) {
          stored[k + l] = {f, turn};
        } else {
          particles_.force[i[l]] -= f;
          particles_.force[j[l]] += f;
          particles_.torque[i[l]] += r[i[l]] * turn;
          particles_.torque[j[l]] += r[j[l]] * turn;
        }
        record_pair_touch(pair, out.dissipated[l], dissipated, each_apart);
      };
      apply_outcomes(
          touches, [&](std::size_t l)
                       __attribute__((always_inline)) { history[q[l]] = ContactHistory<D>{}; });
    }
  }
  dissipated_sum = dissipated;
  ended_count = ended;
}

// The members defined in this file, for both dimensions (world.hpp declares World<2> and
// World<3> extern; world.cpp instantiates the rest).
template void World<2>::evaluate_pair_contacts();
template void World<3>::evaluate_pair_contacts();
template void World<2>::finish_pair_stage();
template void World<3>::finish_pair_stage();
template std::size_t World<2>::list_pairs_for_law(std::size_t, std::size_t, std::size_t,
                                                  std::uint32_t*) const;
template std::size_t World<3>::list_pairs_for_law(std::size_t, std::size_t, std::size_t,
                                                  std::uint32_t*) const;
template void World<2>::evaluate_pair_block(std::size_t);
template void World<3>::evaluate_pair_block(std::size_t);
template void World<2>::evaluate_listed_pairs(std::size_t, const std::uint32_t*, std::size_t,
                                              double&, std::uint32_t&, bool, PairForce*);
template void World<3>::evaluate_listed_pairs(std::size_t, const std::uint32_t*, std::size_t,
                                              double&, std::uint32_t&, bool, PairForce*);
#if defined(__x86_64__)
template std::size_t World<2>::list_pairs_avx2<false, true>(std::size_t, std::size_t, std::size_t,
                                                            std::uint32_t*) const;
template std::size_t World<2>::list_pairs_avx2<false, false>(std::size_t, std::size_t, std::size_t,
                                                             std::uint32_t*) const;
template std::size_t World<3>::list_pairs_avx2<false, true>(std::size_t, std::size_t, std::size_t,
                                                            std::uint32_t*) const;
template std::size_t World<3>::list_pairs_avx2<false, false>(std::size_t, std::size_t, std::size_t,
                                                             std::uint32_t*) const;
template std::size_t World<3>::list_pairs_avx2<true, true>(std::size_t, std::size_t, std::size_t,
                                                           std::uint32_t*) const;
template std::size_t World<3>::list_pairs_avx2<true, false>(std::size_t, std::size_t, std::size_t,
                                                            std::uint32_t*) const;
template void World<2>::evaluate_listed_pairs_avx2(std::size_t, const std::uint32_t*, std::size_t,
                                                   double&, std::uint32_t&, bool, PairForce*);
template void World<3>::evaluate_listed_pairs_avx2(std::size_t, const std::uint32_t*, std::size_t,
                                                   double&, std::uint32_t&, bool, PairForce*);
#endif

}  // namespace millsim
