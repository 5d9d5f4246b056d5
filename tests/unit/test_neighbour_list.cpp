// The neighbour list (search/neighbour_list.hpp) against a brute-force search over all pairs:
// the same pairs in the same order, a refresh exactly when some particle has moved more than
// half the skin, and the history of kept pairs carried over a rebuild, also one that renumbers
// the particles.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "millsim/search/neighbour_list.hpp"

namespace millsim {
namespace {

using PairList = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

/// A cloud of `count` particles of radius 0.5–1.5 in a cube (square) of side `side`.
template <int D>
struct Cloud {
  std::vector<Vec<D>> position;
  std::vector<double> radius;
};

template <int D>
Cloud<D> random_cloud(std::size_t count, double side, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> where(0.0, side);
  std::uniform_real_distribution<double> size(0.5, 1.5);
  Cloud<D> cloud;
  for (std::size_t i = 0; i < count; ++i) {
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = where(random);
    cloud.position.push_back(x);
    cloud.radius.push_back(size(random));
  }
  return cloud;
}

/// Every pair i < j closer than r_i + r_j + skin, in (i, j) order: the definition of the list.
template <int D>
PairList brute_force_pairs(const Cloud<D>& cloud, double skin) {
  PairList pairs;
  for (std::uint32_t i = 0; i < cloud.position.size(); ++i) {
    for (std::uint32_t j = i + 1; j < cloud.position.size(); ++j) {
      const double reach = cloud.radius[i] + cloud.radius[j] + skin;
      // distance < reach, compared squared (both sides are positive).
      if (norm_squared(cloud.position[j] - cloud.position[i]) < reach * reach) {
        pairs.emplace_back(i, j);
      }
    }
  }
  return pairs;
}

template <int D>
PairList listed_pairs(const NeighbourList<D>& list) {
  PairList pairs;
  for (std::size_t p = 0; p < list.pair_count(); ++p) {
    pairs.emplace_back(list.first()[p], list.second()[p]);
  }
  return pairs;
}

template <int D>
void expect_default(const ContactHistory<D>& h) {
  EXPECT_EQ(h.normal_spring_origin, 0.0);
  EXPECT_EQ(h.tangential_spring, SpinOf<D>{});
  EXPECT_EQ(h.dissipated, 0.0);
}

// 300 particles, radii uniform in [0.5, 1.5], placed independently (so some overlap), skin 0.3.
// A pair is listed when its centres are within s = r_i + r_j + 0.3, with E[s²] = 2.3² + 1/6
// = 5.46 and E[s³] = 2.3³ + 3 × 2.3 / 6 = 13.3. Expected pairs, 300 × 299 / 2 = 44850 times the
// chance of being within s: 2D, side 40: 44850 × π × 5.46 / 1600 ≈ 480 pairs (3.2 per disc);
// 3D, side 14: 44850 × 4π/3 × 13.3 / 2744 ≈ 910 pairs (6 per sphere).
constexpr std::size_t cloud_size = 300;
constexpr double skin = 0.3;
template <int D>
constexpr double box_side = D == 2 ? 40.0 : 14.0;

template <int D>
void check_matches_brute_force(std::uint64_t seed) {
  const Cloud<D> cloud = random_cloud<D>(cloud_size, box_side<D>, seed);
  // The search one partner at a time, and four at a time where the processor has AVX2.
  for (const bool lanes : {false, true}) {
    SCOPED_TRACE(lanes ? "four partners at a time" : "one partner at a time");
    NeighbourList<D> list(skin);
    list.set_lane_search(lanes);
    list.rebuild(cloud.position, cloud.radius);
    const PairList expected = brute_force_pairs(cloud, skin);
    ASSERT_GT(expected.size(), cloud_size) << "the cloud should have more pairs than particles";
    EXPECT_EQ(listed_pairs(list), expected);
    EXPECT_EQ(list.history().size(), expected.size());
    EXPECT_EQ(list.rebuild_count(), 1);
  }
}

TEST(NeighbourList, DiscPairsEqualBruteForceSortedByFirstThenSecond) {
  for (std::uint64_t seed : {1u, 2u, 3u}) check_matches_brute_force<2>(seed);
}

TEST(NeighbourList, SpherePairsEqualBruteForceSortedByFirstThenSecond) {
  for (std::uint64_t seed : {1u, 2u, 3u}) check_matches_brute_force<3>(seed);
}

/// Every pair i < j closer than r_i + r_j + list_skin, along the last axis by the nearest image
/// when `period` > 0.
template <int D>
PairList brute_force_pairs_periodic(const Cloud<D>& cloud, double list_skin, double period) {
  PairList pairs;
  for (std::uint32_t i = 0; i < cloud.position.size(); ++i) {
    for (std::uint32_t j = i + 1; j < cloud.position.size(); ++j) {
      Vec<D> offset = cloud.position[j] - cloud.position[i];
      if (period > 0.0) offset[D - 1] -= period * std::nearbyint(offset[D - 1] / period);
      const double reach = cloud.radius[i] + cloud.radius[j] + list_skin;
      if (norm_squared(offset) < reach * reach) pairs.emplace_back(i, j);
    }
  }
  return pairs;
}

/// Particles of a few sizes, many of each (as a mill's charge): two particles of the same radius
/// are found from one of them only, the one earlier in the cells' order, and a particle of the
/// smallest radius searches only the cells after its own. The list is the brute force's, in
/// the particles' own numbering and after renumbering into cell order, and with the last axis
/// periodic (pairs across the ends found once).
template <int D>
void check_equal_radii(const std::vector<double>& sizes, double period) {
  for (const auto& [seed, lanes] : {std::pair{4u, false}, {4u, true}, {5u, false}, {5u, true}}) {
    SCOPED_TRACE(lanes ? "four partners at a time" : "one partner at a time");
    Cloud<D> cloud = random_cloud<D>(cloud_size, box_side<D>, seed);
    std::mt19937_64 random(seed);
    std::uniform_int_distribution<std::size_t> pick(0, sizes.size() - 1);
    for (double& r : cloud.radius) r = sizes[pick(random)];
    NeighbourList<D> list(skin);
    list.set_lane_search(lanes);
    list.set_period(period);
    list.rebuild(cloud.position, cloud.radius);
    const PairList expected = brute_force_pairs_periodic(cloud, skin, period);
    ASSERT_GT(expected.size(), cloud_size);
    EXPECT_EQ(listed_pairs(list), expected);

    // Renumbered into cell order: the same pairs among the renumbered particles.
    list.rebuild(cloud.position, cloud.radius, true);
    Cloud<D> renumbered;
    for (const std::uint32_t before : list.previous_index()) {
      renumbered.position.push_back(cloud.position[before]);
      renumbered.radius.push_back(cloud.radius[before]);
    }
    EXPECT_EQ(listed_pairs(list), brute_force_pairs_periodic(renumbered, skin, period));
  }
}

TEST(NeighbourList, ParticlesFarApartOrDivergedSizeTheGridWithinBounds) {
  // The grid's cells are doubled in size until there are at most 32 a particle. Counted in
  // integers, the cells of particles far apart wrapped round: two 0.1 mm discs 4.4e5 m apart
  // on each axis asked for 2^32 × 2^32 cells, counted as 0, and the rebuild wrote far outside
  // the grid (a scene allows ±1e6 m). Nor may a diverged particle (NaN or infinite) make the
  // grid unbounded or its cell index undefined. Each case lists the one pair that is near.
  const double far = 440234.14778875007;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> radius(4, 5e-5);
  const double huge = std::numeric_limits<double>::max();  // an infinite span from -huge
  for (const double odd : {far, -far, nan, inf, -inf, huge}) {
    SCOPED_TRACE(odd);
    NeighbourList<2> discs(5e-6);
    discs.rebuild({Vec2{{odd, odd}}, Vec2{{0.0, 0.0}}, Vec2{{0.0, 9e-5}},
                   Vec2{{odd == huge ? -huge : far, 0.0}}},
                  radius);
    EXPECT_EQ(listed_pairs(discs), (PairList{{1, 2}}));
    NeighbourList<3> spheres(5e-6);
    const double wide = 429.91610875;  // 2^22 cells on each axis, 2^66 in all
    const double x = std::isfinite(odd) ? wide : odd;
    spheres.rebuild(
        {Vec3{{x, x, x}}, Vec3{{0.0, 0.0, 0.0}}, Vec3{{0.0, 9e-5, 0.0}}, Vec3{{wide, 0.0, 0.0}}},
        radius);
    EXPECT_EQ(listed_pairs(spheres), (PairList{{1, 2}}));
  }
}

TEST(NeighbourList, OneSizeOfParticleMatchesBruteForce) {
  check_equal_radii<2>({1.0}, 0.0);
  check_equal_radii<3>({1.0}, 0.0);
}

TEST(NeighbourList, AFewSizesOfParticleMatchBruteForce) {
  check_equal_radii<2>({0.5, 1.0, 1.5}, 0.0);
  check_equal_radii<3>({0.5, 1.0, 1.5}, 0.0);
}

TEST(NeighbourList, PeriodicAxisMatchesBruteForceByTheNearestImage) {
  // The box's side along the last axis is the period; positions lie in [0, period).
  check_equal_radii<2>({1.0}, box_side<2>);
  check_equal_radii<3>({0.5, 1.0, 1.5}, box_side<3>);
}

TEST(NeighbourList, ThinSlabIsOrderedAlongItsWiderAxisAndMatchesBruteForce) {
  // 600 spheres in a slab 28 wide (x, y) and 7 thick along the last axis, periodic along it
  // and not: the cells are put in order with the wider of the two outer axes varying slowest,
  // so that a run of particles in that order is a layer across y, not across the thin axis.
  for (const double period : {0.0, 7.0}) {
    Cloud<3> cloud = random_cloud<3>(600, 28.0, 6);
    for (Vec3& x : cloud.position) x[2] *= 0.25;
    NeighbourList<3> list(skin);
    list.set_period(period);
    list.rebuild(cloud.position, cloud.radius, true);
    Cloud<3> renumbered;
    for (const std::uint32_t before : list.previous_index()) {
      renumbered.position.push_back(cloud.position[before]);
      renumbered.radius.push_back(cloud.radius[before]);
    }
    const PairList expected = brute_force_pairs_periodic(renumbered, skin, period);
    ASSERT_GT(expected.size(), 600u);
    EXPECT_EQ(listed_pairs(list), expected);
    // In the new order y does not fall by more than a cell (the cells are at least 2 × 0.5 +
    // skin = 1.3 wide) from one particle to the next, while z does, many times.
    std::size_t z_falls = 0;
    for (std::size_t k = 1; k < renumbered.position.size(); ++k) {
      EXPECT_GT(renumbered.position[k][1], renumbered.position[k - 1][1] - 5.0) << k;
      z_falls += renumbered.position[k][2] < renumbered.position[k - 1][2] - 1.0 ? 1 : 0;
    }
    EXPECT_GT(z_falls, 10u);
  }
}

TEST(NeighbourList, WideSpreadCloudStillMatchesBruteForce) {
  // Two clumps 10⁴ apart: the grid grows its cells rather than holding 10⁸ of them, and the
  // pairs must not change.
  Cloud<2> cloud = random_cloud<2>(200, 20.0, 7);
  for (std::size_t i = 100; i < 200; ++i) cloud.position[i] += Vec2{{1.0e4, 1.0e4}};
  NeighbourList<2> list(skin);
  list.rebuild(cloud.position, cloud.radius);
  EXPECT_EQ(listed_pairs(list), brute_force_pairs(cloud, skin));
}

TEST(NeighbourList, PairExactlyAtReachIsNotListed) {
  // Radii 1 and 1, skin 1: reach = 1 + 1 + 1 = 3. Centres 3 apart (3² = 9 = reach² exactly in
  // binary) are not listed (distance < reach is the rule); 2.999 apart are.
  NeighbourList<2> list(1.0);
  list.rebuild({Vec2{{0.0, 0.0}}, Vec2{{3.0, 0.0}}}, {1.0, 1.0});
  EXPECT_EQ(list.pair_count(), 0u);
  list.rebuild({Vec2{{0.0, 0.0}}, Vec2{{2.999, 0.0}}}, {1.0, 1.0});
  EXPECT_EQ(listed_pairs(list), (PairList{{0, 1}}));
}

template <int D>
void check_refresh_rule() {
  Cloud<D> cloud = random_cloud<D>(cloud_size, box_side<D>, 11);
  NeighbourList<D> list(skin);
  EXPECT_TRUE(list.needs_refresh(cloud.position)) << "never built";
  list.rebuild(cloud.position, cloud.radius);
  EXPECT_FALSE(list.needs_refresh(cloud.position));

  // Every particle moves 0.49 skin in its own random direction: no refresh yet.
  std::mt19937_64 random(12);
  std::normal_distribution<double> gauss;
  const auto random_unit = [&] {
    Vec<D> u;
    for (int a = 0; a < D; ++a) u[a] = gauss(random);
    return u * (1.0 / norm(u));
  };
  Cloud<D> moved = cloud;
  for (auto& x : moved.position) x += (0.49 * skin) * random_unit();
  EXPECT_FALSE(list.needs_refresh(moved.position));

  // Safety of the rule: with every particle moved less than skin/2, every pair that now
  // overlaps (distance < r_i + r_j) is in the list, since it was closer than
  // r_i + r_j + 2 × skin/2 before. (The cloud is placed at random, so some pairs overlap.)
  const PairList listed = listed_pairs(list);
  std::size_t overlapping = 0;
  for (const auto& [i, j] : brute_force_pairs(moved, 0.0)) {
    ++overlapping;
    EXPECT_TRUE(std::binary_search(listed.begin(), listed.end(), std::pair{i, j}))
        << "pair " << i << "-" << j << " touches but is not listed";
  }
  EXPECT_GT(overlapping, 0u);

  // One particle moves 0.51 skin: refresh. The rule is on the distance, not per axis: a move of
  // 0.3 skin along every axis is 0.3 sqrt(D) skin = 0.42 (2D) or 0.52 (3D) skin.
  Cloud<D> one_moved = cloud;
  one_moved.position[123] += (0.51 * skin) * random_unit();
  EXPECT_TRUE(list.needs_refresh(one_moved.position));
  Vec<D> diagonal;
  for (int a = 0; a < D; ++a) diagonal[a] = 0.3 * skin;
  Cloud<D> diagonal_moved = cloud;
  diagonal_moved.position[45] += diagonal;
  EXPECT_EQ(list.needs_refresh(diagonal_moved.position), D == 3);

  // A rebuild takes the new positions as the reference.
  list.rebuild(one_moved.position, one_moved.radius);
  EXPECT_FALSE(list.needs_refresh(one_moved.position));
  EXPECT_EQ(list.rebuild_count(), 2);

  // A particle added (or removed) always asks for a refresh.
  one_moved.position.push_back(one_moved.position[0]);
  EXPECT_TRUE(list.needs_refresh(one_moved.position));
  one_moved.position.pop_back();
  one_moved.position.pop_back();
  EXPECT_TRUE(list.needs_refresh(one_moved.position));
}

TEST(NeighbourList, RefreshOnlyAfterAMoveOfMoreThanHalfTheSkinDiscs) {
  check_refresh_rule<2>();
}

TEST(NeighbourList, RefreshOnlyAfterAMoveOfMoreThanHalfTheSkinSpheres) {
  check_refresh_rule<3>();
}

template <int D>
void check_history_carry_over() {
  Cloud<D> cloud = random_cloud<D>(cloud_size, box_side<D>, 21);
  NeighbourList<D> list(skin);
  list.rebuild(cloud.position, cloud.radius);

  // Mark every pair's history with a value unique to the pair, in every field.
  std::map<std::pair<std::uint32_t, std::uint32_t>, double> marker;
  for (std::size_t p = 0; p < list.pair_count(); ++p) {
    const double m = 1000.0 + static_cast<double>(p);
    marker[{list.first()[p], list.second()[p]}] = m;
    ContactHistory<D>& h = list.history()[p];
    h.dissipated = m;
    h.normal_spring_origin = -m;
    if constexpr (D == 2) {
      h.tangential_spring = 3.0 * m;
    } else {
      h.tangential_spring[0] = 3.0 * m;
    }
    list.touching()[p] = TouchState::touching;
  }

  // Everyone jiggles by up to 0.1 skin per axis (most pairs stay within reach, a few at the
  // margin may leave it); particles 0, 50, 100, ... jump to a new random place in the box, so
  // they drop their old pairs and find new ones.
  std::mt19937_64 random(22);
  std::uniform_real_distribution<double> jiggle(-0.1 * skin, 0.1 * skin);
  std::uniform_real_distribution<double> where(0.0, box_side<D>);
  for (std::size_t i = 0; i < cloud.position.size(); ++i) {
    for (int a = 0; a < D; ++a) {
      cloud.position[i][a] = i % 50 == 0 ? where(random) : cloud.position[i][a] + jiggle(random);
    }
  }
  list.rebuild(cloud.position, cloud.radius);
  const PairList now = brute_force_pairs(cloud, skin);
  ASSERT_EQ(listed_pairs(list), now) << "dropped pairs are gone, new ones are in";

  std::size_t kept = 0;
  std::size_t fresh = 0;
  for (std::size_t p = 0; p < list.pair_count(); ++p) {
    const ContactHistory<D>& h = list.history()[p];
    const auto found = marker.find({list.first()[p], list.second()[p]});
    if (found == marker.end()) {
      ++fresh;
      expect_default(h);
      EXPECT_EQ(list.touching()[p], TouchState::apart);
    } else {
      ++kept;
      const double m = found->second;
      EXPECT_EQ(h.dissipated, m);
      EXPECT_EQ(h.normal_spring_origin, -m);
      if constexpr (D == 2) {
        EXPECT_EQ(h.tangential_spring, 3.0 * m);
      } else {
        EXPECT_EQ(h.tangential_spring[0], 3.0 * m);
      }
      EXPECT_EQ(list.touching()[p], TouchState::touching);
    }
  }
  const std::size_t dropped = marker.size() - kept;
  // The test means something only if all three kinds occur.
  EXPECT_GT(kept, 0u);
  EXPECT_GT(fresh, 0u);
  EXPECT_GT(dropped, 0u);
}

TEST(NeighbourList, KeptPairsKeepTheirHistoryNewPairsStartClearDiscs) {
  check_history_carry_over<2>();
}

TEST(NeighbourList, KeptPairsKeepTheirHistoryNewPairsStartClearSpheres) {
  check_history_carry_over<3>();
}

/// A pair's tangential spring as the force on its second particle, of normal n from the first
/// to the second: the spring itself in 3D, in 2D its length times the tangent of n.
template <int D>
Vec<D> tangential_force_on_second(const ContactHistory<D>& h, const Vec<D>& n) {
  if constexpr (D == 2) {
    return h.tangential_spring * tangent_of(n);
  } else {
    return h.tangential_spring;
  }
}

/// Writes the marker m into every field of a history (in 3D a spring along no axis).
template <int D>
void mark_history(ContactHistory<D>& h, double m) {
  h.dissipated = m;
  h.normal_spring_origin = -m;
  if constexpr (D == 2) {
    h.tangential_spring = 3.0 * m;
  } else {
    h.tangential_spring = Vec3{{3.0 * m, -2.0 * m, 0.5 * m}};
  }
}

template <int D>
void check_history_carried_into_cell_order() {
  const Cloud<D> cloud = random_cloud<D>(cloud_size, box_side<D>, 23);
  NeighbourList<D> list(skin);
  list.rebuild(cloud.position, cloud.radius);
  const auto normal = [&](std::uint32_t from, std::uint32_t to) {
    const Vec<D> offset = list.separation(cloud.position[from], cloud.position[to]);
    return offset * (1.0 / norm(offset));
  };

  // Every pair's history marked with values unique to it; the tangential spring, in 3D a
  // vector along no axis, taken down as the force it makes on the pair's second particle.
  struct Marked {
    double marker;
    Vec<D> force_on_second;
  };
  std::map<std::pair<std::uint32_t, std::uint32_t>, Marked> marked;
  for (std::size_t p = 0; p < list.pair_count(); ++p) {
    const std::uint32_t a = list.first()[p];
    const std::uint32_t b = list.second()[p];
    const double m = 1000.0 + static_cast<double>(p);
    ContactHistory<D>& h = list.history()[p];
    mark_history(h, m);
    list.touching()[p] = TouchState::touching;
    marked[{a, b}] = {m, tangential_force_on_second(h, normal(a, b))};
  }

  // Renumbered into cell order, nothing moved: the same pairs, in new numbers. A pair whose
  // particles come in the other order now has its bodies A and B swapped, and the normal
  // n' = −n. The force on each physical particle must not change, so the force on the new
  // second (the old first) is minus the old force on the old second (Newton's third law). In
  // 3D the spring is that force: it is negated. In 2D it is a length s along the tangent, and
  // tangent_of(−n) = −t: s t' = −s t with s kept. (−n is exactly minus n, the offset being
  // negated and its length the same, so the forces compare exactly.)
  list.rebuild(cloud.position, cloud.radius, true);
  const std::vector<std::uint32_t>& previous = list.previous_index();
  std::size_t swapped = 0;
  std::size_t kept_order = 0;
  for (std::size_t p = 0; p < list.pair_count(); ++p) {
    const std::uint32_t first = previous[list.first()[p]];
    const std::uint32_t second = previous[list.second()[p]];
    const bool is_swapped = first > second;
    const auto found = marked.find({std::min(first, second), std::max(first, second)});
    ASSERT_NE(found, marked.end()) << "pair " << first << "-" << second << " was not listed";
    (is_swapped ? swapped : kept_order) += 1;
    const ContactHistory<D>& h = list.history()[p];
    const Vec<D> expected =
        is_swapped ? -found->second.force_on_second : found->second.force_on_second;
    SCOPED_TRACE(testing::Message() << "pair " << first << "-" << second);
    EXPECT_EQ(tangential_force_on_second(h, normal(first, second)), expected);
    EXPECT_EQ(h.dissipated, found->second.marker);
    EXPECT_EQ(h.normal_spring_origin, -found->second.marker);
    EXPECT_EQ(list.touching()[p], TouchState::touching);
  }
  EXPECT_EQ(swapped + kept_order, marked.size());
  // The test means something only if both kinds occur: a random cloud's numbering is far
  // from the cells' order.
  EXPECT_GT(swapped, 0u);
  EXPECT_GT(kept_order, 0u);
}

TEST(NeighbourList, RenumberingKeepsTheTangentialForceOnEachParticleDiscs) {
  check_history_carried_into_cell_order<2>();
}

TEST(NeighbourList, RenumberingKeepsTheTangentialForceOnEachParticleSpheres) {
  check_history_carried_into_cell_order<3>();
}

/// Builds, marks every pair's history, moves the particles and builds again (into cell order
/// if asked), on `threads` threads whose shares of the particles begin at `shares` (none:
/// even shares), searching four partners at a time or not; gives the list.
template <int D>
NeighbourList<D> list_built_twice(const Cloud<D>& start, const Cloud<D>& moved, int threads,
                                  const std::vector<std::uint32_t>& shares, bool into_cell_order,
                                  bool lanes = true) {
  const int threads_before = omp_get_max_threads();
  omp_set_num_threads(threads);
  NeighbourList<D> list(skin);
  list.set_parallel(true);
  list.set_lane_search(lanes);
  list.set_thread_shares(shares);
  list.rebuild(start.position, start.radius);
  for (std::size_t p = 0; p < list.pair_count(); ++p) {
    const double m = 1000.0 + static_cast<double>(list.first()[p]) +
                     1e-4 * static_cast<double>(list.second()[p]);
    ContactHistory<D>& h = list.history()[p];
    mark_history(h, m);
    list.touching()[p] = p % 3 == 0 ? TouchState::touching : TouchState::apart;
  }
  list.rebuild(moved.position, moved.radius, into_cell_order);
  omp_set_num_threads(threads_before);
  return list;
}

template <int D>
void check_same_list_for_any_threads_and_shares() {
  // Enough particles for the rebuild to run on several threads (at least 512 when asked).
  constexpr std::size_t count = 3000;
  const double side = D == 2 ? 40.0 * std::sqrt(10.0) : 14.0 * std::cbrt(10.0);
  const Cloud<D> start = random_cloud<D>(count, side, 31);
  Cloud<D> moved = start;
  std::mt19937_64 random(32);
  std::uniform_real_distribution<double> jiggle(-0.2 * skin, 0.2 * skin);
  for (auto& x : moved.position) {
    for (int a = 0; a < D; ++a) x[a] += jiggle(random);
  }
  for (const bool into_cell_order : {false, true}) {
    SCOPED_TRACE(into_cell_order ? "into cell order" : "kept order");
    // One thread, one partner at a time: the reference.
    const NeighbourList<D> one = list_built_twice(start, moved, 1, {}, into_cell_order, false);
    if (!into_cell_order) {
      ASSERT_EQ(listed_pairs(one), brute_force_pairs(moved, skin));
    }
    std::size_t touching = 0;
    for (const TouchState t : one.touching()) touching += t == TouchState::touching ? 1 : 0;
    ASSERT_GT(touching, 0u) << "some histories must be carried for the comparison to mean much";
    // Even shares, shares far from even, a share with no particle, and shares of another
    // thread count (ignored: even shares).
    const std::vector<std::vector<std::uint32_t>> shares_tried = {
        {}, {0, 200, count}, {0, 2900, count}, {0, 0, count}, {0, 1000, 2000, count}};
    for (const auto& shares : shares_tried) {
      SCOPED_TRACE(testing::Message() << "shares of " << shares.size() << " bounds");
      const NeighbourList<D> two = list_built_twice(start, moved, 2, shares, into_cell_order);
      ASSERT_EQ(listed_pairs(two), listed_pairs(one));
      ASSERT_EQ(two.first_begin(), one.first_begin());
      ASSERT_EQ(two.previous_index(), one.previous_index());
      ASSERT_EQ(two.reference_position(), one.reference_position());
      for (std::size_t p = 0; p < one.pair_count(); ++p) {
        ASSERT_EQ(two.history()[p].dissipated, one.history()[p].dissipated) << "pair " << p;
        ASSERT_EQ(two.history()[p].normal_spring_origin, one.history()[p].normal_spring_origin);
        ASSERT_EQ(two.history()[p].tangential_spring, one.history()[p].tangential_spring);
        ASSERT_EQ(two.touching()[p], one.touching()[p]);
      }
    }
  }
}

TEST(NeighbourList, SameListAndHistoriesOnAnyThreadsAndSharesDiscs) {
  check_same_list_for_any_threads_and_shares<2>();
}

TEST(NeighbourList, SameListAndHistoriesOnAnyThreadsAndSharesSpheres) {
  check_same_list_for_any_threads_and_shares<3>();
}

TEST(NeighbourList, EmptyListStaysEmpty) {
  NeighbourList<2> list(0.1);
  list.rebuild({}, {});
  EXPECT_EQ(list.pair_count(), 0u);
  EXPECT_FALSE(list.needs_refresh({}));
}

}  // namespace
}  // namespace millsim
