#include "millsim/search/neighbour_list.hpp"

#include <algorithm>
#include <array>
#include <cmath>

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
    // the bounds are the same however the particles are shared).
    Vec<D> low = position[0];
    Vec<D> high = position[0];
#pragma omp parallel if (parallel)
    {
      Vec<D> own_low = position[0];
      Vec<D> own_high = position[0];
#pragma omp for schedule(static) nowait
      for (std::size_t i = 0; i < count; ++i) {
        for (int a = 0; a < D; ++a) {
          own_low[a] = std::min(own_low[a], position[i][a]);
          own_high[a] = std::max(own_high[a], position[i][a]);
        }
      }
#pragma omp critical(neighbour_list_bounds)
      for (int a = 0; a < D; ++a) {
        low[a] = std::min(low[a], own_low[a]);
        high[a] = std::max(high[a], own_high[a]);
      }
    }
    const bool periodic = period_ > 0.0;
    if (periodic) {
      low[D - 1] = 0.0;
      high[D - 1] = period_;
    }
    double cell = 2.0 * *smallest + skin_;
    std::array<long, D> cells{};
    std::array<double, D> side{};
    std::size_t total = 1;
    for (;;) {
      total = 1;
      for (int a = 0; a < D; ++a) {
        side[a] = cell;
        cells[a] = static_cast<long>((high[a] - low[a]) / cell) + 1;
        if (a == D - 1 && periodic) {
          // Along a periodic axis the cells tile the period exactly, each at least `cell`.
          cells[a] = std::max(1L, static_cast<long>(period_ / cell));
          side[a] = period_ / static_cast<double>(cells[a]);
        }
        total *= static_cast<std::size_t>(cells[a]);
      }
      if (total <= 32 * count + 4096) break;
      cell *= 2.0;
    }
    // Counting sort of the particles into cells.
    particle_cell_.resize(count);
    cell_start_.assign(total + 1, 0);
    std::vector<std::array<long, D>>& home = particle_home_;
    home.resize(count);
    // The cell along axis a of coordinate x (clamped to the grid).
    const auto cell_of = [&](double x, int a) {
      const auto c = static_cast<long>(std::max(0.0, x - low[a]) / side[a]);
      return std::min(c, cells[a] - 1);
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
    cell_members_.resize(count);
    cell_position_.resize(count);
    cell_radius_.resize(count);
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
      previous_index_.assign(cell_members_.begin(), cell_members_.end());
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
      // Cells along axis 0 are contiguous in the cell order, so each row of the range is one
      // run of cell_members_ (axis 0 is never periodic).
      const auto visit_row = [&](std::size_t row) {
        const std::uint32_t begin =
            std::max(first_slot, cell_start_[row + static_cast<std::size_t>(from[0])]);
        const std::uint32_t end = cell_start_[row + static_cast<std::size_t>(to[0]) + 1];
        if (end <= begin) return;
        if (found.size() < n + (end - begin))
          found.resize(std::max(2 * found.size(), n + (end - begin)));
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
    };
    // Particles in cell order, so that neighbouring searches touch neighbouring memory, in
    // chunks of a fixed size that threads search apart, each into its own list. The sorts
    // below give the same pair list whatever the chunks and threads.
    const std::size_t chunks = (count + search_chunk - 1) / search_chunk;
    if (found_.size() < chunks) found_.resize(chunks);
#pragma omp parallel for schedule(dynamic) if (parallel)
    for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
      std::vector<FoundPair>& found = found_[chunk];
      std::size_t n = 0;
      const std::size_t chunk_end = std::min(count, (chunk + 1) * search_chunk);
      for (std::size_t member = chunk * search_chunk; member < chunk_end; ++member) {
        search_from(member, found, n);
      }
      found.resize(n);
    }
    // Sorted by (first, second): a counting sort by first, then each first's seconds.
    pair_cursor_.assign(count + 1, 0);
    std::size_t found_count = 0;
    for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
      for (const auto& pair : found_[chunk]) ++pair_cursor_[pair.first + 1];
      found_count += found_[chunk].size();
    }
    for (std::size_t i = 0; i < count; ++i) pair_cursor_[i + 1] += pair_cursor_[i];
    reserve_with_slack(next_first_, found_count);
    reserve_with_slack(next_second_, found_count);
    next_first_.resize(found_count);
    next_second_.resize(found_count);
    for (std::size_t chunk = 0; chunk < chunks; ++chunk) {
      for (const auto& [a, b] : found_[chunk]) {
        const std::uint32_t slot = pair_cursor_[a]++;
        next_first_[slot] = a;
        next_second_[slot] = b;
      }
    }
    // pair_cursor_[i] is now the end of particle i's pairs, and the start of particle i + 1's.
#pragma omp parallel for schedule(static) if (parallel)
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint32_t begin = i == 0 ? 0 : pair_cursor_[i - 1];
      std::sort(next_second_.begin() + begin, next_second_.begin() + pair_cursor_[i]);
    }
  }
  // Carry the history of pairs kept from the old list, found among the old pairs of the lower
  // of the two old indices. A pair whose particles were renumbered in the other order has its
  // bodies A and B swapped: its tangential spring, the force on B, changes sign in 3D (in 2D
  // it is a length along the tangent, which turns over with the normal; the other quantities
  // of the history are the same for both bodies). On several threads from as many
  // particles as the search: a smaller world's step runs on one thread, and a parallel region
  // here at every rebuild kept a second core spinning through it (OpenMP's threads wait
  // actively for a while after each region).
  // Every new pair's entry is written below, a new pair's with an empty history (sized here
  // without filling, which on one thread was a fifth of the carry's time).
  reserve_with_slack(next_history_, next_first_.size());
  reserve_with_slack(next_touching_, next_first_.size());
  next_history_.resize(next_first_.size());
  next_touching_.resize(next_first_.size());
  const std::size_t old_count = first_begin_.empty() ? 0 : first_begin_.size() - 1;
  const std::size_t pairs = next_first_.size();
#pragma omp parallel for schedule(static) if (parallel)
  for (std::size_t p = 0; p < pairs; ++p) {
    std::uint32_t a = into_cell_order ? previous_index_[next_first_[p]] : next_first_[p];
    std::uint32_t b = into_cell_order ? previous_index_[next_second_[p]] : next_second_[p];
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
  first_.swap(next_first_);
  second_.swap(next_second_);
  history_.swap(next_history_);
  touching_.swap(next_touching_);
  if (into_cell_order && count > 0) {
    reference_position_.assign(cell_position_.begin(), cell_position_.end());
  } else {
    reference_position_ = position;
  }

  // Where each particle's pairs as the first begin: the counting sort above left the end of
  // particle i's pairs, the start of particle i + 1's, in pair_cursor_[i].
  first_begin_.assign(count + 1, 0);
  if (count > 0)
    std::copy(pair_cursor_.begin(), pair_cursor_.begin() + count, first_begin_.begin() + 1);
}

template class NeighbourList<2>;
template class NeighbourList<3>;

}  // namespace millsim
