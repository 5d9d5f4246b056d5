#include "millsim/search/neighbour_list.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace millsim {

template <int D>
bool NeighbourList<D>::needs_refresh(const std::vector<Vec<D>>& position) const {
  if (position.size() != reference_position_.size()) return true;
  const double limit = 0.25 * skin_ * skin_;  // (skin / 2)²
  for (std::size_t i = 0; i < position.size(); ++i) {
    if (norm_squared(position[i] - reference_position_[i]) > limit) return true;
  }
  return false;
}

template <int D>
void NeighbourList<D>::rebuild(const std::vector<Vec<D>>& position,
                               const std::vector<double>& radius) {
  const std::size_t count = position.size();
  ++rebuild_count_;
  next_first_.clear();
  next_second_.clear();
  if (count > 0) {
    // Cells of side at least the largest cut-off distance, so every listed pair lies in
    // neighbouring cells. Grow the cells if the particles are spread so wide that the grid
    // would hold many more cells than particles.
    const double largest_radius = *std::max_element(radius.begin(), radius.end());
    Vec<D> low = position[0];
    Vec<D> high = position[0];
    for (const Vec<D>& x : position) {
      for (int a = 0; a < D; ++a) {
        low[a] = std::min(low[a], x[a]);
        high[a] = std::max(high[a], x[a]);
      }
    }
    double cell = 2.0 * largest_radius + skin_;
    std::array<std::size_t, D> cells{};
    std::size_t total = 1;
    for (;;) {
      total = 1;
      for (int a = 0; a < D; ++a) {
        cells[a] = static_cast<std::size_t>((high[a] - low[a]) / cell) + 1;
        total *= cells[a];
      }
      if (total <= 4 * count + 64) break;
      cell *= 2.0;
    }
    // Counting sort of the particles into cells.
    particle_cell_.resize(count);
    cell_start_.assign(total + 1, 0);
    for (std::size_t i = 0; i < count; ++i) {
      std::size_t index = 0;
      for (int a = D - 1; a >= 0; --a) {
        const auto c = static_cast<std::size_t>((position[i][a] - low[a]) / cell);
        index = index * cells[a] + std::min(c, cells[a] - 1);
      }
      particle_cell_[i] = static_cast<std::uint32_t>(index);
      ++cell_start_[index + 1];
    }
    for (std::size_t c = 0; c < total; ++c) cell_start_[c + 1] += cell_start_[c];
    cell_members_.resize(count);
    cell_cursor_.assign(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < count; ++i) {
      cell_members_[cell_cursor_[particle_cell_[i]]++] = static_cast<std::uint32_t>(i);
    }
    // For each particle, the later particles within reach in the 3^D surrounding cells.
    for (std::size_t i = 0; i < count; ++i) {
      std::array<long, D> home{};
      std::size_t rest = particle_cell_[i];
      for (int a = 0; a < D; ++a) {
        home[a] = static_cast<long>(rest % cells[a]);
        rest /= cells[a];
      }
      const std::size_t begin = next_second_.size();
      constexpr int neighbourhood = D == 2 ? 9 : 27;
      for (int offset = 0; offset < neighbourhood; ++offset) {
        std::size_t index = 0;
        bool inside = true;
        int code = offset;
        std::array<long, D> at{};
        for (int a = 0; a < D; ++a) {
          at[a] = home[a] + (code % 3) - 1;
          code /= 3;
          inside = inside && at[a] >= 0 && at[a] < static_cast<long>(cells[a]);
        }
        if (!inside) continue;
        for (int a = D - 1; a >= 0; --a) index = index * cells[a] + static_cast<std::size_t>(at[a]);
        for (std::uint32_t k = cell_start_[index]; k < cell_start_[index + 1]; ++k) {
          const std::uint32_t j = cell_members_[k];
          if (j <= i) continue;
          const double reach = radius[i] + radius[j] + skin_;
          if (norm_squared(position[j] - position[i]) < reach * reach) next_second_.push_back(j);
        }
      }
      std::sort(next_second_.begin() + static_cast<long>(begin), next_second_.end());
      next_first_.resize(next_second_.size(), static_cast<std::uint32_t>(i));
    }
  }
  // Carry the history of pairs kept from the old list: both lists are sorted by (first, second).
  next_history_.assign(next_first_.size(), ContactHistory<D>{});
  std::size_t old = 0;
  for (std::size_t p = 0; p < next_first_.size() && old < first_.size(); ++p) {
    const auto key = std::pair{next_first_[p], next_second_[p]};
    while (old < first_.size() && std::pair{first_[old], second_[old]} < key) ++old;
    if (old < first_.size() && std::pair{first_[old], second_[old]} == key) {
      next_history_[p] = history_[old];
    }
  }
  first_.swap(next_first_);
  second_.swap(next_second_);
  history_.swap(next_history_);
  reference_position_ = position;

  // Per-particle views of the pair list (counting sorts; pairs are already ordered by first).
  first_begin_.assign(count + 1, 0);
  second_begin_.assign(count + 1, 0);
  for (std::size_t p = 0; p < first_.size(); ++p) {
    ++first_begin_[first_[p] + 1];
    ++second_begin_[second_[p] + 1];
  }
  for (std::size_t i = 0; i < count; ++i) {
    first_begin_[i + 1] += first_begin_[i];
    second_begin_[i + 1] += second_begin_[i];
  }
  second_pairs_.resize(first_.size());
  cell_cursor_.assign(second_begin_.begin(), second_begin_.end() - 1);
  for (std::size_t p = 0; p < first_.size(); ++p) {
    second_pairs_[cell_cursor_[second_[p]]++] = static_cast<std::uint32_t>(p);
  }
}

template class NeighbourList<2>;
template class NeighbourList<3>;

}  // namespace millsim
