// What World's stage files (world*.cpp) share: the sizes of the blocks of pairs and wall
// candidates that are the unit of parallel work and of partial sums, and the thresholds that
// decide when a stage runs on several threads. Internal to World; not part of the library's
// interface.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "millsim/geometry/walls.hpp"
#include "millsim/measure/spectrum.hpp"

namespace millsim::world_detail {

inline ContactType wall_contact_type(WallKind kind) {
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
/// quarter of the candidates (whole numbers, rounded down), rounded up to a power of two within
/// 256–1024 pairs or 64–256 candidates (so at most 17 and 5 blocks where the size is not at its
/// largest: 4 097 pairs make 17 blocks of 256). Large
/// blocks cost less per pair (the 2D SAG scene, 941 candidates, was 0.7 % slower on two threads
/// in 8 blocks of 128 than in 4 of 256); in a small world, where one block was a third of the
/// list, the blocks that two threads' runs share (done one pair at a time, or by one thread for
/// both) held up the step (bench/results.md).
inline constexpr std::size_t min_pair_block = 256;
inline constexpr std::size_t max_pair_block = 1024;
inline constexpr std::size_t min_wall_block = 64;
inline constexpr std::size_t max_wall_block = 256;
/// Below this many items a stage runs on one thread (a parallel region costs microseconds).
inline constexpr std::size_t parallel_threshold = 2048;
/// The fewest wall candidates whose nearby lifters are found on several threads in a world
/// whose step splits among them.
inline constexpr std::size_t parallel_candidate_threshold_when_split = 256;
/// The pair stage, and with it the particle stages, split among threads from this many listed
/// pairs, where two threads and one break even: below it the threads' barriers cost more than
/// the split saves (the 3D scaling slab of 996 balls and 2 500 pairs on two threads against
/// one: 1.1 times faster on an Intel host, 0.85 times on an AMD one, which broke even at about
/// 5 000 pairs; bench/results.md).
inline constexpr std::size_t parallel_pair_threshold = 2048;
/// The same for the old three-stage path's wall stage, whose candidates cost tens of pairs
/// each: from 512 on (the 2D SAG scene has about a thousand candidates; on one thread they held
/// the other one waiting for 3 % of the step).
inline constexpr std::size_t parallel_wall_threshold = 2 * max_wall_block;

/// The block size for a list of `items`: items / blocks rounded up to a power of two, within
/// [smallest, largest].
inline std::size_t block_size_for(std::size_t items, std::size_t blocks, std::size_t smallest,
                                  std::size_t largest) {
  return std::clamp(std::bit_ceil(std::max<std::size_t>(1, items / blocks)), smallest, largest);
}

/// Whether a list of `pairs` splits the step among `threads` threads.
inline bool splits_among_threads(std::size_t pairs, int threads) {
  return threads > 1 && pairs >= parallel_pair_threshold;
}
/// When the particle arrays that the pair kernel reads and writes hold more than this many
/// bytes, half a core's second-level cache here, the kernel prefetches the particles and
/// history of the pairs two lanes ahead: the second particle of a pair is met out of order and
/// comes from beyond that cache otherwise. Below it the prefetches cost more than they save
/// (bench/results.md, sixteenth session: the 2D SAG scene, 0.6 MB, 5–7 % slower with them; the
/// 1e4-ball slab, 1.5 MB, 2–4 % faster; the 3D 20 k scene and the LIGGGHTS comparison's, 3 MB,
/// 3–8 % faster; the 1e5-ball slab, 15 MB, +10 % in the eleventh).
inline constexpr std::size_t prefetch_threshold_bytes = std::size_t{1} << 20;

/// The pair kernel's window of prefetched particles (World::pair_window_): the furthest a
/// listed pair's second particle lies beyond its first (the list gives the lower index first)
/// among the pairs within the largest window, plus pair_window_lead particles so that the last
/// ones' lines have time to arrive. The largest window is pair_window_bytes of the arrays
/// (`bytes_per_particle` each), a quarter of the AMD host's 1 MiB second-level cache. Pairs
/// beyond it have only World::prefetch_pairs' fetch, a few pairs ahead: in the tiled slabs of
/// the scaling series, whose axis is the cell grid's outermost, those across the slab's ends,
/// whose second particle is at the far end of the list (1 % of the 1e4-ball slab's pairs,
/// 0.01 % of the 1e6-ball slab's). In the 1e6-ball slab the window is 393 particles (99.9 % of
/// the pairs' second particles lie within 347 of the first).
inline constexpr std::size_t pair_window_lead = 32;
/// The window is kept from this size of its arrays up: where the world's arrays outgrow the
/// last-level cache. Below it the kernel finds the second particles in that cache, and fetching
/// every line ahead costs more than it saves (bench/results.md, forty-first session, one
/// thread on the AMD host with 32 MiB of L3: the 3e4-ball slab, 5.5 MB of these arrays, 4 %
/// slower with the window; the 5e4-ball slab, 9.2 MB, 11 % faster; 1e5 and 1e6, 30 %).
inline constexpr std::size_t pair_window_threshold_bytes = std::size_t{8} << 20;
inline constexpr std::size_t pair_window_bytes = std::size_t{256} << 10;
inline std::size_t pair_window_for(const std::vector<std::uint32_t>& first,
                                   const std::vector<std::uint32_t>& second,
                                   std::size_t bytes_per_particle) {
  const std::size_t largest = pair_window_bytes / std::max<std::size_t>(1, bytes_per_particle);
  std::size_t furthest = 0;
  for (std::size_t q = 0; q < first.size(); ++q) {
    const std::size_t gap = second[q] - first[q];
    furthest = gap + pair_window_lead <= largest ? std::max(furthest, gap) : furthest;
  }
  return furthest + pair_window_lead;
}

inline std::size_t block_count(std::size_t items, std::size_t block) {
  return (items + block - 1) / block;
}

}  // namespace millsim::world_detail
