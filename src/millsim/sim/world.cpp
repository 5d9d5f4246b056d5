// The World itself: its construction, step() (the stages in order), the neighbour list's
// refresh with what hangs on it (the particles' cell order, the blocks, the wall candidates and
// their nearby lifters), and the energy accounts. The stages are in their own files:
// world_pairs.cpp (pair contacts), world_walls.cpp (wall contacts), world_integrate.cpp (the
// leapfrog and the velocity estimates) and world_threads.cpp (the three run interleaved, on one
// thread or several); docs/architecture.md has the table of what each reads and writes.
#include "millsim/sim/world.hpp"

#include <omp.h>

#include <algorithm>
#include <type_traits>

#include "millsim/core/cpu.hpp"
#include "millsim/core/vector_growth.hpp"
#include "millsim/sim/world_detail.hpp"

namespace millsim {

using namespace world_detail;

namespace {

/// values[k] ← values[previous[k]] for blocks of `per_particle` elements, through `scratch`
/// (swapped with `values`: it keeps the old buffer for the next array of its type).
template <typename T>
void reorder(std::vector<T>& values, const std::vector<std::uint32_t>& previous,
             std::size_t per_particle, std::vector<T>& scratch) {
  scratch.resize(values.size());
  for (std::size_t k = 0; k < previous.size(); ++k) {
    const std::size_t from = previous[k] * per_particle;
    std::copy(values.begin() + static_cast<std::ptrdiff_t>(from),
              values.begin() + static_cast<std::ptrdiff_t>(from + per_particle),
              scratch.begin() + static_cast<std::ptrdiff_t>(k * per_particle));
  }
  values.swap(scratch);
}

}  // namespace

template <int D>
World<D>::World(const WorldSettings<D>& settings, const Walls<D>& walls)
    : settings_(settings),
      walls_(walls),
      ball_ball_law_(settings.ball_ball, settings.allow_tension),
      ball_wall_law_(settings.ball_wall, settings.allow_tension),
      neighbours_(settings.skin) {
  if (walls_.mill) walls_.mill->turn_to(walls_.mill->angle);
  neighbours_.set_period(axial_period());
  set_avx2_lanes(true);
}

template <int D>
void World<D>::set_avx2_lanes(bool on) {
  avx2_lanes_ = on && processor_has_avx2();
}

template <int D>
double World<D>::axial_period() const {
  if constexpr (D == 3) {
    if (walls_.mill && walls_.mill->periodic) return walls_.mill->length;
  }
  return 0.0;
}

template <int D>
void World<D>::step() {
  bool moved = moved_half_skin_;
  if (estimates_made_ && particles_.size() == neighbours_.built_count()) {
    check_estimates_made();
  } else {
    moved = estimate_current_velocities();
    check_uniform_mass();
  }
  refresh_neighbours(moved);
  if (stages_on_one_thread()) {
    moved_half_skin_ = run_stages_in_one_pass();
  } else if (particles_.size() == neighbours_.built_count() && pairs_split_among_threads()) {
    moved_half_skin_ = run_stages_split_among_threads();
  } else {
    evaluate_pair_contacts();
    evaluate_wall_contacts();
    moved_half_skin_ = accumulate_forces_and_integrate();
  }
  estimates_made_ = true;
  advance_walls();
  time_ += settings_.time_step;
  ++steps_;
}

template <int D>
void World<D>::refresh_neighbours(bool moved) {
  const std::size_t count = particles_.size();
  // Particles added since the last step are at the end, each with its index as id and no
  // wall-contact slots.
  for (std::size_t i = particle_id_.size(); i < count; ++i) {
    particle_id_.push_back(static_cast<std::uint32_t>(i));
    particle_index_.push_back(static_cast<std::uint32_t>(i));
    wall_slots_of_.push_back(no_wall_slots);
  }
  if (!moved) {
    if (lifters_moved_too_far()) refresh_nearby_lifters();
    return;
  }
  const double skin = settings_.skin > 0.0 ? settings_.skin : choose_skin();
  neighbours_.set_skin(skin);
  const bool into_cell_order =
      cell_order_interval_ > 0 && neighbours_.rebuild_count() % cell_order_interval_ == 0;
  // The last list's pairs say whether the step splits among threads.
  neighbours_.set_parallel(splits_among_threads(neighbours_.pair_count(), omp_get_max_threads()));
  neighbours_.set_thread_shares(split_particle_);
  neighbours_.rebuild(particles_.position, particles_.radius, into_cell_order);
  if (into_cell_order) reorder_particles(neighbours_.previous_index());
  const std::size_t pairs = neighbours_.pair_count();
  pair_ended_.resize(pairs);
  // The arrays of prefetch_pairs.
  constexpr std::size_t kernel_bytes = 3 * sizeof(Vec<D>) + 3 * sizeof(Spin<D>) + sizeof(double);
  const bool sizes_set = prefetch_from_bytes_ > 0;  // by a test: set_prefetch_from
  const std::size_t pairs_from = sizes_set ? prefetch_from_bytes_ : prefetch_threshold_bytes;
  const std::size_t window_from = sizes_set ? prefetch_from_bytes_ : pair_window_threshold_bytes;
  prefetch_pairs_ = count * kernel_bytes > pairs_from;
  if constexpr (D == 3) {
    // The arrays of prefetch_particles: those of prefetch_pairs, the positions and the radii.
    constexpr std::size_t window_bytes = kernel_bytes + sizeof(Vec<D>) + sizeof(double);
    const bool window = prefetch_pairs_ && count * window_bytes > window_from;
    pair_window_ =
        window ? pair_window_for(neighbours_.first(), neighbours_.second(), window_bytes) : 0;
  }
  pair_block_ = block_size_for(pairs, 16, min_pair_block, max_pair_block);
  pair_block_ended_.resize(block_count(pairs, pair_block_));
  pair_block_dissipated_.resize(block_count(pairs, pair_block_));

  // Wall candidates: a particle further than a skin from every wall cannot reach one before
  // it has moved half a skin, which triggers the next rebuild. Each candidate has
  // max_wall_contacts slots of wall-contact history, carried over from the last list if it was
  // a candidate then. One that leaves the list has no wall contact left (it is a skin away);
  // any slot it still held ends here. Each thread lists the candidates among its share of the
  // particles (the shares of the step's runs), so that their slots are written by the core
  // that steps them (the 2D SAG scene, two threads: 40 µs a rebuild, against 60 µs on one
  // thread; bench/results.md).
  constexpr auto slots = static_cast<std::size_t>(max_wall_contacts);
  const bool parallel_candidates =
      count >=
      (neighbours_.parallel() ? parallel_candidate_threshold_when_split : parallel_threshold);
  const std::size_t most =
      parallel_candidates ? static_cast<std::size_t>(omp_get_max_threads()) : 1;
  candidate_share_.assign(most + 1, 0);
  if (leaving_slots_.size() < most) leaving_slots_.resize(most);
  is_candidate_.resize(count);
  // The last list's candidate count: the stride of its histories' slots (wall_history_index).
  const std::size_t old_candidates = wall_slot_history_.size() / slots;
  std::size_t team_size = 1;
#pragma omp parallel if (parallel_candidates)
  {
    const auto team = static_cast<std::size_t>(omp_get_num_threads());
    const auto t = static_cast<std::size_t>(omp_get_thread_num());
    const bool as_split = split_particle_.size() == team + 1 && split_particle_[team] == count;
    const std::size_t low = as_split ? split_particle_[t] : count * t / team;
    const std::size_t high = as_split ? split_particle_[t + 1] : count * (t + 1) / team;
    std::uint32_t found = 0;
    for (std::size_t i = low; i < high; ++i) {
      const bool candidate = walls_.may_touch(particles_.position[i], particles_.radius[i], skin);
      is_candidate_[i] = candidate ? 1 : 0;
      found += candidate ? 1U : 0U;
    }
    candidate_share_[t + 1] = found;
#pragma omp barrier
#pragma omp single
    {
      team_size = team;
      for (std::size_t u = 0; u < team; ++u) candidate_share_[u + 1] += candidate_share_[u];
      const std::size_t candidates = candidate_share_[team];
      wall_candidates_.resize(candidates);
      reserve_with_slack(next_wall_slot_id_, candidates * slots);
      reserve_with_slack(next_wall_slot_history_, candidates * slots);
      next_wall_slot_id_.resize(candidates * slots);
      next_wall_slot_history_.resize(candidates * slots);
    }
    std::vector<std::uint32_t>& leaving = leaving_slots_[t];
    leaving.clear();
    std::size_t k = candidate_share_[t];
    const std::size_t new_candidates = candidate_share_[team];
    for (std::size_t i = low; i < high; ++i) {
      const std::uint32_t held = wall_slots_of_[i];
      const std::size_t from = static_cast<std::size_t>(held) * slots;
      if (is_candidate_[i] == 0) {
        wall_slots_of_[i] = no_wall_slots;
        if (held != no_wall_slots) leaving.push_back(held);
        continue;
      }
      wall_slots_of_[i] = static_cast<std::uint32_t>(k);
      wall_candidates_[k] = static_cast<std::uint32_t>(i);
      const std::size_t to = k * slots;
      for (std::size_t slot = 0; slot < slots; ++slot) {
        next_wall_slot_id_[to + slot] = held == no_wall_slots ? -1 : wall_slot_id_[from + slot];
        next_wall_slot_history_[slot * new_candidates + k] =
            held == no_wall_slots ? WallHistory{}
                                  : wall_slot_history_[slot * old_candidates + held];
      }
      ++k;
    }
  }
  candidate_share_.resize(team_size + 1);
  // The collisions of the particles that left, in particle order: recorded as every other
  // collision is (record_ended), in the spectrum and where they began.
  for (std::size_t t = 0; t < team_size && (spectrum_ != nullptr || impacts_ != nullptr); ++t) {
    for (const std::uint32_t held : leaving_slots_[t]) {
      const std::size_t from = static_cast<std::size_t>(held) * slots;
      for (std::size_t slot = 0; slot < slots; ++slot) {
        if (wall_slot_id_[from + slot] < 0) continue;
        const WallHistory& history = wall_slot_history_[slot * old_candidates + held];
        const ContactType type = wall_contact_type(walls_.kind_of(wall_slot_id_[from + slot]));
        if (spectrum_ != nullptr) spectrum_->record(type, history.dissipated);
        if (impacts_ != nullptr) {
          impacts_->record(type, static_cast<float>(history.start_angle), history.dissipated);
        }
      }
    }
  }
  wall_slot_id_.swap(next_wall_slot_id_);
  wall_slot_history_.swap(next_wall_slot_history_);
  const std::size_t candidates = wall_candidates_.size();
  wall_ended_.resize(candidates * max_wall_contacts);
  wall_block_ = block_size_for(candidates, 4, min_wall_block, max_wall_block);
  wall_block_ended_.resize(block_count(candidates, wall_block_));
  wall_block_dissipated_.resize(block_count(candidates, wall_block_));
  wall_block_torque_.resize(block_count(candidates, wall_block_));
  wall_block_work_.resize(block_count(candidates, wall_block_));
  refresh_nearby_lifters();
}

template <int D>
bool World<D>::lifters_moved_too_far() const {
  if (!walls_.mill || nearby_lifters_.size() != wall_candidates_.size()) {
    return nearby_lifter_lists_ && walls_.mill.has_value();
  }
  const auto& mill = *walls_.mill;
  return mill.lifter_count != nearby_lifter_count_ ||
         std::abs(mill.angle - nearby_lifter_angle_) * mill.radius > lifter_travel_;
}

template <int D>
void World<D>::refresh_nearby_lifters() {
  // A candidate moves at most half a skin from where it was at the last rebuild before the
  // next one, so at most a skin from where it is now. The lifters move with the mill; the
  // lists are made again when they have moved lifter_travel_ (here the smallest radius, which
  // on the mills measured is tens to hundreds of steps of turning: seldom before the next
  // rebuild). A lifter the candidate can touch before then is within r + skin + travel now.
  const std::size_t candidates = wall_candidates_.size();
  if (!walls_.mill || !nearby_lifter_lists_) {
    nearby_lifters_.clear();
    return;
  }
  const auto& mill = *walls_.mill;
  const double skin = neighbours_.skin();
  lifter_travel_ = 0.0;
  if (particles_.size() > 0) {
    lifter_travel_ = *std::min_element(particles_.radius.begin(), particles_.radius.end());
  }
  nearby_lifter_angle_ = mill.angle;
  nearby_lifter_count_ = mill.lifter_count;
  ++nearby_lifter_refreshes_;
  nearby_lifters_.resize(candidates);
  // The reach is widened by a part in a million for the rounding of the distances.
  constexpr double rounding = 1.0 + 1e-6;
  // On several threads where the step splits among them (the other core is awake), from a few
  // hundred candidates; otherwise from as many as the other parallel loops.
  const bool parallel =
      candidates >=
      (neighbours_.parallel() ? parallel_candidate_threshold_when_split : parallel_threshold);
  // Each thread the candidates it listed at the last rebuild (refresh_neighbours).
#pragma omp parallel if (parallel)
  {
    const auto team = static_cast<std::size_t>(omp_get_num_threads());
    const auto t = static_cast<std::size_t>(omp_get_thread_num());
    const bool as_listed =
        candidate_share_.size() == team + 1 && candidate_share_[team] == candidates;
    const std::size_t low = as_listed ? candidate_share_[t] : candidates * t / team;
    const std::size_t high = as_listed ? candidate_share_[t + 1] : candidates * (t + 1) / team;
    for (std::size_t k = low; k < high; ++k) {
      const std::size_t i = wall_candidates_[k];
      const Vec<D>& x = particles_.position[i];
      const double reach = rounding * (particles_.radius[i] + skin + lifter_travel_);
      nearby_lifters_[k] = nearby_lifters(mill, Vec2{{x[0], x[1]}}, reach);
    }
  }
}

template <int D>
double World<D>::choose_skin() const {
  const auto& p = particles_;
  if (p.size() == 0) return 0.0;
  double smallest = p.radius[0];
  double fastest_squared = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    smallest = std::min(smallest, p.radius[i]);
    fastest_squared = std::max(fastest_squared, norm_squared(p.velocity[i]));
  }
  const double lasting = 2.0 * skin_target_steps * settings_.time_step * std::sqrt(fastest_squared);
  return std::clamp(lasting, skin_floor * smallest, skin_ceiling<D> * smallest);
}

template <int D>
void World<D>::reorder_particles(const std::vector<std::uint32_t>& previous) {
  // Everything per particle that the step reads after the rebuild is reordered: what lasts
  // from step to step and this step's velocity estimates.
  particles_.for_each_array([&](auto& values) {
    using Element = typename std::decay_t<decltype(values)>::value_type;
    reorder(values, previous, 1, std::get<std::vector<Element>>(reorder_scratch_));
  });
  reorder(particle_id_, previous, 1, std::get<std::vector<std::uint32_t>>(reorder_scratch_));
  // This step's velocity estimates, made before the rebuild.
  reorder(velocity_now_, previous, 1, std::get<std::vector<Vec<D>>>(reorder_scratch_));
  reorder(rim_speed_now_, previous, 1, std::get<std::vector<Spin<D>>>(reorder_scratch_));
  if constexpr (keeps_step_rim) {
    reorder(rim_speed_step_, previous, 1, std::get<std::vector<Spin<D>>>(reorder_scratch_));
  }
  reorder(wall_slots_of_, previous, 1, std::get<std::vector<std::uint32_t>>(reorder_scratch_));
  for (std::size_t k = 0; k < particle_id_.size(); ++k) {
    particle_index_[particle_id_[k]] = static_cast<std::uint32_t>(k);
  }
}

template <int D>
void World<D>::check_uniform_mass() {
  const std::vector<double>& mass = particles_.mass;
  uniform_mass_ =
      uniform_mass_shortcut_ && !mass.empty() &&
      std::all_of(mass.begin(), mass.end(), [&](double m) { return m == mass.front(); });
  if (!uniform_mass_) return;
  // As the kernels would work them out from the two masses (the same operations).
  const double m = mass.front();
  uniform_pair_damping_ = ball_ball_law_.damping(m * m / (m + m));
  uniform_wall_damping_ = ball_wall_law_.damping(m);
}

template <int D>
ParticleStore<D> World<D>::particles_by_id() const {
  std::vector<std::uint32_t> index_of_id(particles_.size());
  for (std::size_t id = 0; id < index_of_id.size(); ++id) {
    index_of_id[id] = static_cast<std::uint32_t>(particle_index(id));
  }
  ParticleStore<D> by_id = particles_;
  by_id.for_each_array([&](auto& values) {
    std::decay_t<decltype(values)> scratch;
    reorder(values, index_of_id, 1, scratch);
  });
  return by_id;
}

template <int D>
void World<D>::record_ended(const std::vector<EndedCollision>& ended,
                            const std::vector<std::uint32_t>& block_ended,
                            std::size_t block_capacity) {
  if (spectrum_ == nullptr && impacts_ == nullptr) return;
  for (std::size_t b = 0; b < block_ended.size(); ++b) {
    for (std::size_t k = 0; k < block_ended[b]; ++k) {
      const EndedCollision& e = ended[b * block_capacity + k];
      if (spectrum_ != nullptr) spectrum_->record(e.type, e.energy);
      if (impacts_ != nullptr) impacts_->record(e.type, e.start_angle, e.energy);
    }
  }
}

template <int D>
void World<D>::advance_walls() {
  if (walls_.mill) {
    walls_.mill->turn_to(walls_.mill->angle + walls_.mill->angular_speed * settings_.time_step);
  }
}

template <int D>
std::size_t World<D>::touching_contacts() const {
  std::size_t count = 0;
  for (const auto t : neighbours_.touching()) count += t == TouchState::touching ? 1 : 0;
  for (const auto id : wall_slot_id_) count += id >= 0 ? 1 : 0;
  return count;
}

template <int D>
double World<D>::kinetic_energy() const {
  double energy = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const double inertia = 1.0 / particles_.inverse_inertia[i];
    energy +=
        0.5 * particles_.mass[i] * norm_squared(particles_.velocity[i]) +
        0.5 * inertia * spin_dot(particles_.angular_velocity[i], particles_.angular_velocity[i]);
  }
  return energy;
}

template <int D>
double World<D>::potential_energy() const {
  double energy = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    energy -= particles_.mass[i] * dot(settings_.gravity, particles_.position[i]);
  }
  return energy;
}

template <int D>
double World<D>::stored_spring_energy() const {
  // The springs as the last step left them, at the overlaps of the positions it started from:
  // u(n) = u(n+1) − u̇(n+½) Δt, to within rounding (a pair's history does not keep its overlap;
  // the kernel's reads of it were 2 % of the 3D step: bench/results.md).
  double energy = 0.0;
  const auto& history = neighbours_.history();
  const auto& touching = neighbours_.touching();
  const auto& first = neighbours_.first();
  const auto& second = neighbours_.second();
  const auto& p = particles_;
  const double dt = settings_.time_step;
  for (std::size_t q = 0; q < history.size(); ++q) {
    if (touching[q] == TouchState::touching) {
      const std::uint32_t i = first[q];
      const std::uint32_t j = second[q];
      const Vec<D> offset = neighbours_.separation(p.position[i] - dt * p.velocity[i],
                                                   p.position[j] - dt * p.velocity[j]);
      const double overlap = p.radius[i] + p.radius[j] - norm(offset);
      energy += ball_ball_law_.stored_energy(history[q], overlap);
    }
  }
  for (std::size_t s = 0; s < wall_slot_id_.size(); ++s) {
    if (wall_slot_id_[s] >= 0) {
      const WallHistory& held =
          wall_slot_history_[wall_history_index(s / max_wall_contacts, s % max_wall_contacts)];
      energy += ball_wall_law_.stored_energy(held, held.overlap);
    }
  }
  return energy;
}

template <int D>
double World<D>::largest_overlap_fraction() const {
  double largest = 0.0;
  const auto& touching = neighbours_.touching();
  const auto& first = neighbours_.first();
  const auto& second = neighbours_.second();
  const auto& p = particles_;
  for (std::size_t q = 0; q < touching.size(); ++q) {
    if (touching[q] != TouchState::touching) continue;
    const std::uint32_t i = first[q];
    const std::uint32_t j = second[q];
    const double overlap =
        p.radius[i] + p.radius[j] - norm(neighbours_.separation(p.position[i], p.position[j]));
    largest = std::max(largest, overlap / std::min(p.radius[i], p.radius[j]));
  }
  for (std::size_t s = 0; s < wall_slot_id_.size(); ++s) {
    if (wall_slot_id_[s] < 0) continue;
    const std::uint32_t i = wall_candidates_[s / max_wall_contacts];
    const WallHistory& held =
        wall_slot_history_[wall_history_index(s / max_wall_contacts, s % max_wall_contacts)];
    largest = std::max(largest, held.overlap / p.radius[i]);
  }
  return largest;
}

// Every member defined here or in world.hpp; the stages' members are instantiated in their
// own files (world_pairs.cpp, world_walls.cpp, world_threads.cpp, world_integrate.cpp).
template class World<2>;
template class World<3>;

}  // namespace millsim
