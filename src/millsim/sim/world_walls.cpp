// World's wall stage: each wall candidate's contacts with the shell, the lifters and the end
// plates found, the contact law on them four at a time, their forces added to the candidate and
// their moments about the axis to the drive torque.

#include <algorithm>
#include <array>
#include <cstring>

#include "millsim/core/prefetch.hpp"
#include "millsim/sim/world.hpp"
#include "millsim/sim/world_detail.hpp"

namespace millsim {

using namespace world_detail;

namespace {

/// The moment about the mill axis (+z) of a force applied at a point.
double axial_moment(const Vec2& point, const Vec2& force) {
  return cross(point, force);
}
double axial_moment(const Vec3& point, const Vec3& force) {
  return point[0] * force[1] - point[1] * force[0];
}

}  // namespace

template <int D>
void World<D>::evaluate_wall_contacts() {
  const std::size_t candidates = wall_candidates_.size();
  const std::size_t blocks = wall_block_ended_.size();
  // Blocks differ in cost (a block of candidates along the lifters' faces costs more than one
  // on the bare shell): handed out as threads come free.
#pragma omp parallel for schedule(dynamic) if (candidates >= parallel_wall_threshold)
  for (std::size_t b = 0; b < blocks; ++b) evaluate_wall_block(b);
  finish_wall_stage();
}

template <int D>
void World<D>::finish_wall_stage() {
  const std::size_t blocks = wall_block_ended_.size();
  double torque = 0.0;
  for (std::size_t b = 0; b < blocks; ++b) {
    torque += wall_block_torque_[b];
    account_.shell_work += wall_block_work_[b];
    last_step_dissipation_ += wall_block_dissipated_[b];
  }
  shell_torque_ = torque;
  account_.dissipated += last_step_dissipation_;
  record_ended(wall_ended_, wall_block_ended_, wall_block_ * max_wall_contacts);
}

template <int D>
bool World<D>::mill_has_cones() const {
  if constexpr (D == 3) {
    return walls_.mill && walls_.mill->has_cones();
  } else {
    return false;
  }
}

template <int D>
bool World<D>::clear_of_shell_and_ends(std::uint32_t i, double shell_radius) const {
  const Vec<D>& x = particles_.position[i];
  const double r = particles_.radius[i];
  // Clear of the shell with a margin far beyond rounding, so that mill_contacts, which tests
  // norm(x) + r > R, finds no contact in any case this passes.
  const double clear = shell_radius - r - 1e-9 * shell_radius;
  if (!(clear > 0.0 && x[0] * x[0] + x[1] * x[1] < clear * clear)) return false;
  if constexpr (D == 3) {
    // mill_contacts' own test of the flat end plates.
    const auto& mill = *walls_.mill;
    if (!mill.periodic && (x[2] < r || mill.length - x[2] < r)) return false;
  }
  return true;
}

template <int D>
void World<D>::evaluate_wall_block(std::size_t b) {
  evaluate_wall_candidates(b, b * wall_block_,
                           std::min(wall_candidates_.size(), (b + 1) * wall_block_), nullptr);
}

template <int D>
void World<D>::evaluate_wall_candidates(std::size_t b, std::size_t begin, std::size_t end,
                                        WallPart* part) {
  const double dt = settings_.time_step;
  WallBlockSum sum;
  std::uint32_t ended = 0;
  EndedCollision* block_ended = &wall_ended_[b * wall_block_ * max_wall_contacts];
  const auto end_collision = [&](const EndedCollision& collision) {
    if (part != nullptr) {
      part->ended.push_back(collision);
    } else {
      block_ended[ended++] = collision;
    }
  };
  // The block's contacts, found candidate by candidate (each in its slot of wall-contact
  // history) and written where the law reads them, then their contact law worked out
  // lane_count at a time, then each candidate's contacts added up in the order they were found.
  // One list per thread, kept.
  static thread_local std::vector<WallContact<D>> found_list;
  static thread_local std::vector<WallWork> work_list;
  static thread_local std::vector<std::uint32_t> first_work;
  const std::size_t most = walls_.max_contacts();
  std::size_t found = 0;
  first_work.assign(end - begin + 1, 0);
  // Most candidates are near no wall this step: a lifter may sweep past them later, but none
  // is near now (their list of nearby lifters is empty) and they are clear of the shell and
  // the end plates. Told apart here with no search and no call (in the 3D 20 k scene, nine
  // candidates in ten).
  const bool quick =
      !nearby_lifters_.empty() && walls_.planes.empty() && walls_.mill && !mill_has_cones();
  const double shell_radius = walls_.mill ? walls_.mill->radius : 0.0;
  long dropped = 0;  // contacts with no free slot (dropped_wall_contacts)
  for (std::size_t k = begin; k < end; ++k) {
    const std::uint32_t i = wall_candidates_[k];
    std::int32_t* slot_id = &wall_slot_id_[k * max_wall_contacts];
    if (quick && nearby_lifters_[k].count == 0 && clear_of_shell_and_ends(i, shell_radius) &&
        std::all_of(slot_id, slot_id + max_wall_contacts, [](std::int32_t id) { return id < 0; })) {
      first_work[k - begin + 1] = static_cast<std::uint32_t>(found);
      continue;
    }
    // The candidate's slots' histories, one array of candidates per slot.
    const auto history_at = [&](int slot) -> WallHistory& {
      return wall_slot_history_[wall_history_index(k, static_cast<std::size_t>(slot))];
    };
    unsigned seen = 0;  // bit s: slot s touched now
    const NearbyLifters* nearby = nearby_lifters_.empty() ? nullptr : &nearby_lifters_[k];
    if (found_list.size() < found + most) {
      found_list.resize(std::max(2 * found_list.size(), found + most));
      work_list.resize(found_list.size());
    }
    WallContact<D>* contact = &found_list[found];
    const int count =
        walls_.contacts_of(particles_.position[i], particles_.radius[i], contact, nearby);
    int kept_count = 0;
    for (int c = 0; c < count; ++c) {
      const int wall_id = contact[c].wall_id;
      int slot = 0;
      while (slot < max_wall_contacts && slot_id[slot] != wall_id) ++slot;
      if (slot == max_wall_contacts) {
        slot = 0;
        while (slot < max_wall_contacts && slot_id[slot] >= 0) ++slot;
        if (slot == max_wall_contacts) {
          ++dropped;  // more walls at once than slots: see dropped_wall_contacts()
          continue;
        }
        slot_id[slot] = wall_id;
        // A collision begins: where, for ShellImpacts (its history is fresh, all zero).
        history_at(slot).start_angle = std::atan2(contact[c].point[1], contact[c].point[0]);
      }
      seen |= 1U << static_cast<unsigned>(slot);
      // The slot's history, which the law reads and writes once the block's contacts are found:
      // in a large world it is in memory, one slot here and there.
      if (prefetch_pairs_) prefetch_record(history_at(slot), true);
      if (kept_count != c) contact[kept_count] = contact[c];
      WallWork& work_of = work_list[found + static_cast<std::size_t>(kept_count)];
      work_of.particle = i;
      work_of.slot = static_cast<std::uint32_t>(wall_history_index(k, slot));
      ++kept_count;
    }
    found += static_cast<std::size_t>(kept_count);
    first_work[k - begin + 1] = static_cast<std::uint32_t>(found);
    // Slots of walls the candidate no longer touches: their collisions have ended. (The law
    // below works on the touched slots alone.)
    unsigned held = 0;  // bit s: slot s holds a wall's history
    for (int slot = 0; slot < max_wall_contacts; ++slot) {
      held |= slot_id[slot] >= 0 ? 1U << static_cast<unsigned>(slot) : 0U;
    }
    for (unsigned ended_slots = held & ~seen; ended_slots != 0; ended_slots &= ended_slots - 1) {
      const int slot = std::countr_zero(ended_slots);
      end_collision({.type = wall_contact_type(walls_.kind_of(slot_id[slot])),
                     .start_angle = static_cast<float>(history_at(slot).start_angle),
                     .energy = history_at(slot).dissipated});
      history_at(slot) = WallHistory{};
      slot_id[slot] = -1;
    }
  }
  if (dropped > 0) {
#pragma omp atomic
    dropped_wall_contacts_ += dropped;
  }
  evaluate_wall_laws(found_list.data(), work_list.data(), found);
  for (std::size_t k = begin; k < end; ++k) {
    // A candidate touching no wall adds nothing: its sums, begun at +0 and so never −0 (in
    // round-to-nearest x + y is −0 only if both are), would stay the same bits.
    if (first_work[k - begin] == first_work[k - begin + 1]) continue;
    const std::uint32_t i = wall_candidates_[k];
    Vec<D> force{};
    Spin<D> moment{};
    for (std::uint32_t w = first_work[k - begin]; w < first_work[k - begin + 1]; ++w) {
      const WallWork& done = work_list[w];
      const WallContact<D>& contact = found_list[w];
      force += done.force;
      moment += done.moment;
      WallTerm term{.dissipated = done.dissipated, .turns = contact.kind != WallKind::plane};
      if (term.turns) {
        term.torque = axial_moment(contact.point, done.force);
        term.work = dot(done.force, contact.wall_velocity) * dt;
      }
      if (part != nullptr) {
        part->terms.push_back(term);  // added up after the runs, in this order
      } else {
        sum.add(term);
      }
    }
    // Added to the particle's sums after its pairs (they are all done), before gravity.
    particles_.force[i] += force;
    particles_.torque[i] += moment;
  }
  if (part != nullptr) return;
  keep_wall_block(b, sum, ended);
}

template <int D>
void World<D>::evaluate_wall_laws(const WallContact<D>* contact, WallWork* work,
                                  std::size_t count) {
#if defined(__x86_64__)
  if (avx2_lanes_) {
    evaluate_wall_laws_avx2(contact, work, count);
    return;
  }
#endif
  evaluate_wall_laws_in_lanes(contact, work, count);
}

#if defined(__x86_64__)
template <int D>
void World<D>::evaluate_wall_laws_avx2(const WallContact<D>* contact, WallWork* work,
                                       std::size_t count) {
  evaluate_wall_laws_in_lanes(contact, work, count);
}
#endif

template <int D>
void World<D>::evaluate_wall_laws_in_lanes(const WallContact<D>* contact, WallWork* work,
                                           std::size_t count) {
  using T = Lanes;
  constexpr auto lanes = static_cast<std::size_t>(lane_count);
  const double dt = settings_.time_step;
  const auto& p = particles_;
  for (std::size_t k = 0; k < count; k += lanes) {
    // The contacts of the lanes; where fewer remain, the last one fills the rest.
    const std::size_t filled = std::min(lanes, count - k);
    std::array<WallWork*, lanes> c{};
    std::array<const WallContact<D>*, lanes> wall{};
    for (std::size_t l = 0; l < lanes; ++l) {
      c[l] = &work[k + std::min(l, filled - 1)];
      wall[l] = &contact[k + std::min(l, filled - 1)];
    }
    const auto particle = [&](std::size_t l) { return c[l]->particle; };
    ContactInput<D, T> in;
    for (int d = 0; d < D; ++d) {
      in.normal[d] = gather_lanes([&](std::size_t l) { return wall[l]->normal[d]; });
      in.velocity[d] = gather_lanes(
          [&](std::size_t l) { return velocity_now_[particle(l)][d] - wall[l]->wall_velocity[d]; });
      in.step_velocity[d] = gather_lanes(
          [&](std::size_t l) { return p.velocity[particle(l)][d] - wall[l]->wall_velocity[d]; });
    }
    in.overlap = gather_lanes([&](std::size_t l) { return wall[l]->overlap; });
    const T radius = gather_lanes([&](std::size_t l) { return p.radius[particle(l)]; });
    // The spin's sliding velocity from r ω, at the time of the positions and over the last step.
    in.spin_velocity = spin_sliding(in.normal, gather_spin_lanes<D>([&](std::size_t l) {
                                      return rim_speed_now_[particle(l)];
                                    }));
    in.step_spin_velocity = spin_sliding(
        in.normal, gather_spin_lanes<D>([&](std::size_t l) { return step_rim(particle(l)); }));
    // The dashpots' coefficients from the particle's mass (m* = m against a wall), as the pair
    // kernel has them (the same for every particle of a charge of one size).
    ContactDampingOf<T> damping;
    if (uniform_mass_) {
      damping.normal = splat<T>(uniform_wall_damping_.normal);
      damping.tangential = splat<T>(uniform_wall_damping_.tangential);
    } else {
      damping =
          ball_wall_law_.damping(gather_lanes([&](std::size_t l) { return p.mass[particle(l)]; }));
    }
    ContactHistory<D, T> held;
    const auto history = [&](std::size_t l) -> WallHistory& {
      return wall_slot_history_[c[l]->slot];
    };
    held.normal_spring_origin =
        gather_lanes([&](std::size_t l) { return history(l).normal_spring_origin; });
    held.tangential_spring =
        gather_spin_lanes<D>([&](std::size_t l) { return history(l).tangential_spring; });
    held.dissipated = gather_lanes([&](std::size_t l) { return history(l).dissipated; });
    const ContactOutput<D, T> out = ball_wall_law_.evaluate(in, damping, held, dt);
    const auto moment = -radius * cross(in.normal, out.tangential_force);
    for (std::size_t l = 0; l < filled; ++l) {
      WallHistory& h = history(l);
      h.normal_spring_origin = held.normal_spring_origin[l];
      if constexpr (D == 2) {
        h.tangential_spring = held.tangential_spring[l];
      } else {
        for (int d = 0; d < D; ++d) h.tangential_spring[d] = held.tangential_spring[d][l];
      }
      h.dissipated = held.dissipated[l];
      h.overlap = in.overlap[l];
      WallWork& done = *c[l];
      for (int d = 0; d < D; ++d) done.force[d] = out.force[d][l];
      if constexpr (D == 2) {
        done.moment = moment[l];
      } else {
        for (int d = 0; d < 3; ++d) done.moment[d] = moment[d][l];
      }
      done.dissipated = out.dissipated[l];
    }
  }
}

// The members defined in this file, for both dimensions (world.hpp declares World<2> and
// World<3> extern; world.cpp instantiates the rest).
template void World<2>::evaluate_wall_contacts();
template void World<3>::evaluate_wall_contacts();
template void World<2>::finish_wall_stage();
template void World<3>::finish_wall_stage();
template bool World<2>::mill_has_cones() const;
template bool World<3>::mill_has_cones() const;
template bool World<2>::clear_of_shell_and_ends(std::uint32_t, double) const;
template bool World<3>::clear_of_shell_and_ends(std::uint32_t, double) const;
template void World<2>::evaluate_wall_block(std::size_t);
template void World<3>::evaluate_wall_block(std::size_t);
template void World<2>::evaluate_wall_candidates(std::size_t, std::size_t, std::size_t, WallPart*);
template void World<3>::evaluate_wall_candidates(std::size_t, std::size_t, std::size_t, WallPart*);
template void World<2>::evaluate_wall_laws(const WallContact<2>*, WallWork*, std::size_t);
template void World<3>::evaluate_wall_laws(const WallContact<3>*, WallWork*, std::size_t);
#if defined(__x86_64__)
template void World<2>::evaluate_wall_laws_avx2(const WallContact<2>*, WallWork*, std::size_t);
template void World<3>::evaluate_wall_laws_avx2(const WallContact<3>*, WallWork*, std::size_t);
#endif

}  // namespace millsim
