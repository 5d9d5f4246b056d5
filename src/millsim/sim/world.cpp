#include "millsim/sim/world.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <type_traits>

#include "millsim/core/cpu.hpp"
#include "millsim/core/prefetch.hpp"
#include "millsim/core/vector_growth.hpp"

namespace millsim {
namespace {

ContactType wall_contact_type(WallKind kind) {
  switch (kind) {
    case WallKind::shell:
      return ContactType::ball_shell;
    case WallKind::lifter:
      return ContactType::ball_lifter;
    case WallKind::end_plate:
      return ContactType::ball_end_plate;
    case WallKind::plane:
      return ContactType::ball_plane;
  }
  return ContactType::ball_plane;
}

/// Blocks of pairs and of wall candidates are the unit of parallel work and of partial sums.
/// Their sizes are chosen at each rebuild from the list alone (block_size_for), never from
/// the number of threads, so that results do not depend on it: a sixteenth of the pairs and a
/// quarter of the candidates, rounded up to a power of two within 256–1024 pairs or 64–256
/// candidates (so at most 16 and 4 blocks where the size is not at its largest). Large
/// blocks cost less per pair (the 2D SAG scene, 941 candidates, was 0.7 % slower on two threads
/// in 8 blocks of 128 than in 4 of 256); in a small world, where one block was a third of the
/// list, the blocks that two threads' runs share (done one pair at a time, or by one thread for
/// both) held up the step (bench/results.md).
constexpr std::size_t min_pair_block = 256;
constexpr std::size_t max_pair_block = 1024;
constexpr std::size_t min_wall_block = 64;
constexpr std::size_t max_wall_block = 256;
/// Below this many items a stage runs on one thread (a parallel region costs microseconds).
constexpr std::size_t parallel_threshold = 2048;
/// The fewest wall candidates whose nearby lifters are found on several threads in a world
/// whose step splits among them.
constexpr std::size_t parallel_candidate_threshold_when_split = 256;
/// The pair stage, and with it the particle stages, split among threads from this many listed
/// pairs, where two threads and one break even: below it the threads' barriers cost more than
/// the split saves (the 3D scaling slab of 996 balls and 2 500 pairs on two threads against
/// one: 1.1 times faster on an Intel host, 0.85 times on an AMD one, which broke even at about
/// 5 000 pairs; bench/results.md).
constexpr std::size_t parallel_pair_threshold = 2048;
/// The same for the old three-stage path's wall stage, whose candidates cost tens of pairs
/// each: from 512 on (the 2D SAG scene has about a thousand candidates; on one thread they held
/// the other one waiting for 3 % of the step).
constexpr std::size_t parallel_wall_threshold = 2 * max_wall_block;

/// The block size for a list of `items`: items / blocks rounded up to a power of two, within
/// [smallest, largest].
std::size_t block_size_for(std::size_t items, std::size_t blocks, std::size_t smallest,
                           std::size_t largest) {
  return std::clamp(std::bit_ceil(std::max<std::size_t>(1, items / blocks)), smallest, largest);
}

}  // namespace

std::vector<double> balanced_run_shares(const std::vector<double>& shares,
                                        const std::vector<double>& weights,
                                        const std::vector<double>& seconds) {
  const std::size_t runs = shares.size();
  bool timed = weights.size() >= runs && seconds.size() >= runs;
  for (std::size_t r = 0; timed && r < runs; ++r) timed = weights[r] > 0.0 && seconds[r] > 0.0;
  double speeds = 0.0;
  for (std::size_t r = 0; timed && r < runs; ++r) speeds += weights[r] / seconds[r];
  const double even = 1.0 / static_cast<double>(runs);
  std::vector<double> balanced(runs);
  double total = 0.0;
  for (std::size_t r = 0; r < runs; ++r) {
    // Untimed (a run left empty, say), the shares are only brought within bounds, so that
    // every run holds some weight and is timed next time.
    const double aim =
        timed ? shares[r] + run_share_gain * (weights[r] / seconds[r] / speeds - shares[r])
              : shares[r];
    balanced[r] = std::clamp(aim, 0.5 * even, 2.0 * even);
    total += balanced[r];
  }
  for (double& share : balanced) share /= total;
  return balanced;
}

namespace {

/// Whether a list of `pairs` splits the step among `threads` threads.
bool splits_among_threads(std::size_t pairs, int threads) {
  return threads > 1 && pairs >= parallel_pair_threshold;
}
/// When the particle arrays that the pair kernel reads and writes hold more than this many
/// bytes, half a core's second-level cache here, the kernel prefetches the particles and
/// history of the pairs two lanes ahead: the second particle of a pair is met out of order and
/// comes from beyond that cache otherwise. Below it the prefetches cost more than they save
/// (bench/results.md, sixteenth session: the 2D SAG scene, 0.6 MB, 5–7 % slower with them; the
/// 1e4-ball slab, 1.5 MB, 2–4 % faster; the 3D 20 k scene and the LIGGGHTS comparison's, 3 MB,
/// 3–8 % faster; the 1e5-ball slab, 15 MB, +10 % in the eleventh).
constexpr std::size_t prefetch_threshold_bytes = std::size_t{1} << 20;

std::size_t block_count(std::size_t items, std::size_t block) {
  return (items + block - 1) / block;
}

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

/// The moment about the mill axis (+z) of a force applied at a point.
double axial_moment(const Vec2& point, const Vec2& force) {
  return cross(point, force);
}
double axial_moment(const Vec3& point, const Vec3& force) {
  return point[0] * force[1] - point[1] * force[0];
}

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
  prefetch_pairs_ = count * kernel_bytes > prefetch_threshold_bytes;
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
        next_wall_slot_history_[to + slot] =
            held == no_wall_slots ? WallHistory{} : wall_slot_history_[from + slot];
      }
      ++k;
    }
  }
  candidate_share_.resize(team_size + 1);
  // The collisions of the particles that left, in particle order.
  for (std::size_t t = 0; t < team_size && spectrum_ != nullptr; ++t) {
    for (const std::uint32_t held : leaving_slots_[t]) {
      const std::size_t from = static_cast<std::size_t>(held) * slots;
      for (std::size_t slot = from; slot < from + slots; ++slot) {
        if (wall_slot_id_[slot] < 0) continue;
        spectrum_->record(wall_contact_type(walls_.kind_of(wall_slot_id_[slot])),
                          wall_slot_history_[slot].dissipated);
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
  reorder(rim_speed_step_, previous, 1, std::get<std::vector<Spin<D>>>(reorder_scratch_));
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
bool World<D>::pairs_split_among_threads() {
  const int threads = omp_get_max_threads();
  const std::size_t pairs = neighbours_.pair_count();
  if (!splits_among_threads(pairs, threads)) return false;
  if (threads != split_threads_ || neighbours_.rebuild_count() != split_rebuild_ ||
      split_pair_.back() != pairs) {
    split_pairs_among(threads);
  }
  return true;
}

template <int D>
template <class Body>
void World<D>::for_each_particle(Body&& body) {
  for_each_particle_run([&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) body(i);
    return false;
  });
}

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
  rim_speed_step_.resize(count);
  const double half_step = 0.5 * settings_.time_step;
  const auto& p = particles_;
  // Particles added since the last list: it must be made again.
  const bool added = count != neighbours_.built_count();
  const bool moved = for_each_particle_run([&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      velocity_now_[i] = estimate_now(p.velocity[i], p.inverse_mass[i], p.force[i], half_step);
      rim_speed_now_[i] = p.radius[i] * estimate_now(p.angular_velocity[i], p.inverse_inertia[i],
                                                     p.torque[i], half_step);
      rim_speed_step_[i] = p.radius[i] * p.angular_velocity[i];
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
    if (!(velocity == velocity_now_[i]) || !(p.radius[i] * spin == rim_speed_now_[i]) ||
        !(p.radius[i] * p.angular_velocity[i] == rim_speed_step_[i]) ||
        (neighbours_.moved_too_far(i, p.position[i]) && !moved_half_skin_)) {
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
void World<D>::split_pairs_among(int threads) {
  // Thread t owns the particles [split_particle_[t], split_particle_[t + 1]) and the pairs whose
  // first particle is one of them, a run of the list (sorted by first) of about the same cost.
  const auto& first_begin = neighbours_.first_begin();
  const auto& second = neighbours_.second();
  const std::size_t count = particles_.size();
  const std::size_t pairs = second.size();
  const auto ranges = static_cast<std::size_t>(threads);
  // Weighed by their cost: a pair that touches (the contact law after the distance test) costs
  // about eight times one that does not (the distance test alone). On the 2D SAG scene's two
  // threads, with a weight of 4 the thread holding the dense bottom of the charge finished its
  // pairs 12 % later than the other; with 8, 3 % (bench/results.md).
  const auto& touching = neighbours_.touching();
  const auto pair_weight = [&touching](std::size_t q) -> std::size_t {
    constexpr std::size_t touching_weight = 8;
    return touching[q] == TouchState::touching ? touching_weight : 1;
  };
  std::size_t total = 0;
  for (std::size_t q = 0; q < pairs; ++q) total += pair_weight(q);
  // The weight does not count everything a run costs (its wall candidates, the blocks it
  // shares), and one core may be slower than the other for a while: each run's share of the
  // weight follows what its thread measured since the last split (balanced_run_shares).
  if (split_share_.size() != ranges) {
    split_share_.assign(ranges, 1.0 / static_cast<double>(ranges));
  } else if (split_weight_.size() == ranges && run_seconds_.size() == ranges) {
    split_share_ = balanced_run_shares(split_share_, split_weight_, run_seconds_);
  }
  run_seconds_.assign(ranges, 0.0);
  split_weight_.assign(ranges, 0.0);
  split_particle_.assign(ranges + 1, static_cast<std::uint32_t>(count));
  split_pair_.assign(ranges + 1, static_cast<std::uint32_t>(pairs));
  split_particle_[0] = 0;
  split_pair_[0] = 0;
  std::size_t t = 1;
  std::size_t weight = 0;
  std::size_t run_start_weight = 0;
  double ends_at = split_share_[0] * static_cast<double>(total);  // where run t − 1 ends
  for (std::size_t i = 0; i < count && t < ranges; ++i) {
    // Particle i starts range t once the ranges before it hold their shares of the weight.
    while (t < ranges && static_cast<double>(weight) >= ends_at) {
      split_particle_[t] = static_cast<std::uint32_t>(i);
      split_pair_[t] = first_begin[i];
      // Each run's weight, for the next split's measure of its speed.
      split_weight_[t - 1] = static_cast<double>(weight - run_start_weight);
      run_start_weight = weight;
      ends_at += split_share_[t] * static_cast<double>(total);
      ++t;
    }
    for (std::uint32_t q = first_begin[i]; q < first_begin[i + 1]; ++q) weight += pair_weight(q);
  }
  split_weight_[t - 1] = static_cast<double>(total - run_start_weight);
  // Pairs whose second particle belongs to a later thread than their first (pairs are stored
  // with first < second, so never an earlier one).
  cross_pairs_.clear();
  for (std::size_t range = 0; range < ranges; ++range) {
    for (std::size_t q = split_pair_[range]; q < split_pair_[range + 1]; ++q) {
      if (second[q] >= split_particle_[range + 1])
        cross_pairs_.push_back(static_cast<std::uint32_t>(q));
    }
  }
  cross_force_.resize(cross_pairs_.size());
  // The cross pairs by the run of their second particle, whose thread evaluates them
  // (do_cross_pairs): a counting sort that keeps them in pair order within each run.
  const auto run_of = [&](std::uint32_t particle) {
    return static_cast<std::size_t>(
        std::upper_bound(split_particle_.begin(), split_particle_.end(), particle) -
        split_particle_.begin() - 1);
  };
  cross_of_run_begin_.assign(ranges + 1, 0);
  for (const std::uint32_t q : cross_pairs_) ++cross_of_run_begin_[run_of(second[q]) + 1];
  for (std::size_t run = 0; run < ranges; ++run) {
    cross_of_run_begin_[run + 1] += cross_of_run_begin_[run];
  }
  cross_of_run_.resize(cross_pairs_.size());
  std::vector<std::uint32_t> cursor(cross_of_run_begin_.begin(), cross_of_run_begin_.end() - 1);
  for (std::size_t c = 0; c < cross_pairs_.size(); ++c) {
    cross_of_run_[cursor[run_of(second[cross_pairs_[c]])]++] = static_cast<std::uint32_t>(c);
  }
  // Blocks of pairs that one thread cannot go through alone: those split between two runs and
  // those holding a cross pair.
  block_mixed_.assign(block_count(pairs, pair_block_), 0);
  split_blocks_.clear();
  for (std::size_t range = 1; range < ranges; ++range) {
    const std::size_t q = split_pair_[range];
    if (q % pair_block_ == 0 || q >= pairs) continue;
    block_mixed_[q / pair_block_] = 1;
    if (split_blocks_.empty() || split_blocks_.back() != q / pair_block_) {
      split_blocks_.push_back(static_cast<std::uint32_t>(q / pair_block_));
    }
  }
  for (const std::uint32_t q : cross_pairs_) block_mixed_[q / pair_block_] = 1;
  // How many runs hold pairs of each split block: the last of them to finish its part sums
  // the block (finish_mixed_part).
  split_block_parts_.assign(split_blocks_.size(), 0);
  for (std::size_t k = 0; k < split_blocks_.size(); ++k) {
    const std::size_t block_begin = std::size_t{split_blocks_[k]} * pair_block_;
    const std::size_t block_end = std::min(pairs, block_begin + pair_block_);
    for (std::size_t range = 0; range < ranges; ++range) {
      if (std::max<std::size_t>(block_begin, split_pair_[range]) <
          std::min<std::size_t>(block_end, split_pair_[range + 1])) {
        ++split_block_parts_[k];
      }
    }
  }
  split_threads_ = threads;
  split_rebuild_ = neighbours_.rebuild_count();
}

template <int D>
typename World<D>::PairOutcome World<D>::evaluate_pair(std::size_t q, PairForce& out) {
  const auto& x = particles_.position;
  const auto& v = velocity_now_;
  const auto& rim = rim_speed_now_;
  const auto& step_v = particles_.velocity;
  const auto& step_rim = rim_speed_step_;
  const auto& m = particles_.mass;
  auto& history = neighbours_.history();
  auto& touching = neighbours_.touching();
  const std::uint32_t i = neighbours_.first()[q];
  const std::uint32_t j = neighbours_.second()[q];
  const Vec<D> offset = neighbours_.separation(x[i], x[j]);
  const double distance_squared = norm_squared(offset);
  const double reach = neighbours_.reach()[q];
  if (distance_squared >= reach * reach) {
    if (touching[q] == TouchState::apart) return {PairStatus::apart, 0.0};
    const double energy = history[q].dissipated;
    history[q] = ContactHistory<D>{};
    touching[q] = TouchState::apart;
    return {PairStatus::ended, energy};
  }
  const double distance = std::sqrt(distance_squared);
  ContactInput<D> in;
  in.normal = offset * (1.0 / distance);
  in.overlap = reach - distance;
  in.velocity = v[j] - v[i];
  in.spin_velocity = spin_sliding(in.normal, rim[i] + rim[j]);
  in.step_velocity = step_v[j] - step_v[i];
  in.step_spin_velocity = spin_sliding(in.normal, step_rim[i] + step_rim[j]);
  touching[q] = TouchState::touching;
  // The dashpots' coefficients from the pair's effective mass, worked out here rather than
  // read from a per-pair array made at each rebuild, whose entries, read only for the few
  // listed pairs that touch, missed the cache.
  const ContactDamping damping = ball_ball_law_.damping(m[i] * m[j] / (m[i] + m[j]));
  const ContactOutput<D> result =
      ball_ball_law_.evaluate(in, damping, history[q], settings_.time_step);
  out = {result.force, -cross(in.normal, result.tangential_force)};
  return {PairStatus::touching, result.dissipated};
}

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
  // AVX2 a fifth that takes four pairs at a time: in 3D worlds that are not periodic, and in 2D
  // worlds small enough for the caches (a larger one keeps the one-by-one loop, which fetches
  // the position of the pair 64 ahead's second particle; bench/results.md).
  const bool every_pair = below >= particles_.size();
  std::size_t count = 0;
  if (neighbours_.period() > 0.0) {
    count = every_pair ? list_pairs_of<true, true>(begin, end, below, listed)
                       : list_pairs_of<true, false>(begin, end, below, listed);
#if defined(__x86_64__)
  } else if (every_pair && avx2_lanes_ && (D == 3 || !prefetch_pairs_)) {
    count = list_pairs_avx2(begin, end, listed);
#endif
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
std::size_t World<D>::list_pairs_avx2(std::size_t begin, std::size_t end,
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
    std::size_t count = 0;
    std::size_t q = begin;
    for (; q + lanes <= end; q += lanes) {
      std::array<std::uint32_t, lanes> i{}, j{};
      for (std::size_t l = 0; l < lanes; ++l) {
        i[l] = first[q + l];
        j[l] = second[q + l];
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
        const Lanes dz = gather_lanes([&](std::size_t l) { return x[j[l]][2] - x[i[l]][2]; });
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
      // The kept pairs' numbers written at once, in order; the rest of the four is overwritten
      // by the next ones (or repeats, or is left beyond the count).
      FourIndices numbers{};
      std::memcpy(&numbers, kept_lanes[keep].lanes.data(), sizeof numbers);
      numbers += static_cast<std::uint32_t>(q);
      std::memcpy(listed + count, &numbers, sizeof numbers);
      count += kept_lanes[keep].count;
    }
    return count + list_pairs_of<false, true>(q, end, end, listed + count);
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
                                     bool each_apart) {
#if defined(__x86_64__)
  if (avx2_lanes_) {
    evaluate_listed_pairs_avx2(block, listed, count, dissipated, ended, each_apart);
    return;
  }
#endif
  // Compiled for each value of each_apart (the kernel is inlined), so that no pair asks.
  if (each_apart) {
    evaluate_listed_pairs_in_lanes(block, listed, count, dissipated, ended, true);
  } else {
    evaluate_listed_pairs_in_lanes(block, listed, count, dissipated, ended, false);
  }
}

#if defined(__x86_64__)
template <int D>
void World<D>::evaluate_listed_pairs_avx2(std::size_t block, const std::uint32_t* listed,
                                          std::size_t count, double& dissipated,
                                          std::uint32_t& ended, bool each_apart) {
  if (each_apart) {
    evaluate_listed_pairs_in_lanes(block, listed, count, dissipated, ended, true);
  } else {
    evaluate_listed_pairs_in_lanes(block, listed, count, dissipated, ended, false);
  }
}
#endif

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
      __builtin_prefetch(&rim_speed_step_[i]);
      if (!uniform_mass_) __builtin_prefetch(&p.mass[i]);
      __builtin_prefetch(&p.force[i], 1);
      __builtin_prefetch(&p.torque[i], 1);
    }
  }
}

template <int D>
void World<D>::evaluate_listed_pairs_in_lanes(std::size_t block, const std::uint32_t* listed,
                                              std::size_t count, double& dissipated_sum,
                                              std::uint32_t& ended_count, bool each_apart) {
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
  const auto& step_rim = rim_speed_step_;
  const auto& r = particles_.radius;
  auto& history = neighbours_.history();
  auto& touching = neighbours_.touching();
  const double dt = settings_.time_step;
  const std::size_t begin = block * pair_block_;
  const bool periodic = neighbours_.period() > 0.0;

  for (std::size_t k = 0; k < count; k += lanes) {
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
      if (periodic) {
        std::array<Vec<D>, lanes> offset;
        for (std::size_t l = 0; l < lanes; ++l)
          offset[l] = neighbours_.separation(p.position[i[l]], p.position[j[l]]);
        for (int d = 0; d < D; ++d) {
          separation[d] = gather_lanes([&](std::size_t l) { return offset[l][d]; });
        }
      } else {
        const Vec<2, T> planar = planar_lanes(p.position);
        separation = {{planar[0], planar[1], axial_lanes(p.position)}};
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
                                           return step_rim[i[l]] + step_rim[j[l]];
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
        subtract_from(particles_.force[i[l]], force_of[l]);
        add_to(particles_.force[j[l]], force_of[l]);
        particles_.torque[i[l]] += r[i[l]] * moment[l];
        particles_.torque[j[l]] += r[j[l]] * moment[l];
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
        particles_.force[i[l]] -= f;
        particles_.force[j[l]] += f;
        Vec3 turn;
        for (int d = 0; d < 3; ++d) turn[d] = moment[d][l];
        particles_.torque[i[l]] += r[i[l]] * turn;
        particles_.torque[j[l]] += r[j[l]] * turn;
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
void World<D>::evaluate_wall_block(std::size_t b, WallSum* kept) {
  const double dt = settings_.time_step;
  const std::size_t candidates = wall_candidates_.size();
  double torque = 0.0;
  double work = 0.0;
  double dissipated = 0.0;
  std::uint32_t ended = 0;
  EndedCollision* block_ended = &wall_ended_[b * wall_block_ * max_wall_contacts];
  const std::size_t begin = b * wall_block_;
  const std::size_t end = std::min(candidates, begin + wall_block_);
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
  for (std::size_t k = begin; k < end; ++k) {
    const std::uint32_t i = wall_candidates_[k];
    std::int32_t* slot_id = &wall_slot_id_[k * max_wall_contacts];
    if (quick && nearby_lifters_[k].count == 0 && clear_of_shell_and_ends(i, shell_radius) &&
        std::all_of(slot_id, slot_id + max_wall_contacts, [](std::int32_t id) { return id < 0; })) {
      first_work[k - begin + 1] = static_cast<std::uint32_t>(found);
      continue;
    }
    WallHistory* slot_history = &wall_slot_history_[k * max_wall_contacts];
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
        if (slot == max_wall_contacts) continue;  // cannot happen: see max_wall_contacts
        slot_id[slot] = wall_id;
        // A collision begins: where, for ShellImpacts (its history is fresh, all zero).
        slot_history[slot].start_angle = std::atan2(contact[c].point[1], contact[c].point[0]);
      }
      seen |= 1U << static_cast<unsigned>(slot);
      // The slot's history, which the law reads and writes once the block's contacts are found:
      // in a large world it is in memory, one slot here and there.
      if (prefetch_pairs_) prefetch_record(slot_history[slot], true);
      if (kept_count != c) contact[kept_count] = contact[c];
      WallWork& work_of = work_list[found + static_cast<std::size_t>(kept_count)];
      work_of.particle = i;
      work_of.slot =
          static_cast<std::uint32_t>(k * max_wall_contacts) + static_cast<std::uint32_t>(slot);
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
      block_ended[ended++] = {.type = wall_contact_type(walls_.kind_of(slot_id[slot])),
                              .start_angle = static_cast<float>(slot_history[slot].start_angle),
                              .energy = slot_history[slot].dissipated};
      slot_history[slot] = WallHistory{};
      slot_id[slot] = -1;
    }
  }
  evaluate_wall_laws(found_list.data(), work_list.data(), found);
  for (std::size_t k = begin; k < end; ++k) {
    // A candidate touching no wall adds nothing: its sums, begun at +0 and so never −0 (in
    // round-to-nearest x + y is −0 only if both are), would stay the same bits.
    if (first_work[k - begin] == first_work[k - begin + 1]) {
      if (kept != nullptr) kept[k - begin].touches = false;
      continue;
    }
    const std::uint32_t i = wall_candidates_[k];
    Vec<D> force{};
    Spin<D> moment{};
    for (std::uint32_t w = first_work[k - begin]; w < first_work[k - begin + 1]; ++w) {
      const WallWork& done = work_list[w];
      const WallContact<D>& contact = found_list[w];
      force += done.force;
      moment += done.moment;
      dissipated += done.dissipated;
      if (contact.kind != WallKind::plane) {
        torque += axial_moment(contact.point, done.force);
        work += dot(done.force, contact.wall_velocity) * dt;
      }
    }
    // Added to the particle's sums after its pairs (they are all done), before gravity; or
    // kept to be added then.
    if (kept != nullptr) {
      kept[k - begin] = {force, moment, true};
      continue;
    }
    particles_.force[i] += force;
    particles_.torque[i] += moment;
  }
  wall_block_torque_[b] = torque;
  wall_block_work_[b] = work;
  wall_block_dissipated_[b] = dissipated;
  wall_block_ended_[b] = ended;
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
    in.step_spin_velocity = spin_sliding(in.normal, gather_spin_lanes<D>([&](std::size_t l) {
                                           return rim_speed_step_[particle(l)];
                                         }));
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
bool World<D>::integrate_run(std::size_t begin, std::size_t end) {
#if defined(__x86_64__)
  if (avx2_lanes_) return integrate_particles_avx2(begin, end);
#endif
  if (neighbours_.period() > 0.0) return integrate_particles<true>(begin, end);
  return integrate_particles<false>(begin, end);
}

template <int D>
bool World<D>::stages_on_one_thread() {
  if (particles_.size() != neighbours_.built_count()) return false;
  if (omp_get_max_threads() == 1) return true;
  return !pairs_split_among_threads() && wall_candidates_.size() < parallel_wall_threshold &&
         particles_.size() < parallel_threshold;
}

template <int D>
bool World<D>::run_stages_in_one_pass() {
  const std::size_t count = particles_.size();
  zero_sums(0, count);
  const auto& first = neighbours_.first();
  const std::size_t pairs = first.size();
  const std::size_t blocks = pair_block_ended_.size();
  ParticleRun run(*this, 0, count, 0, wall_candidates_.size());
  for (std::size_t b = 0; b < blocks; ++b) {
    evaluate_pair_block(b);
    const std::size_t next = (b + 1) * pair_block_;
    run.advance_below(next < pairs ? std::size_t{first[next]} : count);
  }
  run.advance_below(count);
  finish_pair_stage();
  finish_wall_stage();
  return run.moved;
}

template <int D>
World<D>::ParticleRun::ParticleRun(World& world, std::size_t particle_begin,
                                   std::size_t particle_end, std::size_t candidate_begin,
                                   std::size_t candidate_end)
    : world_(world),
      advanced_(particle_begin),
      particle_end_(particle_end),
      candidate_begin_(candidate_begin),
      candidate_end_(candidate_end),
      next_wall_block_(candidate_begin / world.wall_block_),
      wall_block_end_(candidate_begin < candidate_end
                          ? block_count(candidate_end, world.wall_block_)
                          : candidate_begin / world.wall_block_) {}

template <int D>
void World<D>::ParticleRun::advance_below(std::size_t complete) {
  // Wall candidates are listed in particle order: a wall block can be done once every one of
  // its candidates has all its pair forces.
  const auto& candidates = world_.wall_candidates_;
  while (next_wall_block_ < wall_block_end_) {
    const std::size_t block_begin = next_wall_block_ * world_.wall_block_;
    const std::size_t block_end = std::min(candidates.size(), block_begin + world_.wall_block_);
    const std::size_t begin = std::max(block_begin, candidate_begin_);
    const std::size_t end = std::min(block_end, candidate_end_);
    if (candidates[end - 1] >= complete) break;
    if (begin == block_begin && end == block_end) {
      world_.evaluate_wall_block(next_wall_block_);
    } else {
      // A block shared with another run, done apart, its candidates' sums kept.
      const std::size_t shared = world_.shared_wall_block_index(next_wall_block_);
      world_.do_shared_wall_block(shared);
      const WallSum* kept = &world_.shared_wall_sums_[shared * world_.wall_block_];
      for (std::size_t k = begin; k < end; ++k) {
        const WallSum& sum = kept[k - block_begin];
        if (!sum.touches) continue;
        world_.particles_.force[candidates[k]] += sum.force;
        world_.particles_.torque[candidates[k]] += sum.moment;
      }
    }
    ++next_wall_block_;
  }
  std::size_t ready = std::min(complete, particle_end_);
  if (next_wall_block_ < wall_block_end_) {
    ready = std::min<std::size_t>(
        ready, candidates[std::max(next_wall_block_ * world_.wall_block_, candidate_begin_)]);
  }
  if (ready > advanced_) {
    moved = world_.integrate_run(advanced_, ready) || moved;
    advanced_ = ready;
  }
}

template <int D>
void World<D>::zero_sums(std::size_t begin, std::size_t end) {
  // All bits zero is +0 in every component.
  std::memset(static_cast<void*>(particles_.force.data() + begin), 0,
              (end - begin) * sizeof(Vec<D>));
  std::memset(static_cast<void*>(particles_.torque.data() + begin), 0,
              (end - begin) * sizeof(Spin<D>));
}

template <int D>
std::size_t World<D>::shared_wall_block_index(std::size_t block) const {
  return static_cast<std::size_t>(
      std::lower_bound(shared_wall_blocks_.begin(), shared_wall_blocks_.end(), block) -
      shared_wall_blocks_.begin());
}

namespace {

/// Work shared by the threads of one step (World's shared wall blocks and cross pairs), done
/// once by whichever thread comes to it first while the others wait for it. The flag holds
/// 2 s + 1 once step s has done it, 2 s while a thread does it; earlier steps left less.
template <class Work>
void do_once_in_step(std::atomic<std::uint64_t>& flag, std::uint64_t step, Work&& work) {
  const std::uint64_t taken = 2 * step;
  const std::uint64_t done = taken + 1;
  std::uint64_t seen = flag.load(std::memory_order_acquire);
  if (seen < taken && flag.compare_exchange_strong(seen, taken, std::memory_order_acquire)) {
    work();
    flag.store(done, std::memory_order_release);
    flag.notify_all();
    return;
  }
  // Another thread has taken it: wait until it is done.
  while (seen != done) {
    flag.wait(seen, std::memory_order_acquire);
    seen = flag.load(std::memory_order_acquire);
  }
}

}  // namespace

template <int D>
void World<D>::do_shared_wall_block(std::size_t k) {
  do_once_in_step(shared_wall_done_[k], split_step_count_, [&] {
    evaluate_wall_block(shared_wall_blocks_[k], &shared_wall_sums_[k * wall_block_]);
  });
}

template <int D>
void World<D>::do_cross_pairs(std::size_t run) {
  if (cross_of_run_begin_[run] == cross_of_run_begin_[run + 1]) return;
  do_once_in_step(cross_done_[run], split_step_count_, [&] {
    for (std::size_t k = cross_of_run_begin_[run]; k < cross_of_run_begin_[run + 1]; ++k) {
      const std::uint32_t c = cross_of_run_[k];
      const std::uint32_t q = cross_pairs_[c];
      const PairOutcome outcome = evaluate_pair(q, cross_force_[c]);
      pair_status_[q] = outcome.status;
      pair_energy_[q] = outcome.energy;
    }
  });
}

template <int D>
void World<D>::finish_mixed_part(std::size_t b) {
  const auto split = std::lower_bound(split_blocks_.begin(), split_blocks_.end(), b);
  if (split != split_blocks_.end() && *split == b) {
    const auto k = static_cast<std::size_t>(split - split_blocks_.begin());
    // Each run's part done, then counted (release); the thread of the last part sees them all
    // (acquire) and sums the block.
    if (split_block_done_[k].fetch_add(1, std::memory_order_acq_rel) + 1 < split_block_parts_[k])
      return;
  }
  // Every pair's outcome in pair order, as one thread going through the block sums them.
  double dissipated = 0.0;
  std::uint32_t ended = 0;
  const std::size_t end = std::min(pair_status_.size(), (b + 1) * pair_block_);
  for (std::size_t q = b * pair_block_; q < end; ++q) {
    if (pair_status_[q] == PairStatus::touching) {
      dissipated += pair_energy_[q];
    } else if (pair_status_[q] == PairStatus::ended) {
      pair_ended_[b * pair_block_ + ended++] = {.type = ContactType::ball_ball,
                                                .energy = pair_energy_[q]};
    }
  }
  pair_block_dissipated_[b] = dissipated;
  pair_block_ended_[b] = ended;
}

template <int D>
bool World<D>::run_stages_split_among_threads() {
  // Thread t owns a run of particles and the pairs whose first particle is one of them
  // (split_pairs_among), and goes through the three stages on them interleaved, as
  // run_stages_in_one_pass does on one thread; the sums of every particle are made in the same
  // order. A pair whose second particle belongs to a later run (a cross pair: 1.5 % of the 3D
  // 20 k scene's on two threads) is evaluated by that run's thread first thing
  // (do_cross_pairs); the thread then zeroes its particles, adds the cross pairs' forces to
  // their second particles (they come before any of its own pairs in pair order), and goes
  // down its own pairs, adding each one's force to both particles, or, for a cross pair, the
  // stored force to the first, which waits for the later runs' cross pairs at its first block
  // that holds one (near its run's end, long after they were done). A block of pairs that lies
  // in one run and holds no cross pair is gone through as on one thread (evaluate_pair_block);
  // in the others (mixed: at most a few per run) each pair's dissipation and end are kept apart
  // and summed in the same order by the last run to finish its part (finish_mixed_part).
  // (Keeping every pair's apart cost a third more instructions per pair: callgrind, the 2D SAG
  // scene.) So the runs wait for each other only where a flag says they must, and the step has
  // one barrier, at the region's end: with a barrier after the cross pairs and another before
  // the mixed blocks' sums, the 3D slab of 996 balls ran 5–10 % slower on two threads
  // (bench/results.md). A wall block is done by the thread that owns its candidates'
  // particles, whose arrays are in its core's cache and whose sums it alone writes (on the 2D
  // SAG scene, handing wall blocks to whichever thread came free moved those arrays between the
  // cores at every step and cost 8 % of the step: bench/results.md). A block whose candidates
  // belong to two threads is done by the later one first thing (do_shared_wall_block), each
  // candidate's sums kept until its own thread adds them; the earlier thread needs it only at
  // the end of its run. (Done before the barrier instead, it held the other thread waiting: 2D
  // SAG, two threads, 2 % slower.)
  const auto& first = neighbours_.first();
  const auto& second = neighbours_.second();
  const auto& r = particles_.radius;
  auto& force = particles_.force;
  auto& torque = particles_.torque;
  const std::size_t pairs = first.size();
  const std::size_t candidates = wall_candidates_.size();
  const auto ranges = static_cast<std::size_t>(split_threads_);
  split_candidate_.resize(ranges + 1);
  shared_wall_blocks_.clear();
  for (std::size_t t = 0; t <= ranges; ++t) {
    split_candidate_[t] = static_cast<std::uint32_t>(
        std::lower_bound(wall_candidates_.begin(), wall_candidates_.end(), split_particle_[t]) -
        wall_candidates_.begin());
    const std::size_t k = split_candidate_[t];
    if (t > 0 && t < ranges && k % wall_block_ != 0 && k < candidates &&
        (shared_wall_blocks_.empty() || shared_wall_blocks_.back() != k / wall_block_)) {
      shared_wall_blocks_.push_back(static_cast<std::uint32_t>(k / wall_block_));
    }
  }
  shared_wall_sums_.resize(shared_wall_blocks_.size() * wall_block_);
  shared_wall_done_.reserve(shared_wall_blocks_.size());
  cross_done_.reserve(ranges);
  ++split_step_count_;
  split_block_done_.reserve(split_blocks_.size());
  for (std::size_t k = 0; k < split_blocks_.size(); ++k) {
    split_block_done_[k].store(0, std::memory_order_relaxed);  // before the threads start
  }
  pair_status_.resize(pairs);
  pair_energy_.resize(pairs);
  const std::size_t crossing = cross_pairs_.size();
  bool moved = false;
#pragma omp parallel num_threads(split_threads_) reduction(|| : moved)
  {
    const auto team = static_cast<std::size_t>(omp_get_num_threads());
    for (auto t = static_cast<std::size_t>(omp_get_thread_num()); t < ranges; t += team) {
      const double run_start = omp_get_wtime();
      const std::uint32_t own_begin = split_particle_[t];
      const std::uint32_t own_end = split_particle_[t + 1];
      // The cross pairs into this run, whose forces its particles take before any other.
      do_cross_pairs(t);
      // A wall block shared with earlier runs that holds this run's first candidates: done now,
      // as a rule before the earlier run's thread needs it at the end of its run (a block is
      // done by whichever thread comes to it first, so that no thread waits for itself).
      const std::size_t k = split_candidate_[t];
      if (k % wall_block_ != 0 && k < candidates) {
        do_shared_wall_block(shared_wall_block_index(k / wall_block_));
      }
      zero_sums(own_begin, own_end);
      for (std::size_t c = 0; c < crossing; ++c) {
        const std::uint32_t q = cross_pairs_[c];
        const std::uint32_t j = second[q];
        if (j >= own_begin && j < own_end && pair_status_[q] == PairStatus::touching) {
          force[j] += cross_force_[c].force;
          torque[j] += r[j] * cross_force_[c].moment;
        }
      }
      ParticleRun run(*this, own_begin, own_end, split_candidate_[t], split_candidate_[t + 1]);
      std::size_t c = static_cast<std::size_t>(
          std::lower_bound(cross_pairs_.begin(), cross_pairs_.end(), split_pair_[t]) -
          cross_pairs_.begin());
      const std::size_t own_pairs_end = split_pair_[t + 1];
      bool crosses_known = false;
      std::size_t q = split_pair_[t];
      while (q < own_pairs_end) {
        const std::size_t b = q / pair_block_;
        if (!block_mixed_[b]) {
          evaluate_pair_block(b);  // which starts at q and ends in this run
          q = std::min(pairs, (b + 1) * pair_block_);
        } else {
          // This run's part of a block shared with another run or holding cross pairs: its own
          // pairs through the kernel, each one's outcome kept apart; then the cross pairs'
          // forces on their first particles, in pair order. That is each particle's order as
          // on one thread: a particle's pairs as the first are sorted by the second, and a
          // cross pair's second lies beyond this run, so its cross pairs come after all its
          // other pairs, and no pair after them in the list holds it.
          const std::size_t end = std::min(own_pairs_end, (b + 1) * pair_block_);
          if (!crosses_known && c < crossing && cross_pairs_[c] < end) {
            // The first block holding a cross pair out of this run, whose contact the listing
            // below reads: the later runs' threads evaluated theirs at their start (a run not
            // yet begun has them evaluated here).
            for (std::size_t later = t + 1; later < ranges; ++later) do_cross_pairs(later);
            crosses_known = true;
          }
          for (std::size_t p = q; p < end; ++p) {
            if (second[p] < own_end) pair_status_[p] = PairStatus::apart;
          }
          std::array<std::uint32_t, max_pair_block + lane_count> listed;
          const std::size_t count = list_pairs_for_law(q, end, own_end, listed.data());
          double unused_sum = 0.0;
          std::uint32_t unused_count = 0;
          evaluate_listed_pairs(b, listed.data(), count, unused_sum, unused_count, true);
          for (; c < crossing && cross_pairs_[c] < end; ++c) {
            const std::uint32_t cross = cross_pairs_[c];
            const std::uint32_t i = first[cross];
            if (pair_status_[cross] == PairStatus::touching) {
              force[i] -= cross_force_[c].force;
              torque[i] += r[i] * cross_force_[c].moment;
            }
          }
          finish_mixed_part(b);
          q = end;
        }
        run.advance_below(q < own_pairs_end ? std::size_t{first[q]} : std::size_t{own_end});
      }
      run.advance_below(own_end);
      moved = run.moved || moved;
      run_seconds_[t] += omp_get_wtime() - run_start;
    }
  }
  finish_pair_stage();
  finish_wall_stage();
  return moved;
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
    auto& p = particles_;
    Vec2* const force = p.force.data();
    const double* const torque = p.torque.data();
    Vec2* const velocity = p.velocity.data();
    Vec2* const position = p.position.data();
    double* const spin = p.angular_velocity.data();
    const double* const mass = p.mass.data();
    const double* const inverse_mass = p.inverse_mass.data();
    const double* const inverse_inertia = p.inverse_inertia.data();
    const double* const radius = p.radius.data();
    Vec2* const velocity_now = velocity_now_.data();
    double* const rim_now = rim_speed_now_.data();
    double* const rim_step = rim_speed_step_.data();
    const Vec2* const reference = neighbours_.reference_position().data();
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
    auto& p = particles_;
    Vec3* const force = p.force.data();
    const Vec3* const torque = p.torque.data();
    Vec3* const velocity = p.velocity.data();
    Vec3* const position = p.position.data();
    Vec3* const spin = p.angular_velocity.data();
    const double* const mass = p.mass.data();
    const double* const inverse_mass = p.inverse_mass.data();
    const double* const inverse_inertia = p.inverse_inertia.data();
    Vec3* const velocity_now = velocity_now_.data();
    const double* const radius = p.radius.data();
    Vec3* const rim_now = rim_speed_now_.data();
    Vec3* const rim_step = rim_speed_step_.data();
    const Vec3* const reference = neighbours_.reference_position().data();
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
    const std::size_t last = p.size() - 1;
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
          __builtin_prefetch(&rim_step[a], 1);
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
      store_vectors(&rim_step[i], times(r, w));
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
  auto& p = particles_;
  Vec<D>* const force = p.force.data();
  const Spin<D>* const torque = p.torque.data();
  Vec<D>* const velocity = p.velocity.data();
  Vec<D>* const position = p.position.data();
  Spin<D>* const spin = p.angular_velocity.data();
  const double* const mass = p.mass.data();
  const double* const inverse_mass = p.inverse_mass.data();
  const double* const inverse_inertia = p.inverse_inertia.data();
  Vec<D>* const velocity_now = velocity_now_.data();
  const double* const radius = p.radius.data();
  Spin<D>* const rim_now = rim_speed_now_.data();
  Spin<D>* const rim_step = rim_speed_step_.data();
  const Vec<D>* const reference = neighbours_.reference_position().data();
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
  const std::size_t last = p.size() - 1;
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
      __builtin_prefetch(&rim_step[ahead], 1);
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
    rim_step[i] = radius[i] * spin[i];
    rim_now[i] = radius[i] * estimate_now(spin[i], inverse_inertia[i], torque[i], half_step);
    moved |= norm_squared(offset) > limit ? 1U : 0U;
  }
  return moved != 0;
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
      energy += ball_wall_law_.stored_energy(wall_slot_history_[s], wall_slot_history_[s].overlap);
    }
  }
  return energy;
}

template class World<2>;
template class World<3>;

}  // namespace millsim
