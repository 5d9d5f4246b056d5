#include "millsim/search/neighbour_list.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "millsim/core/cpu.hpp"
#include "millsim/core/lanes.hpp"
#include "millsim/core/vector_growth.hpp"

namespace millsim {
namespace {

/// Particles searched by one thread at a time in a rebuild, and the fewest particles for which
/// the rebuild runs on several threads: by default, and where the caller's step runs on
/// several threads anyway (set_parallel; below the default, in a world whose step runs on one
/// thread, the rebuild's parallel regions would wake a second core only to keep it spinning).
constexpr std::size_t search_chunk = 512;
constexpr std::size_t parallel_search_threshold = 2048;
constexpr std::size_t parallel_search_threshold_when_asked = 512;
/// Entries beyond the last in the cells' arrays, and in each chunk's list of found pairs, that
/// the search four partners at a time reads or writes and does not use.
constexpr std::size_t lane_padding = 3;

#if defined(__x86_64__)
/// Four and eight unsigned 32-bit numbers in a register; eight signed, as vpermd takes them.
using FourIndices = std::uint32_t __attribute__((vector_size(4 * sizeof(std::uint32_t))));
using EightIndices = std::uint32_t __attribute__((vector_size(8 * sizeof(std::uint32_t))));
using EightInts = int __attribute__((vector_size(8 * sizeof(int))));
using FourFloats = float __attribute__((vector_size(4 * sizeof(float))));

/// For each set of four lanes (bit l for lane l), the 32-bit words of the kept lanes' pairs in
/// order, lane l's pair being words 2l and 2l + 1.
constexpr std::array<std::array<int, 8>, 16> kept_pair_words_table() {
  std::array<std::array<int, 8>, 16> table{};
  for (unsigned set = 0; set < 16; ++set) {
    int word = 0;
    for (int l = 0; l < 4; ++l) {
      if ((set >> l) & 1U) {
        table[set][static_cast<std::size_t>(word++)] = 2 * l;
        table[set][static_cast<std::size_t>(word++)] = 2 * l + 1;
      }
    }
  }
  return table;
}
constexpr std::array<std::array<int, 8>, 16> kept_pair_words = kept_pair_words_table();

/// The bits of a four-lane mask of 32-bit lanes (bit l for lane l).
__attribute__((target("avx2"))) inline unsigned mask_bits(FourIndices mask) {
  return static_cast<unsigned>(__builtin_ia32_movmskps(reinterpret_cast<FourFloats>(mask)));
}
__attribute__((target("avx2"))) inline unsigned mask_bits(Mask<Lanes> mask) {
  return static_cast<unsigned>(__builtin_ia32_movmskpd256(reinterpret_cast<Lanes>(mask)));
}

/// A row of cells to search: the slots [begin, end) of the cells' arrays.
struct SlotRange {
  std::uint32_t begin;
  std::uint32_t end;
};
/// How many rows NeighbourList::rebuild hands search_rows_avx2 at most at once.
constexpr std::size_t rows_at_once = 16;

/// The search of rows of cells (each [begin, end) in the cell order) from one particle, four
/// partners at a time: the scalar loop of NeighbourList::rebuild's visit_row, the same
/// operations on each lane, so the same pairs in the same order. One call for all of a
/// particle's rows (rows_at_once at most), not one a row: rows hold four candidates on average
/// in the 2D SAG scene, and the call and its set-up cost a quarter of the search's
/// instructions when it was made for each. The pairs go to `found` (two words each, lower
/// index first), four at a time: it must have room for the rows' candidates and three more,
/// and the arrays three entries beyond each row's end (their values unused). Gives the number
/// found. Along a periodic last axis (period > 0), the nearest image's offset, as
/// NeighbourList::separation takes it.
template <int D>
__attribute__((target("avx2"))) std::size_t search_rows_avx2(
    const Vec<D>& own_position, double own_radius, std::uint32_t own, std::uint32_t slot,
    double skin, double period, const Vec<D>* position, const double* radius,
    const std::uint32_t* member, const SlotRange* rows, std::size_t row_count,
    std::uint32_t* found) {
  const Lanes period_l = splat<Lanes>(period);
  // nearest_integer in each lane: the same operations.
  const Lanes two_to_52 = splat<Lanes>(4503599627370496.0);
  const auto nearest_image = [&](Lanes offset) __attribute__((always_inline)) {
    const Lanes t = offset / period_l;
    const Lanes a = lane_abs(t);
    const Lanes rounded = select(a < two_to_52, (a + two_to_52) - two_to_52, a);
    return offset - period_l * lane_copysign(rounded, t);
  };
  const bool periodic = period > 0.0;
  const Lanes own_r = splat<Lanes>(own_radius);
  const Lanes skin_l = splat<Lanes>(skin);
  Vec<D, Lanes> own_x;
  for (int a = 0; a < D; ++a) own_x[a] = splat<Lanes>(own_position[a]);
  const FourIndices own_index = {own, own, own, own};
  const FourIndices own_slot = {slot, slot, slot, slot};
  std::size_t n = 0;
  for (std::size_t row = 0; row < row_count; ++row) {
    const std::uint32_t begin = rows[row].begin;
    const std::uint32_t end = rows[row].end;
    const FourIndices row_end = {end, end, end, end};
    for (std::uint32_t k = begin; k < end; k += 4) {
      Lanes other_radius;
      std::memcpy(&other_radius, radius + k, sizeof other_radius);
      Lanes distance_squared;
      if constexpr (D == 2) {
        Lanes a;
        Lanes b;
        std::memcpy(&a, position[k].c.data(), sizeof a);      // x0 y0 x1 y1
        std::memcpy(&b, position[k + 2].c.data(), sizeof b);  // x2 y2 x3 y3
        const Lanes dx = __builtin_shufflevector(a, b, 0, 2, 4, 6) - own_x[0];
        Lanes dy = __builtin_shufflevector(a, b, 1, 3, 5, 7) - own_x[1];
        if (periodic) dy = nearest_image(dy);
        distance_squared = dx * dx + dy * dy;
      } else {
        Lanes q0;
        Lanes q1;
        Lanes q2;
        const double* p = position[k].c.data();
        std::memcpy(&q0, p, sizeof q0);                                  // x0 y0 z0 x1
        std::memcpy(&q1, p + 4, sizeof q1);                              // y1 z1 x2 y2
        std::memcpy(&q2, p + 8, sizeof q2);                              // z2 x3 y3 z3
        const Lanes xy01 = __builtin_shufflevector(q0, q1, 0, 3, 6, 1);  // x0 x1 x2 y0
        const Lanes yz01 = __builtin_shufflevector(q0, q1, 1, 4, 7, 2);  // y0 y1 y2 z0
        const Lanes zs01 = __builtin_shufflevector(q0, q1, 2, 5, 0, 0);  // z0 z1 . .
        const Lanes dx = __builtin_shufflevector(xy01, q2, 0, 1, 2, 5) - own_x[0];
        const Lanes dy = __builtin_shufflevector(yz01, q2, 0, 1, 2, 6) - own_x[1];
        Lanes dz = __builtin_shufflevector(zs01, q2, 0, 1, 4, 7) - own_x[2];
        if (periodic) dz = nearest_image(dz);
        distance_squared = (dx * dx + dy * dy) + dz * dz;
      }
      const Lanes reach = own_r + other_radius + skin_l;
      const FourIndices lane = FourIndices{k, k, k, k} + FourIndices{0, 1, 2, 3};
      const unsigned near = mask_bits(distance_squared < reach * reach);
      const unsigned smaller = mask_bits(other_radius < own_r);
      const unsigned same = mask_bits(other_radius == own_r);
      const unsigned later = mask_bits(lane > own_slot);
      const unsigned in_row = mask_bits(lane < row_end);
      const unsigned keep = near & (smaller | (same & later)) & in_row;
      FourIndices other;
      std::memcpy(&other, member + k, sizeof other);
      const FourIndices lower = other < own_index ? other : own_index;
      const FourIndices higher = other < own_index ? own_index : other;
      const EightIndices pairs = __builtin_shufflevector(lower, higher, 0, 4, 1, 5, 2, 6, 3, 7);
      EightInts order;
      std::memcpy(&order, kept_pair_words[keep].data(), sizeof order);
      const auto packed = __builtin_ia32_permvarsi256(reinterpret_cast<EightInts>(pairs), order);
      std::memcpy(found + 2 * n, &packed, sizeof packed);
      n += static_cast<std::size_t>(__builtin_popcount(keep));
    }
  }
  return n;
}
#endif

}  // namespace

template <int D>
bool NeighbourList<D>::needs_refresh(const std::vector<Vec<D>>& position) const {
  if (position.size() != reference_position_.size()) return true;
  return moved_too_far(position, 0, position.size());
}

template <int D>
bool NeighbourList<D>::moved_too_far(const std::vector<Vec<D>>& position, std::size_t begin,
                                     std::size_t end) const {
  const double limit = half_skin_squared();
  // Every step asks, and the answer is almost always no: every particle is looked at, without
  // a branch, so that the compiler can work on several at once.
  bool moved = false;
  if (period_ > 0.0) {
    for (std::size_t i = begin; i < end; ++i) {
      moved |= norm_squared(displacement(reference_position_[i], position[i])) > limit;
    }
    return moved;
  }
  for (std::size_t i = begin; i < end; ++i) {
    moved |= norm_squared(position[i] - reference_position_[i]) > limit;
  }
  return moved;
}

template <int D>
void NeighbourList<D>::rebuild(const std::vector<Vec<D>>& position,
                               const std::vector<double>& radius, bool into_cell_order) {
  const std::size_t count = position.size();
  const bool parallel =
      count >= (parallel_ ? parallel_search_threshold_when_asked : parallel_search_threshold);
  ++rebuild_count_;
  skin_ = next_skin_;
  next_first_.clear();
  next_second_.clear();
  previous_index_.clear();
  if (count > 0) {
    // Cells of side the smallest cut-off distance (two of the smallest particles), grown if
    // the particles are spread so wide that the grid would hold many more cells than
    // particles. Each pair is found once, from its larger particle (ties: from the one earlier
    // in the cells' order, below), which searches as many cells round its own as its largest
    // cut-off needs: a small particle looks only at its neighbouring cells however large the
    // largest one is.
    const auto [smallest, largest] = std::minmax_element(radius.begin(), radius.end());
    // The particles' bounds, on each thread over its share (minima and maxima are exact, so
    // the bounds are the same however the particles are shared). Only finite coordinates
    // count: a diverged particle (NaN or infinite) lands in an edge cell, and cannot make the
    // grid unbounded.
    constexpr double none_low = std::numeric_limits<double>::max();
    constexpr double none_high = std::numeric_limits<double>::lowest();
    Vec<D> low;
    Vec<D> high;
    for (int a = 0; a < D; ++a) {
      low[a] = none_low;
      high[a] = none_high;
    }
#pragma omp parallel if (parallel)
    {
      // (From the constants, not from `low` and `high`, which a thread done with its share
      // may be writing already.)
      Vec<D> own_low;
      Vec<D> own_high;
      for (int a = 0; a < D; ++a) {
        own_low[a] = none_low;
        own_high[a] = none_high;
      }
#pragma omp for schedule(static) nowait
      for (std::size_t i = 0; i < count; ++i) {
        for (int a = 0; a < D; ++a) {
          const double x = position[i][a];
          if (!std::isfinite(x)) continue;
          own_low[a] = std::min(own_low[a], x);
          own_high[a] = std::max(own_high[a], x);
        }
      }
#pragma omp critical(neighbour_list_bounds)
      for (int a = 0; a < D; ++a) {
        low[a] = std::min(low[a], own_low[a]);
        high[a] = std::max(high[a], own_high[a]);
      }
    }
    for (int a = 0; a < D; ++a) {
      if (low[a] > high[a]) low[a] = high[a] = 0.0;  // no finite coordinate on this axis
    }
    const bool periodic = period_ > 0.0;
    if (periodic) {
      low[D - 1] = 0.0;
      high[D - 1] = period_;
    }
    // Cells at least a pair's reach wide, doubled until there are at most 32 a particle (plus
    // 4096). Counted in doubles: the extents are finite, but particles far apart (a scene
    // allows ±1e6 m) ask for more cells than an integer holds, and a product that wrapped
    // round to a small number once passed the test and sized the grid wrongly.
    const double most_cells = 32.0 * static_cast<double>(count) + 4096.0;
    // (Finite bounds can still be an infinite span apart, ±1e308: taken as the largest double,
    // so that doubling the cells ends.)
    std::array<double, D> span{};
    for (int a = 0; a < D; ++a) {
      span[a] = std::min(high[a] - low[a], std::numeric_limits<double>::max());
    }
    double cell = 2.0 * *smallest + skin_;
    std::array<double, D> cells_wide{};
    for (;;) {
      double product = 1.0;
      for (int a = 0; a < D; ++a) {
        // Along a periodic axis the cells tile the period exactly, each at least `cell`.
        cells_wide[a] = a == D - 1 && periodic ? std::max(1.0, std::floor(period_ / cell))
                                               : std::floor(span[a] / cell) + 1.0;
        product *= cells_wide[a];
      }
      if (product <= most_cells) break;
      cell *= 2.0;
    }
    std::array<long, D> cells{};
    std::array<double, D> side{};
    std::size_t total = 1;
    for (int a = 0; a < D; ++a) {
      cells[a] = static_cast<long>(cells_wide[a]);
      side[a] = a == D - 1 && periodic ? period_ / cells_wide[a] : cell;
      total *= static_cast<std::size_t>(cells[a]);
    }
    // Counting sort of the particles into cells.
    particle_cell_.resize(count);
    cell_start_.assign(total + 1, 0);
    std::vector<std::array<long, D>>& home = particle_home_;
    home.resize(count);
    // The cell along axis a of coordinate x (clamped to the grid, in doubles: a NaN goes to
    // the first cell, an infinity to the first or the last).
    const auto cell_of = [&](double x, int a) {
      const double c = std::max(0.0, x - low[a]) / side[a];
      return c < cells_wide[a] - 1.0 ? static_cast<long>(c) : cells[a] - 1;
    };
    // The cells' order: axis 0 varies fastest; in 3D the axis with more cells of the other two
    // varies slowest. A run of particles in that order (a thread's share of the step) then
    // ends on a plane across the shorter extent, which few pairs cross: in a thin periodic slab
    // ordered by its axis first, a run ended between two of its three layers of cells, and 28 %
    // of the pairs crossed between the runs of two threads (bench/results.md).
    const int outer = D == 3 && cells[1] > cells[D - 1] ? 1 : D - 1;
    const int middle = D == 3 ? 3 - outer : 0;  // unused in 2D
#pragma omp parallel for schedule(static) if (parallel)
    for (std::size_t i = 0; i < count; ++i) {
      for (int a = 0; a < D; ++a) home[i][a] = cell_of(position[i][a], a);
      std::size_t index = static_cast<std::size_t>(home[i][outer]);
      if constexpr (D == 3) {
        index = index * static_cast<std::size_t>(cells[middle]) +
                static_cast<std::size_t>(home[i][middle]);
      }
      index = index * static_cast<std::size_t>(cells[0]) + static_cast<std::size_t>(home[i][0]);
      particle_cell_[i] = static_cast<std::uint32_t>(index);
    }
    for (std::size_t i = 0; i < count; ++i) ++cell_start_[particle_cell_[i] + 1];
    for (std::size_t c = 0; c < total; ++c) cell_start_[c + 1] += cell_start_[c];
    // Each cell's members with their positions and radii copied alongside, so that the search
    // below reads them in sequence instead of gathering them from the particle arrays.
    // (Three entries more, read and unused by the last four-lane group of a row.)
    cell_members_.resize(count + lane_padding, 0);
    cell_position_.resize(count + lane_padding, Vec<D>{});
    cell_radius_.resize(count + lane_padding, 0.0);
    cell_cursor_.assign(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint32_t slot = cell_cursor_[particle_cell_[i]]++;
      cell_members_[slot] = static_cast<std::uint32_t>(i);
      cell_position_[slot] = position[i];
      cell_radius_[slot] = radius[i];
    }
    if (into_cell_order) {
      // Particles are renumbered by their place in the cells: from here on a member's index
      // is its slot.
      previous_index_.assign(cell_members_.begin(),
                             cell_members_.begin() + static_cast<std::ptrdiff_t>(count));
      for (std::size_t slot = 0; slot < count; ++slot) {
        cell_members_[slot] = static_cast<std::uint32_t>(slot);
      }
    }

    // Pairs found from the particle in `slot` (see above) go to `found`. Two particles of the
    // same radius: from the one in the earlier slot (cells in order, each cell's members in
    // order). A particle of the smallest radius, then, has nothing to find in the slots up to
    // its own: all it can find is another of its radius in a later slot, and it looks at those
    // alone (half the search in a mill of one ball size).
    const double smallest_radius = *smallest;
    // Four partners at a time where the processor can.
#if defined(__x86_64__)
    const bool lanes = lane_search_ && processor_has_avx2();
#endif
    // The pairs go to found[0, n), found kept long enough to take every partner looked at.
    const auto search_from = [&](std::size_t slot, std::vector<FoundPair>& found, std::size_t& n) {
      const std::uint32_t i = cell_members_[slot];
      const double own_radius = cell_radius_[slot];
      const std::uint32_t first_slot =
          own_radius == smallest_radius ? static_cast<std::uint32_t>(slot + 1) : 0;
      const Vec<D> own_position = cell_position_[slot];
      const std::array<long, D>& own_home = home[into_cell_order ? previous_index_[slot] : i];
      const double cutoff = 2.0 * own_radius + skin_;  // the farthest a smaller partner can be
      std::array<long, D> from{};
      std::array<long, D> to{};
      for (int a = 0; a < D; ++a) {
        if (periodic && a == D - 1) {
          const long range = static_cast<long>(std::ceil(cutoff / side[a]));
          from[a] = own_home[a] - range;
          to[a] = own_home[a] + range;
          if (to[a] - from[a] + 1 >= cells[a]) {
            from[a] = 0;  // the range wraps onto itself: visit every cell along the axis once
            to[a] = cells[a] - 1;
          }
          continue;
        }
        // The cells that [x − cutoff, x + cutoff] meets, found as the particles' own cells were
        // (a partner inside that span lies in one of them), the span widened by a hair against
        // rounding.
        const double reach_a = cutoff * (1.0 + 1e-9);
        from[a] = cell_of(own_position[a] - reach_a, a);
        to[a] = cell_of(own_position[a] + reach_a, a);
      }
#if defined(__x86_64__)
      // With lanes, the rows are gathered and searched together (search_rows_avx2).
      std::array<SlotRange, rows_at_once> rows;
      std::size_t row_count = 0;
      std::size_t candidates = 0;
      const auto search_rows = [&] {
        // Room for the rows' candidates and three more (search_rows_avx2).
        const std::size_t room = n + candidates + lane_padding;
        if (found.size() < room) found.resize(std::max(2 * found.size(), room));
        n += search_rows_avx2<D>(own_position, own_radius, i, static_cast<std::uint32_t>(slot),
                                 skin_, period_, cell_position_.data(), cell_radius_.data(),
                                 cell_members_.data(), rows.data(), row_count, &found[n].first);
        row_count = 0;
        candidates = 0;
      };
#endif
      // Cells along axis 0 are contiguous in the cell order, so each row of the range is one
      // run of cell_members_ (axis 0 is never periodic).
      const auto visit_row = [&](std::size_t row) {
        const std::uint32_t begin =
            std::max(first_slot, cell_start_[row + static_cast<std::size_t>(from[0])]);
        const std::uint32_t end = cell_start_[row + static_cast<std::size_t>(to[0]) + 1];
        if (end <= begin) return;
#if defined(__x86_64__)
        if (lanes) {
          rows[row_count++] = {begin, end};
          candidates += end - begin;
          if (row_count == rows_at_once) search_rows();
          return;
        }
#endif
        const std::size_t room = n + (end - begin);
        if (found.size() < room) found.resize(std::max(2 * found.size(), room));
        // Without a branch: every partner is written and kept only if it is found, as which
        // partners are (a third of those looked at in the 2D SAG scene) cannot be predicted,
        // nor, in a charge of several sizes, which of the two is the larger (`|` and `&`, not
        // `||` and `&&`, which compiled to a branch on it: the 2D SAG scene's search took half
        // as long again), nor which of the two indices is the lower (std::min and std::max
        // compiled to a branch on it; with masks the rebuild took 3 % less time).
        for (std::uint32_t k = begin; k < end; ++k) {
          const double other_radius = cell_radius_[k];
          const bool searched_here =
              (other_radius < own_radius) | ((other_radius == own_radius) & (k > slot));
          const std::uint32_t j = cell_members_[k];
          const double reach = own_radius + other_radius + skin_;
          const bool near =
              norm_squared(separation(own_position, cell_position_[k])) < reach * reach;
          const std::uint32_t i_lower = 0U - static_cast<std::uint32_t>(i < j);  // all ones or 0
          const std::uint32_t lower = j ^ ((i ^ j) & i_lower);
          found[n] = FoundPair(lower, i ^ j ^ lower);
          n += static_cast<std::size_t>(searched_here & near);
        }
      };
      const auto wrap = [&](long c, int a) {
        return c < 0 ? c + cells[a] : (c >= cells[a] ? c - cells[a] : c);
      };
      const auto width = static_cast<std::size_t>(cells[0]);
      if constexpr (D == 2) {
        for (long y = from[1]; y <= to[1]; ++y) {
          visit_row(static_cast<std::size_t>(wrap(y, 1)) * width);
        }
      } else {
        for (long o = from[outer]; o <= to[outer]; ++o) {
          const auto plane =
              static_cast<std::size_t>(wrap(o, outer)) * static_cast<std::size_t>(cells[middle]);
          for (long m = from[middle]; m <= to[middle]; ++m) {
            visit_row((plane + static_cast<std::size_t>(wrap(m, middle))) * width);
          }
        }
      }
#if defined(__x86_64__)
      if (row_count > 0) search_rows();
#endif
    };
    // Particles in cell order, so that neighbouring searches touch neighbouring memory, in
    // chunks of a fixed size that threads search apart, each into its own list. The sorts
    // below give the same pair list whatever the chunks and threads.
    const std::size_t chunks = (count + search_chunk - 1) / search_chunk;
    if (found_.size() < chunks) found_.resize(chunks);
    found_low_.resize(chunks);
    found_high_.resize(chunks);
#pragma omp parallel for schedule(dynamic) if (parallel)
    for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
      std::vector<FoundPair>& found = found_[chunk];
      std::size_t n = 0;
      const std::size_t chunk_end = std::min(count, (chunk + 1) * search_chunk);
      for (std::size_t member = chunk * search_chunk; member < chunk_end; ++member) {
        search_from(member, found, n);
      }
      found.resize(n);
      // The chunk's lowest and highest first particle, so that the sort below reads only the
      // chunks that hold a thread's particles.
      std::uint32_t low_first = std::numeric_limits<std::uint32_t>::max();
      std::uint32_t high_first = 0;
      for (const FoundPair& pair : found) {
        low_first = std::min(low_first, pair.first);
        high_first = std::max(high_first, pair.first);
      }
      found_low_[chunk] = low_first;
      found_high_[chunk] = high_first;
    }
  }
  sort_and_carry(position, radius, count, into_cell_order, parallel);
}

template <int D>
void NeighbourList<D>::sort_and_carry(const std::vector<Vec<D>>& position,
                                      const std::vector<double>& radius, std::size_t count,
                                      bool into_cell_order, bool parallel) {
  // The pairs sorted by (first, second): a counting sort by first, then each first's seconds.
  // Then the history of each pair kept from the old list, found among the old pairs of the
  // lower of the two old indices. A pair whose particles were renumbered in the other order has
  // its bodies A and B swapped: its tangential spring, the force on B, changes sign in 3D (in
  // 2D it is a length along the tangent, which turns over with the normal; the other
  // quantities of the history are the same for both bodies).
  //
  // Each thread does all of this for the pairs whose first particle lies in its share of the
  // particles (the caller's, set_thread_shares, or even ones), so that no part of it runs on
  // one thread while the others wait, and each thread writes the pairs its core will step. On
  // the 2D SAG scene's two threads it took 270 µs a rebuild, against 320 µs with the counting
  // sort on one thread (bench/results.md). Every new pair's history is written here, a new
  // pair's empty (the arrays are sized without filling, which on one thread was a fifth of the
  // carry's time).
  const std::size_t old_count = first_begin_.empty() ? 0 : first_begin_.size() - 1;
  const std::size_t chunks = count == 0 ? 0 : (count + search_chunk - 1) / search_chunk;
  const auto most = static_cast<std::size_t>(parallel ? omp_get_max_threads() : 1);
  pair_cursor_.resize(count + 1);
  pair_cursor_[0] = 0;
  range_end_.assign(most + 1, 0);
  next_first_begin_.resize(count + 1);
  next_first_begin_[0] = 0;
  reference_position_.resize(count);
#pragma omp parallel if (parallel)
  {
    const auto team = static_cast<std::size_t>(omp_get_num_threads());
    const auto t = static_cast<std::size_t>(omp_get_thread_num());
    // This thread's first particles, [low, high).
    const bool shared_as_asked = share_begin_.size() == team + 1 && share_begin_[team] == count;
    const std::size_t low = shared_as_asked ? share_begin_[t] : count * t / team;
    const std::size_t high = shared_as_asked ? share_begin_[t + 1] : count * (t + 1) / team;
    // pair_cursor_[a + 1]: how many pairs particle a is the first of; then, summed over this
    // thread's particles, where each one's pairs end among them.
    std::fill(pair_cursor_.begin() + static_cast<std::ptrdiff_t>(low) + 1,
              pair_cursor_.begin() + static_cast<std::ptrdiff_t>(high) + 1, 0U);
    for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
      if (found_[chunk].empty() || found_high_[chunk] < low || found_low_[chunk] >= high) continue;
      for (const FoundPair& pair : found_[chunk]) {
        if (pair.first >= low && pair.first < high) ++pair_cursor_[pair.first + 1];
      }
    }
    for (std::size_t a = low + 1; a < high; ++a) pair_cursor_[a + 1] += pair_cursor_[a];
    range_end_[t + 1] = high > low ? pair_cursor_[high] : 0;
#pragma omp barrier
#pragma omp single
    {
      // Each thread's pairs follow those of the threads before it.
      for (std::size_t u = 0; u < team; ++u) range_end_[u + 1] += range_end_[u];
      const std::size_t pairs = range_end_[team];
      reserve_with_slack(next_first_, pairs);
      reserve_with_slack(next_second_, pairs);
      reserve_with_slack(next_history_, pairs);
      reserve_with_slack(next_touching_, pairs);
      reserve_with_slack(next_reach_, pairs);
      next_first_.resize(pairs);
      next_second_.resize(pairs);
      next_history_.resize(pairs);
      next_touching_.resize(pairs);
      next_reach_.resize(pairs);
    }
    const std::uint32_t pairs_begin = range_end_[t];
    const std::uint32_t pairs_end = range_end_[t + 1];
    for (std::size_t a = low; a < high; ++a) pair_cursor_[a + 1] += pairs_begin;
      // pair_cursor_[a], a in [low, high], now holds where particle a's pairs start (that of
      // `low`, the end of the thread before, written by that thread).
#pragma omp barrier
    for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
      if (found_[chunk].empty() || found_high_[chunk] < low || found_low_[chunk] >= high) continue;
      for (const auto& [a, b] : found_[chunk]) {
        if (a < low || a >= high) continue;
        const std::uint32_t slot = pair_cursor_[a]++;
        next_first_[slot] = a;
        next_second_[slot] = b;
      }
    }
    // pair_cursor_[a] is now the end of particle a's pairs (for a in [low, high)).
    for (std::size_t a = low; a < high; ++a) {
      const std::uint32_t begin = a == low ? pairs_begin : pair_cursor_[a - 1];
      const std::uint32_t end = pair_cursor_[a];
      std::sort(next_second_.begin() + begin, next_second_.begin() + end);
      next_first_begin_[a + 1] = end;
      if (into_cell_order) continue;
      // In the same numbering the old list holds a's old partners in order too: one walk
      // through both (a particle added since the last rebuild has no old pair).
      std::uint32_t old = a < old_count ? first_begin_[a] : 0;
      const std::uint32_t old_end = a < old_count ? first_begin_[a + 1] : 0;
      for (std::uint32_t p = begin; p < end; ++p) {
        const std::uint32_t b = next_second_[p];
        while (old < old_end && second_[old] < b) ++old;
        const bool kept = old < old_end && second_[old] == b;
        next_history_[p] = kept ? history_[old] : ContactHistory<D>{};
        next_touching_[p] = kept ? touching_[old] : TouchState::apart;
      }
    }
    // Renumbered: each new pair's history looked up among the old pairs of its particles' old
    // numbers.
    for (std::size_t p = pairs_begin; p < pairs_end && into_cell_order; ++p) {
      std::uint32_t a = previous_index_[next_first_[p]];
      std::uint32_t b = previous_index_[next_second_[p]];
      const bool swapped = a > b;
      if (swapped) std::swap(a, b);
      ContactHistory<D> carried{};
      TouchState touched = TouchState::apart;
      if (b < old_count) {  // else a particle added since the last rebuild
        for (std::uint32_t old = first_begin_[a]; old < first_begin_[a + 1] && second_[old] <= b;
             ++old) {
          if (second_[old] != b) continue;
          carried = history_[old];
          touched = touching_[old];
          if (D == 3 && swapped) carried.tangential_spring = -carried.tangential_spring;
          break;
        }
      }
      next_history_[p] = carried;
      next_touching_[p] = touched;
    }
    // The pairs' reach, from the radii in the new numbering.
    const double* const r = into_cell_order ? cell_radius_.data() : radius.data();
    for (std::size_t p = pairs_begin; p < pairs_end; ++p) {
      next_reach_[p] = r[next_first_[p]] + r[next_second_[p]];
    }
    for (std::size_t i = low; i < high; ++i) {
      reference_position_[i] = into_cell_order ? cell_position_[i] : position[i];
    }
  }
  first_.swap(next_first_);
  second_.swap(next_second_);
  history_.swap(next_history_);
  touching_.swap(next_touching_);
  reach_.swap(next_reach_);
  first_begin_.swap(next_first_begin_);
}

template class NeighbourList<2>;
template class NeighbourList<3>;

}  // namespace millsim
