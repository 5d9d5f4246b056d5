// Contact search (MODEL.md §5): a cell grid finds the pairs closer than the sum of their radii
// plus a skin; the list is kept until some particle has moved half a skin, and the history of
// every pair (its springs, its dissipated energy) is carried over when the list is rebuilt.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "millsim/contact/contact.hpp"
#include "millsim/core/vec.hpp"

namespace millsim {

/// Whether a listed pair's bodies overlap (a collision is under way). Not a character type, so
/// that the step's writes of it do not oblige the compiler to reload everything else.
enum class TouchState : std::uint8_t { apart, touching };

template <int D>
class NeighbourList {
 public:
  /// skin: extra distance beyond contact within which pairs are listed, m (> 0).
  explicit NeighbourList(double skin) : skin_(skin), next_skin_(skin) {}

  /// The skin of the lists built from the next rebuild on. The current list keeps the skin it
  /// was built with, and needs_refresh() keeps judging it by that one.
  void set_skin(double skin) { next_skin_ = skin; }

  /// Makes the last axis periodic with this period, m (0: not periodic). Positions along it
  /// must lie in [0, period), and the period must exceed twice the largest cut-off distance
  /// so that a particle meets at most one image of another.
  void set_period(double period) { period_ = period; }
  double period() const { return period_; }
  /// b − a, along the periodic axis the nearest image's.
  Vec<D> separation(const Vec<D>& a, const Vec<D>& b) const {
    Vec<D> offset = b - a;
    if (period_ > 0.0) offset[D - 1] -= period_ * nearest_integer(offset[D - 1] / period_);
    return offset;
  }

  /// True when a particle has moved more than half the skin since the last rebuild (or the
  /// particle count changed): only then can a pair not in the list have come into contact.
  bool needs_refresh(const std::vector<Vec<D>>& position) const;
  /// Whether a particle among [begin, end) has moved more than half the skin since the last
  /// rebuild, for positions of the particles the list was built for (built_count()).
  bool moved_too_far(const std::vector<Vec<D>>& position, std::size_t begin, std::size_t end) const;
  /// Whether particle i, now at x, has moved more than half the skin since the last rebuild.
  bool moved_too_far(std::size_t i, const Vec<D>& x) const {
    return norm_squared(displacement(reference_position_[i], x)) > half_skin_squared();
  }
  /// (skin / 2)²: a particle that has moved further since the last rebuild calls for the next.
  double half_skin_squared() const { return 0.25 * skin_ * skin_; }
  /// x − reference, along the periodic axis the nearest image's: separation(reference, x),
  /// without its division unless the two are half a period apart along the axis, as a particle
  /// that has crossed an end since the last rebuild, or a pair across an end, is (below 0.49
  /// periods the nearest integer of the offset / period is ±0, and the square of the plain
  /// offset the same bits).
  Vec<D> displacement(const Vec<D>& reference, const Vec<D>& x) const {
    const Vec<D> offset = x - reference;
    if (period_ > 0.0 && std::fabs(offset[D - 1]) >= 0.49 * period_) {
      return separation(reference, x);
    }
    return offset;
  }
  /// Where the particles were at the last rebuild.
  const std::vector<Vec<D>>& reference_position() const { return reference_position_; }
  /// The number of particles the list was built for.
  std::size_t built_count() const { return reference_position_.size(); }

  /// Rebuilds the pair list, sorted by (first, second), carrying each kept pair's history.
  /// With into_cell_order, the particles are also renumbered in the order of the grid's cells,
  /// so that particles near each other in space are near each other in memory: the new list
  /// is in the new numbers, previous_index() says which particle each one was, and the caller
  /// must reorder every per-particle array of its own (position and radius too) the same way.
  void rebuild(const std::vector<Vec<D>>& position, const std::vector<double>& radius,
               bool into_cell_order = false);
  /// Whether the caller's step runs on several threads, so that rebuilds may too from fewer
  /// particles (512 instead of 2048). The same list either way.
  void set_parallel(bool parallel) { parallel_ = parallel; }
  bool parallel() const { return parallel_; }
  /// Where the caller's threads' shares of the particles begin (one per thread, then the
  /// particle count), if its step splits them so: the rebuild's threads then sort and carry
  /// the pairs of the same shares, so that each thread's pairs are written by its own core.
  /// Empty, or of another thread count or particle count: even shares. The same list either
  /// way.
  void set_thread_shares(const std::vector<std::uint32_t>& share_begin) {
    share_begin_ = share_begin;
  }
  /// Whether the search may look at four partners at a time where the processor has AVX2 (by
  /// default it does; the same list either way, which tests check).
  void set_lane_search(bool on) { lane_search_ = on; }
  /// After a rebuild into cell order, for each new index the particle's index before it.
  const std::vector<std::uint32_t>& previous_index() const { return previous_index_; }

  std::size_t pair_count() const { return first_.size(); }
  const std::vector<std::uint32_t>& first() const { return first_; }
  const std::vector<std::uint32_t>& second() const { return second_; }
  std::vector<ContactHistory<D>>& history() { return history_; }
  const std::vector<ContactHistory<D>>& history() const { return history_; }
  /// Per pair, whether its bodies overlap; carried over rebuilds with the history. Kept apart
  /// from the history so that the step's distance test of a pair that is not touching (most
  /// listed pairs) reads one byte, not a history record.
  std::vector<TouchState>& touching() { return touching_; }
  const std::vector<TouchState>& touching() const { return touching_; }
  /// Per pair, the sum of its two radii as they were at the rebuild (which the list's cut-offs
  /// take as fixed too): the distance at which the pair touches, r_i + r_j. Kept beside the
  /// pairs, so that the step's distance test of every listed pair reads it in sequence instead
  /// of gathering two radii (on the 2D SAG scene's one thread a fifth of that test's time).
  const std::vector<double>& reach() const { return reach_; }
  /// Pairs of particle i as the first: [first_begin()[i], first_begin()[i + 1]).
  const std::vector<std::uint32_t>& first_begin() const { return first_begin_; }
  long rebuild_count() const { return rebuild_count_; }
  /// The skin the current list was built with, m.
  double skin() const { return skin_; }

 private:
  double skin_;
  double next_skin_;
  double period_ = 0.0;
  long rebuild_count_ = 0;
  bool parallel_ = false;                   // set_parallel
  std::vector<std::uint32_t> share_begin_;  // set_thread_shares
  bool lane_search_ = true;                 // set_lane_search
  std::vector<std::uint32_t> first_, second_;
  std::vector<ContactHistory<D>> history_;
  std::vector<TouchState> touching_;
  std::vector<double> reach_;
  std::vector<std::uint32_t> first_begin_;
  std::vector<Vec<D>> reference_position_;
  // Scratch kept between rebuilds so that a rebuild allocates nothing in steady state.
  std::vector<std::uint32_t> particle_cell_, cell_start_, cell_cursor_, cell_members_;
  std::vector<Vec<D>> cell_position_;
  std::vector<double> cell_radius_;
  std::vector<std::uint32_t> next_first_, next_second_;
  std::vector<std::array<long, D>> particle_home_;
  std::vector<std::uint32_t> previous_index_;
  /// A pair found by the search, lower index first. Its empty constructor leaves it unset, so
  /// that growing a chunk's list of found pairs does not write the new entries twice.
  struct FoundPair {
    FoundPair() {}  // NOLINT(modernize-use-equals-default): = default would zero the entries
    FoundPair(std::uint32_t a, std::uint32_t b) : first(a), second(b) {}
    std::uint32_t first;
    std::uint32_t second;
  };
  /// The end of rebuild: the found pairs sorted into the new list, the histories carried
  /// over, the positions kept as the list's reference.
  void sort_and_carry(const std::vector<Vec<D>>& position, const std::vector<double>& radius,
                      std::size_t count, bool into_cell_order, bool parallel);
  std::vector<std::vector<FoundPair>> found_;          // per search chunk
  std::vector<std::uint32_t> found_low_, found_high_;  // each chunk's lowest and highest first
  std::vector<std::uint32_t> pair_cursor_;
  std::vector<std::uint32_t> range_end_;  // where each thread's pairs end (sort_and_carry)
  std::vector<std::uint32_t> next_first_begin_;
  std::vector<ContactHistory<D>> next_history_;
  std::vector<TouchState> next_touching_;
  std::vector<double> next_reach_;
};

extern template class NeighbourList<2>;
extern template class NeighbourList<3>;

}  // namespace millsim
