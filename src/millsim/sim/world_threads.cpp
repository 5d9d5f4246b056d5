// How World's step runs its pair, wall and integration stages interleaved: on one thread
// (run_stages_in_one_pass), or on several, each on its own run of particles and pairs
// (split_pairs_among, run_stages_split_among_threads), with the same bits at any thread count.

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>

#include "millsim/sim/world.hpp"
#include "millsim/sim/world_detail.hpp"

namespace millsim {

using namespace world_detail;

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
                                   std::size_t candidate_end, std::size_t run)
    : world_(world),
      advanced_(particle_begin),
      particle_end_(particle_end),
      candidate_begin_(candidate_begin),
      candidate_end_(candidate_end),
      next_wall_block_(candidate_begin / world.wall_block_),
      wall_block_end_(candidate_begin < candidate_end
                          ? block_count(candidate_end, world.wall_block_)
                          : candidate_begin / world.wall_block_),
      run_(run) {}

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
      // A block shared with another run: this run's candidates of it, the block's sums kept
      // apart in this run's part (add_up_shared_wall_blocks).
      const std::size_t shared = world_.shared_wall_block_index(next_wall_block_);
      const auto runs = static_cast<std::size_t>(world_.split_threads_);
      world_.evaluate_wall_candidates(next_wall_block_, begin, end,
                                      &world_.shared_wall_parts_[shared * runs + run_]);
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

/// Work shared by the threads of one step (World's cross pairs), done once by whichever thread
/// comes to it first while the others wait for it. The flag holds 2 s + 1 once step s has done
/// it, 2 s while a thread does it; earlier steps left less.
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
void World<D>::add_up_shared_wall_blocks() {
  // Each part's terms and ended collisions in run order: the candidates' order, in which one
  // thread going through the block adds them up (evaluate_wall_candidates).
  const auto runs = static_cast<std::size_t>(split_threads_);
  for (std::size_t k = 0; k < shared_wall_blocks_.size(); ++k) {
    const std::size_t b = shared_wall_blocks_[k];
    WallBlockSum sum;
    std::uint32_t ended = 0;
    EndedCollision* block_ended = &wall_ended_[b * wall_block_ * max_wall_contacts];
    for (std::size_t run = 0; run < runs; ++run) {
      WallPart& part = shared_wall_parts_[k * runs + run];
      for (const WallTerm& term : part.terms) sum.add(term);
      for (const EndedCollision& collision : part.ended) block_ended[ended++] = collision;
      part.terms.clear();
      part.ended.clear();
    }
    keep_wall_block(b, sum, ended);
  }
}

template <int D>
void World<D>::do_cross_pairs(std::size_t run) {
  if (cross_of_run_begin_[run] == cross_of_run_begin_[run + 1]) return;
  do_once_in_step(cross_done_[run], split_step_count_, [&] {
    // As a block's pairs: those that overlap or did until now listed (the same test as
    // list_pairs_of), then put through the pair kernel lane_count at a time, their forces kept
    // for both runs' threads to add in pair order. (One at a time, evaluate_pair, these pairs
    // held the second of two threads a tenth of the step on the 996-ball slab.)
    const auto& x = particles_.position;
    const auto& first = neighbours_.first();
    const auto& second = neighbours_.second();
    const auto& reach = neighbours_.reach();
    const auto& touching = neighbours_.touching();
    constexpr std::size_t chunk = 256;
    std::array<std::uint32_t, chunk + lane_count> listed;
    std::array<std::uint32_t, chunk> slot;  // each listed pair's place in cross_pairs_
    std::array<PairForce, chunk> stored;
    std::size_t k = cross_of_run_begin_[run];
    const std::size_t end = cross_of_run_begin_[run + 1];
    while (k < end) {
      std::size_t count = 0;
      for (; k < end && count < chunk; ++k) {
        const std::uint32_t c = cross_of_run_[k];
        const std::uint32_t q = cross_pairs_[c];
        // (The distance along the periodic axis as separation makes it, whose square has the
        // same bits, without its division but for the pairs across an end: displacement.)
        const double distance_squared =
            norm_squared(neighbours_.displacement(x[first[q]], x[second[q]]));
        if (distance_squared < reach[q] * reach[q] || touching[q] == TouchState::touching) {
          listed[count] = q;
          slot[count] = c;
          ++count;
        } else {
          pair_status_[q] = PairStatus::apart;
        }
      }
      if (count == 0) continue;
      for (std::size_t l = count; l % lane_count != 0; ++l) listed[l] = listed[count - 1];
      double unused_sum = 0.0;
      std::uint32_t unused_count = 0;
      evaluate_listed_pairs(0, listed.data(), count, unused_sum, unused_count, true, stored.data());
      for (std::size_t n = 0; n < count; ++n) cross_force_[slot[n]] = stored[n];
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
  // belong to two threads is done in parts, each thread its own candidates, the block's sums
  // kept apart per part and added up after the region in run order (add_up_shared_wall_blocks).
  // (Done whole by the later thread, first thing, it read the earlier thread's candidates from
  // the other core and gave them back at its integration: the 3D slab of 996 balls ran 9 %
  // slower on two threads, bench/results.md.)
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
  shared_wall_parts_.resize(shared_wall_blocks_.size() * ranges);  // all empty between steps
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
      zero_sums(own_begin, own_end);
      for (std::size_t c = 0; c < crossing; ++c) {
        const std::uint32_t q = cross_pairs_[c];
        const std::uint32_t j = second[q];
        if (j >= own_begin && j < own_end && pair_status_[q] == PairStatus::touching) {
          force[j] += cross_force_[c].force;
          torque[j] += r[j] * cross_force_[c].moment;
        }
      }
      ParticleRun run(*this, own_begin, own_end, split_candidate_[t], split_candidate_[t + 1], t);
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
  add_up_shared_wall_blocks();
  finish_wall_stage();
  return moved;
}

// The members defined in this file, for both dimensions (world.hpp declares World<2> and
// World<3> extern; world.cpp instantiates the rest).
template bool World<2>::pairs_split_among_threads();
template bool World<3>::pairs_split_among_threads();
template void World<2>::split_pairs_among(int);
template void World<3>::split_pairs_among(int);
template bool World<2>::stages_on_one_thread();
template bool World<3>::stages_on_one_thread();
template bool World<2>::run_stages_in_one_pass();
template bool World<3>::run_stages_in_one_pass();
template void World<2>::zero_sums(std::size_t, std::size_t);
template void World<3>::zero_sums(std::size_t, std::size_t);
template std::size_t World<2>::shared_wall_block_index(std::size_t) const;
template std::size_t World<3>::shared_wall_block_index(std::size_t) const;
template void World<2>::add_up_shared_wall_blocks();
template void World<3>::add_up_shared_wall_blocks();
template void World<2>::do_cross_pairs(std::size_t);
template void World<3>::do_cross_pairs(std::size_t);
template void World<2>::finish_mixed_part(std::size_t);
template void World<3>::finish_mixed_part(std::size_t);
template bool World<2>::run_stages_split_among_threads();
template bool World<3>::run_stages_split_among_threads();
template World<2>::ParticleRun::ParticleRun(World<2>&, std::size_t, std::size_t, std::size_t,
                                            std::size_t, std::size_t);
template World<3>::ParticleRun::ParticleRun(World<3>&, std::size_t, std::size_t, std::size_t,
                                            std::size_t, std::size_t);
template void World<2>::ParticleRun::advance_below(std::size_t);
template void World<3>::ParticleRun::advance_below(std::size_t);

}  // namespace millsim
