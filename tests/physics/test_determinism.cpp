// Deterministic by construction (STYLE.md rule 5): the same scene stepped on one thread, on
// two and on three gives bitwise-identical particles, energy accounts and collision spectra. The
// stages of World::step() go parallel only above 2048 items (particles, wall candidates,
// listed pairs; `parallel_threshold` in sim/world_detail.hpp), so the scenes are big enough for
// every parallel path to run, and the test checks that they are. The particles are renumbered in
// cell order at every neighbour-list rebuild (the mill job does it less often), during the
// compared steps too, and come out in the same order on one thread and on two.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstddef>
#include <random>
#include <string>
#include <vector>

#include "millsim/core/constants.hpp"
#include "millsim/io/config.hpp"
#include "millsim/measure/spectrum.hpp"
#include "millsim/particles/material.hpp"
#include "millsim/sim/charge.hpp"
#include "millsim/sim/world.hpp"
#include "millsim/sim/world_detail.hpp"

namespace millsim {
namespace {

/// The item count above which a stage of World::step() runs in parallel, and the listed pairs
/// from which the pair stage does: the World's own (read from its header, so that the scenes
/// below follow them if they change).
using world_detail::parallel_pair_threshold;
using world_detail::parallel_threshold;

/// Sets the OpenMP thread count for the life of the object, then puts the old one back.
class ThreadCount {
 public:
  explicit ThreadCount(int threads) : previous_(omp_get_max_threads()) {
    omp_set_num_threads(threads);
  }
  ~ThreadCount() { omp_set_num_threads(previous_); }
  ThreadCount(const ThreadCount&) = delete;
  ThreadCount& operator=(const ThreadCount&) = delete;

 private:
  int previous_;
};

template <int D>
struct Outcome {
  World<D> world;
  ImpactSpectrum spectrum;
  int threads = 1;
};

/// The plan's world with its charge set in motion: every particle moving at up to `speed`
/// (m/s) in a random direction with a random spin, the mill turning at the plan's speed, and
/// then `steps` steps on one thread. The charge is placed without contacts; this makes
/// collisions from the first steps instead of after a long fall, so that the stepping compared
/// below starts from a scene full of contacts and contact history. For a denser scene,
/// `compress` (≤ 1) first draws the particles within `inner` (m) of the axis in towards it by
/// that factor; those beyond stay where they are, among the lifters. The particles are
/// renumbered in cell order at every neighbour-list rebuild.
template <int D>
World<D> moving_scene(const MillPlan& plan, double inner, double compress, double speed,
                      int steps) {
  const ThreadCount one_thread(1);
  World<D> world = build_mill_world<D>(plan);
  world.set_cell_order_interval(1);
  auto& p = world.particles();
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (std::hypot(p.position[i][0], p.position[i][1]) < inner) {
      for (int a = 0; a < 2; ++a) p.position[i][a] *= compress;
    }
    for (int a = 0; a < D; ++a) p.velocity[i][a] = speed * uniform(random) / std::sqrt(D);
    const double spin_scale = speed / p.radius[i];
    if constexpr (D == 2) {
      p.angular_velocity[i] = spin_scale * uniform(random);
    } else {
      for (int a = 0; a < 3; ++a) p.angular_velocity[i][a] = spin_scale * uniform(random);
    }
  }
  world.walls().mill->angular_speed = plan.angular_speed;
  for (int n = 0; n < steps; ++n) world.step();
  return world;
}

/// Steps a copy of `scene` `steps` times on `threads` threads, recording the collisions that
/// end.
/// With avx2_lanes false, the pair stage's lanes use the instructions of any x86-64 processor
/// instead of AVX2 (World::set_avx2_lanes). With `shares`, the threads' runs start from those
/// shares of the pairs' weight (World::set_run_shares) instead of even ones.
template <int D>
Outcome<D> step_on(const World<D>& scene, int steps, int threads, bool avx2_lanes = true,
                   const std::vector<double>& shares = {}) {
  const ThreadCount thread_count(threads);
  EXPECT_EQ(omp_get_max_threads(), threads);
  int team = 0;
#pragma omp parallel
  {
#pragma omp single
    team = omp_get_num_threads();
  }
  EXPECT_EQ(team, threads) << "OpenMP did not give the team asked for";
  Outcome<D> outcome{scene, ImpactSpectrum{}, threads};
  outcome.world.set_avx2_lanes(avx2_lanes);
  if (!shares.empty()) outcome.world.set_run_shares(shares);
  outcome.world.record_collisions_in(&outcome.spectrum);
  for (int n = 0; n < steps; ++n) outcome.world.step();
  outcome.world.record_collisions_in(nullptr);
  return outcome;
}

/// Pairs closer than the neighbour list's cut-off, r_i + r_j + skin: roughly the pairs the pair
/// stage worked on in the last steps (counted by brute force, along a periodic axis by the
/// nearest image).
template <int D>
std::size_t listed_pairs(const World<D>& world) {
  const auto& p = world.particles();
  const double skin = world.neighbour_skin();
  double period = 0.0;
  if constexpr (D == 3) {
    if (world.walls().mill->periodic) period = world.walls().mill->length;
  }
  std::size_t pairs = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      Vec<D> offset = p.position[j] - p.position[i];
      if (period > 0.0) offset[D - 1] -= period * std::nearbyint(offset[D - 1] / period);
      const double reach = p.radius[i] + p.radius[j] + skin;
      if (norm_squared(offset) < reach * reach) ++pairs;
    }
  }
  return pairs;
}

/// Particles that may touch a wall within a skin: the wall stage's candidates.
template <int D>
std::size_t wall_candidates(const World<D>& world) {
  const auto& p = world.particles();
  std::size_t candidates = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (world.walls().may_touch(p.position[i], p.radius[i], world.neighbour_skin())) ++candidates;
  }
  return candidates;
}

/// Indices that hold another particle in `after` than in `before`.
template <int D>
std::size_t renumbered(const World<D>& before, const World<D>& after) {
  std::size_t moved = 0;
  for (std::size_t i = 0; i < after.particles().size(); ++i) {
    moved += before.particle_id(i) != after.particle_id(i) ? 1 : 0;
  }
  return moved;
}

/// Everything a step produces, compared with ==: particle by particle (the same particle at
/// the same index), then the energy accounts, the drive torque, the contacts and the spectrum
/// bin by bin.
template <int D>
void expect_identical(const Outcome<D>& one, const Outcome<D>& two) {
  const auto& a = one.world.particles();
  const auto& b = two.world.particles();
  ASSERT_EQ(a.size(), b.size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const bool same = one.world.particle_id(i) == two.world.particle_id(i) &&
                      a.position[i] == b.position[i] && a.velocity[i] == b.velocity[i] &&
                      a.angular_velocity[i] == b.angular_velocity[i] && a.force[i] == b.force[i] &&
                      a.torque[i] == b.torque[i];
    if (!same && differing++ < 5) {
      ADD_FAILURE() << "particle " << i << " differs between 1 and " << two.threads << " threads"
                    << (two.world.avx2_lanes() ? "" : " (without AVX2)");
    }
  }
  EXPECT_EQ(differing, 0u) << "particles that differ";
  const World<D>& wa = one.world;
  const World<D>& wb = two.world;
  EXPECT_EQ(wa.energy_account().shell_work, wb.energy_account().shell_work);
  EXPECT_EQ(wa.energy_account().dissipated, wb.energy_account().dissipated);
  EXPECT_EQ(wa.last_step_dissipation(), wb.last_step_dissipation());
  EXPECT_EQ(wa.shell_torque(), wb.shell_torque());
  EXPECT_EQ(wa.kinetic_energy(), wb.kinetic_energy());
  EXPECT_EQ(wa.potential_energy(), wb.potential_energy());
  EXPECT_EQ(wa.stored_spring_energy(), wb.stored_spring_energy());
  EXPECT_EQ(wa.touching_contacts(), wb.touching_contacts());
  EXPECT_EQ(wa.neighbour_rebuilds(), wb.neighbour_rebuilds());
  if (wa.walls().mill) {
    EXPECT_EQ(wa.walls().mill->angle, wb.walls().mill->angle);
  }
  for (std::size_t t = 0; t < contact_type_count; ++t) {
    const auto type = static_cast<ContactType>(t);
    for (std::size_t bin = 0; bin < one.spectrum.bin_count(); ++bin) {
      EXPECT_EQ(one.spectrum.count(type, bin), two.spectrum.count(type, bin))
          << contact_type_name(type) << " bin " << bin;
      EXPECT_EQ(one.spectrum.energy(type, bin), two.spectrum.energy(type, bin))
          << contact_type_name(type) << " bin " << bin;
    }
  }
}

TEST(Determinism, SagMill2DIsTheSameOnOneTwoAndThreeThreads) {
  // The 2D SAG benchmark scene (bench/sag-12m-2d.toml): a 12 m mill with forty lifters and
  // about 7 000 discs of 25–150 mm, Δt = 4.5e-5 s, the shell turning at 5 rpm. The charge is
  // placed over the whole mill (30 % filling, so a fifth of its area). The discs within 5.5 m
  // of the axis are drawn in by 0.7 (those beyond, among the 0.2 m lifters from 5.8 m out,
  // stay), all are set moving at up to 3 m/s, and after 200 steps there are thousands of close
  // pairs and hundreds of contacts, some with the shell and lifters. From there, 400 steps on
  // one thread, on two and on three (enough for a change in the order of one particle's pair
  // forces to show: with the forces of pairs across two threads' particles added last, the
  // particles differ after 400 steps but not yet after 80).
  const MillPlan plan = plan_mill(load_mill_config(
      std::string(MILLSIM_SOURCE_DIR) + "/bench/sag-12m-2d.toml", {"output.snapshot_interval=0"}));
  const World<2> scene = moving_scene<2>(plan, 5.5, 0.7, 3.0, 200);
  const Outcome<2> one = step_on(scene, 400, 1);
  const Outcome<2> two = step_on(scene, 400, 2);
  expect_identical(one, two);
  // Three threads split the particles and pairs three ways (more threads than this machine's
  // cores is fine: only the order of the sums is at stake).
  const Outcome<2> three = step_on(scene, 400, 3);
  expect_identical(one, three);
  // The runs' ends where neither the weights nor the measured times would put them (a fifth
  // and four fifths; three ways 0.6, 0.3 and 0.1), and from there balanced by the times.
  expect_identical(one, step_on(scene, 400, 2, true, {0.2, 0.8}));
  expect_identical(one, step_on(scene, 400, 3, true, {0.6, 0.3, 0.1}));
  {
    // The shares take effect: the first of two runs ends earlier from a fifth of the weight
    // than from a half.
    const ThreadCount thread_count(2);
    World<2> even = scene;
    World<2> fifth = scene;
    fifth.set_run_shares({0.2, 0.8});
    even.step();
    fifth.step();
    ASSERT_EQ(even.run_starts().size(), 3u);
    ASSERT_EQ(fifth.run_starts().size(), 3u);
    EXPECT_LT(fifth.run_starts()[1], even.run_starts()[1]);
    EXPECT_GT(fifth.run_starts()[1], 0u);
  }
  // The pair stage's lanes without AVX2, where the processor has it (else the same run twice).
  EXPECT_EQ(one.world.avx2_lanes(), __builtin_cpu_supports("avx2") != 0);
  const Outcome<2> baseline = step_on(scene, 400, 1, false);
  EXPECT_FALSE(baseline.world.avx2_lanes());
  expect_identical(one, baseline);

  // The parallel paths ran: particles and listed pairs above the threshold (the wall stage's
  // candidates, the discs near the shell, stay below it here; the 3D scene covers it), and the
  // neighbour list was rebuilt, carrying contact history, during the compared steps.
  const World<2>& world = one.world;
  EXPECT_GT(world.particles().size(), parallel_threshold);
  EXPECT_GT(listed_pairs(world), parallel_pair_threshold);
  EXPECT_GT(world.neighbour_rebuilds(), scene.neighbour_rebuilds());
  EXPECT_GT(renumbered(scene, world), 0u) << "renumbered during the compared steps";
  // Something happened worth comparing: contacts with each other and with the walls.
  EXPECT_GT(world.touching_contacts(), 300u);
  EXPECT_GT(one.spectrum.total_count(ContactType::ball_ball), 100);
  EXPECT_GT(world.energy_account().dissipated, scene.energy_account().dissipated);
  EXPECT_NE(world.energy_account().shell_work, scene.energy_account().shell_work);
}

/// A short, wide 3D mill full of 1 cm balls: 0.8 m across and only 3 cm long between its end
/// plates (or a periodic slab of 3 cm), sixteen 2 × 2 cm lifters, J = 0.3, 80 % of critical
/// speed. About 5 000 balls; with end plates, the 3 cm between them are three ball diameters,
/// so thousands of balls lie within a skin of one and the wall stage has thousands of
/// candidates (checked below).
std::string short_wide_mill(bool periodic) {
  return fmt::format(R"(
[simulation]
dimension = 3
time_step = "auto"
settle_time = 0.1
revolutions = 1
measure_revolutions = 1
seed = 3

[mill]
diameter = 0.8
length = {}
speed = 0.8
{}

[mill.lifters]
count = 16
height = 0.02
width = 0.02

[charge]
filling = 0.30
porosity = 0.4
density = 7800
ball_diameter = 0.01

[materials.ball_ball]
normal_stiffness = 4.0e5
tangential_stiffness = 3.0e5
restitution = 0.6
friction = 0.6

[materials.ball_wall]
normal_stiffness = 4.0e5
tangential_stiffness = 3.0e5
restitution = 0.5
friction = 0.6

[output]
directory = "runs/tests/determinism"
snapshot_interval = 0
)",
                     periodic ? "0.3" : "0.03",
                     periodic ? "periodic = true\nslab_length = 0.03" : "");
}

void expect_3d_scene_deterministic(bool periodic) {
  // Set moving at up to 4 m/s, 200 steps on one thread (2.3 ms), then 400 more on one, two and
  // three threads.
  const MillPlan plan =
      plan_mill(parse_mill_config(short_wide_mill(periodic), "short-wide-mill.toml"));
  const World<3> scene = moving_scene<3>(plan, 0.0, 1.0, 4.0, 200);
  const Outcome<3> one = step_on(scene, 400, 1);
  const Outcome<3> two = step_on(scene, 400, 2);
  expect_identical(one, two);
  const Outcome<3> three = step_on(scene, 400, 3);
  expect_identical(one, three);
  expect_identical(one, step_on(scene, 400, 2, false));
  expect_identical(one, step_on(scene, 400, 2, true, {0.75, 0.25}));
  expect_identical(one, step_on(scene, 400, 3, true, {0.1, 0.2, 0.7}));

  const World<3>& world = one.world;
  EXPECT_GT(world.particles().size(), parallel_threshold);
  EXPECT_GT(listed_pairs(world), parallel_pair_threshold);
  EXPECT_GT(world.neighbour_rebuilds(), scene.neighbour_rebuilds());
  EXPECT_GT(renumbered(scene, world), 0u) << "renumbered during the compared steps";
  EXPECT_GT(world.touching_contacts(), 100u);
  EXPECT_GT(one.spectrum.total_count(ContactType::ball_ball), 100);
  EXPECT_GT(world.energy_account().dissipated, scene.energy_account().dissipated);
  if (!periodic) {
    EXPECT_GT(wall_candidates(world), parallel_threshold);
    EXPECT_GT(one.spectrum.total_count(ContactType::ball_end_plate), 100);
  }
}

TEST(Determinism, ShortWideMill3DIsTheSameOnOneTwoAndThreeThreads) {
  expect_3d_scene_deterministic(false);
}

TEST(Determinism, PeriodicSlab3DIsTheSameOnOneTwoAndThreeThreads) {
  expect_3d_scene_deterministic(true);
}

TEST(Determinism, SmallSlabSplitInSmallBlocksIsTheSameOnOneTwoAndThreeThreads) {
  // The slab of the scaling benchmark (bench/scaling-mill.toml: 996 balls of 1 cm, 4.1 cm of a
  // 0.3 m mill): a few thousand listed pairs and a few hundred wall candidates, so that its
  // blocks are small (World::pair_block_size) and several of them are shared by two threads'
  // runs or hold pairs across them at every step. Placed apart, drawn in towards the axis and
  // set moving at up to 1 m/s: a loose charge, with tens of contacts at a time.
  const MillPlan plan =
      plan_mill(load_mill_config(std::string(MILLSIM_SOURCE_DIR) + "/bench/scaling-mill.toml",
                                 {"output.snapshot_interval=0"}));
  const World<3> scene = moving_scene<3>(plan, 0.15, 0.75, 1.0, 200);
  const Outcome<3> one = step_on(scene, 600, 1);
  const Outcome<3> two = step_on(scene, 600, 2);
  expect_identical(one, two);
  // Each run did its own candidates of a wall block that both hold, in the last step at least.
  EXPECT_GT(two.world.shared_wall_block_count(), 0u);
  expect_identical(one, step_on(scene, 600, 3));
  // A middle run with a hundredth of the weight, fewer pairs than a block: until the next
  // split the block at its start holds pairs of all three runs, and the last of the three to
  // finish its part sums it.
  expect_identical(one, step_on(scene, 600, 3, true, {0.495, 0.01, 0.495}));
  const World<3>& world = one.world;
  EXPECT_GT(listed_pairs(world), parallel_pair_threshold);
  EXPECT_LT(world.pair_block_size(), 1024u);
  EXPECT_LT(world.wall_block_size(), 256u);
  EXPECT_GT(world.neighbour_rebuilds(), scene.neighbour_rebuilds());
  EXPECT_GT(world.touching_contacts(), 20u);
  EXPECT_GT(one.spectrum.total_count(ContactType::ball_ball), 100);
  EXPECT_GT(one.spectrum.total_count(ContactType::ball_shell), 10);
}

TEST(Determinism, StagesSplitThreeWaysButRunByOneThreadGiveTheSameBits) {
  // World::step splits the particles among as many runs as OpenMP offers threads, and each
  // thread takes its runs in turn; a wall block whose candidates two runs share is done in
  // parts, each run its own candidates. Stepped from inside another parallel region, with
  // nesting off, the step's regions get one thread, which goes through all three runs itself
  // (and so does every part of a shared block, and the cross pairs into a later run at the
  // earlier run's first block holding one instead of at the later run's start, as three
  // threads do). The 3D mill with end plates: thousands of wall candidates, so the runs'
  // boundaries fall inside wall blocks.
  const MillPlan plan =
      plan_mill(parse_mill_config(short_wide_mill(false), "short-wide-mill.toml"));
  const World<3> scene = moving_scene<3>(plan, 0.0, 1.0, 4.0, 200);
  const Outcome<3> one = step_on(scene, 200, 1);
  Outcome<3> nested{scene, ImpactSpectrum{}, 3};
  {
    const ThreadCount thread_count(3);
    const int levels = omp_get_max_active_levels();
    omp_set_max_active_levels(1);
    nested.world.record_collisions_in(&nested.spectrum);
    int inner_team = 0;
    int inner_threads = 0;
#pragma omp parallel num_threads(2)
    {
      if (omp_get_thread_num() == 0) {
        inner_threads = omp_get_max_threads();
#pragma omp parallel
        {
#pragma omp single
          inner_team = omp_get_num_threads();
        }
        for (int n = 0; n < 200; ++n) nested.world.step();
      }
    }
    nested.world.record_collisions_in(nullptr);
    omp_set_max_active_levels(levels);
    EXPECT_EQ(inner_threads, 3) << "the step splits its work three ways";
    EXPECT_EQ(inner_team, 1) << "a nested region gets one thread";
  }
  expect_identical(one, nested);
  EXPECT_GT(wall_candidates(one.world), parallel_threshold);
  EXPECT_GT(listed_pairs(one.world), parallel_pair_threshold);
}

TEST(Determinism, SparseGasOfManyDiscsIsTheSameOnOneAndTwoThreads) {
  // Many particles and few pairs: 4096 discs of 4–6 mm on a 20 mm lattice in a closed box,
  // moving at up to 2 m/s, no gravity. Too few listed pairs to split the pair stage among
  // threads, but enough particles for the integration to run on two: on one thread the step
  // interleaves its stages (World::run_stages_in_one_pass), on two it runs them one after
  // another, the integration split evenly. The same bits either way.
  const ContactMaterial steel{4.0e5, 3.0e5, 0.6, 0.5};
  const int per_row = 64;
  const double spacing = 0.02;  // m
  const double side = per_row * spacing;
  WorldSettings<2> settings;
  settings.ball_ball = steel;
  settings.ball_wall = steel;
  const double density = 7800.0 * 0.01;  // kg/m², a 1 cm thick steel slice
  const double lightest = density * pi * 0.004 * 0.004;
  settings.time_step = contact_duration(steel, 0.5 * lightest) / 20.0;
  Walls<2> walls;
  walls.planes = {
      Plane<2>{Vec2{{0.0, 0.0}}, Vec2{{1.0, 0.0}}}, Plane<2>{Vec2{{side, 0.0}}, Vec2{{-1.0, 0.0}}},
      Plane<2>{Vec2{{0.0, 0.0}}, Vec2{{0.0, 1.0}}}, Plane<2>{Vec2{{0.0, side}}, Vec2{{0.0, -1.0}}}};
  World<2> scene(settings, walls);
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int row = 0; row < per_row; ++row) {
    for (int column = 0; column < per_row; ++column) {
      const double radius = 0.004 + 0.002 * unit(random);
      const double angle = 2.0 * pi * unit(random);
      const double speed = 2.0 * unit(random);
      scene.particles().add(Vec2{{(column + 0.5) * spacing, (row + 0.5) * spacing}}, radius,
                            density * pi * radius * radius,
                            Vec2{{speed * std::cos(angle), speed * std::sin(angle)}});
    }
  }
  const Outcome<2> one = step_on(scene, 1500, 1);
  const Outcome<2> two = step_on(scene, 1500, 2);
  expect_identical(one, two);
  EXPECT_GT(one.world.particles().size(), parallel_threshold);
  EXPECT_LT(listed_pairs(one.world), parallel_pair_threshold);
  EXPECT_GT(one.spectrum.total_count(ContactType::ball_ball), 50);
  EXPECT_GT(one.world.neighbour_rebuilds(), 1);
}

TEST(Determinism, ChargeOfOneMassGivesTheBitsOfDashpotsWorkedOutForEachContact) {
  // In a charge of one ball size the pair and wall kernels take the dashpots' coefficients
  // made once (World::set_uniform_mass_shortcut); they are the bits worked out for each contact
  // from the two masses. The short 3D mill with end plates (balls of 1 cm): pairs and walls.
  const MillPlan plan =
      plan_mill(parse_mill_config(short_wide_mill(false), "short-wide-mill.toml"));
  const World<3> scene = moving_scene<3>(plan, 0.0, 1.0, 4.0, 200);
  const Outcome<3> shortcut = step_on(scene, 300, 1);
  EXPECT_TRUE(shortcut.world.uniform_mass());
  for (const int threads : {1, 2}) {
    const ThreadCount thread_count(threads);
    Outcome<3> worked_out{scene, ImpactSpectrum{}, threads};
    worked_out.world.set_uniform_mass_shortcut(false);
    EXPECT_FALSE(worked_out.world.uniform_mass());
    worked_out.world.record_collisions_in(&worked_out.spectrum);
    for (int n = 0; n < 300; ++n) worked_out.world.step();
    worked_out.world.record_collisions_in(nullptr);
    EXPECT_FALSE(worked_out.world.uniform_mass());
    expect_identical(shortcut, worked_out);
  }
  EXPECT_GT(shortcut.world.touching_contacts(), 100u);
  EXPECT_GT(shortcut.spectrum.total_count(ContactType::ball_end_plate), 100);

  // A mass changed through particles() is seen at the next step, and so is its undoing.
  World<3> world = scene;
  world.step();
  EXPECT_TRUE(world.uniform_mass());
  const double mass = world.particles().mass[0];
  world.particles().mass[0] = 1.5 * mass;
  world.step();
  EXPECT_FALSE(world.uniform_mass());
  world.particles().mass[0] = mass;
  world.step();
  EXPECT_TRUE(world.uniform_mass());
  // The 2D SAG scene's charge has six sizes.
  const MillPlan sag = plan_mill(load_mill_config(
      std::string(MILLSIM_SOURCE_DIR) + "/bench/sag-12m-2d.toml", {"output.snapshot_interval=0"}));
  World<2> graded = build_mill_world<2>(sag);
  graded.step();
  EXPECT_FALSE(graded.uniform_mass());
}

TEST(Determinism, PrefetchingAheadOfThePairKernelChangesNoBit) {
  // Prefetching is for worlds beyond the caches (World::prefetch_pairs from 1 MiB of the
  // arrays it fetches, the 3D window of particles from 8 MiB of its own: about 45 000 balls);
  // forced on here in the periodic slab of 5 184 balls, on one and two threads (the cross pairs
  // and shared blocks of two runs too), it gives the bits of the run without it.
  const MillPlan plan = plan_mill(parse_mill_config(short_wide_mill(true), "periodic-slab.toml"));
  const World<3> scene = moving_scene<3>(plan, 0.0, 1.0, 4.0, 200);
  const Outcome<3> plain = step_on(scene, 300, 1);
  EXPECT_EQ(plain.world.pair_window(), 0u);
  for (const int threads : {1, 2}) {
    const ThreadCount thread_count(threads);
    Outcome<3> fetched{scene, ImpactSpectrum{}, threads};
    fetched.world.set_prefetch_from(1);
    fetched.world.record_collisions_in(&fetched.spectrum);
    for (int n = 0; n < 300; ++n) fetched.world.step();
    fetched.world.record_collisions_in(nullptr);
    EXPECT_GT(fetched.world.pair_window(), world_detail::pair_window_lead) << "window on";
    expect_identical(plain, fetched);
  }
  EXPECT_GT(plain.world.touching_contacts(), 100u);
}

/// Steps a copy of `scene` `steps` times on two threads; halfway, sets one particle's velocity
/// and spin through World::particles(). With `ask_every_step`, particles() is also asked for
/// before every step, so that every step makes its velocity estimates from the particles
/// instead of taking those the last step made (World::step).
template <int D>
Outcome<D> step_changing_halfway(const World<D>& scene, int steps, bool ask_every_step) {
  const ThreadCount thread_count(2);
  Outcome<D> outcome{scene, ImpactSpectrum{}, 2};
  World<D>& world = outcome.world;
  world.record_collisions_in(&outcome.spectrum);
  for (int n = 0; n < steps; ++n) {
    if (ask_every_step) {
      static_cast<void>(world.particles());
      EXPECT_FALSE(world.estimates_made()) << "particles() leaves the last step's estimates";
    }
    if (n == steps / 2) {
      auto& p = world.particles();
      const std::size_t i = p.size() / 2;
      p.velocity[i] = -p.velocity[i];
      p.angular_velocity[i] = 2.0 * p.angular_velocity[i];
    }
    world.step();
    EXPECT_TRUE(world.estimates_made());
  }
  world.record_collisions_in(nullptr);
  return outcome;
}

TEST(Determinism, StepsTakingTheLastStepsEstimatesGiveTheBitsOfStepsMakingThem) {
  // A step takes the velocity estimates u(n), w(n) and the half-skin check that the last
  // step's integration made, unless the particles were given out to be changed in between; then
  // it makes them again. Both ways give the same bits, and a change between steps is seen: the
  // periodic slab (the integration also wraps positions) and the 2D SAG scene.
  const World<3> slab =
      moving_scene<3>(plan_mill(parse_mill_config(short_wide_mill(true), "short-wide-mill.toml")),
                      0.0, 1.0, 4.0, 200);
  const Outcome<3> taken = step_changing_halfway(slab, 200, false);
  const Outcome<3> made = step_changing_halfway(slab, 200, true);
  expect_identical(taken, made);
  EXPECT_GT(taken.world.neighbour_rebuilds(), slab.neighbour_rebuilds());
  // The change halfway was seen: without it the slab ends elsewhere.
  const Outcome<3> unchanged = step_on(slab, 200, 2);
  EXPECT_NE(unchanged.world.kinetic_energy(), taken.world.kinetic_energy());

  const MillPlan sag = plan_mill(load_mill_config(
      std::string(MILLSIM_SOURCE_DIR) + "/bench/sag-12m-2d.toml", {"output.snapshot_interval=0"}));
  const World<2> scene = moving_scene<2>(sag, 5.5, 0.7, 3.0, 200);
  expect_identical(step_changing_halfway(scene, 200, false),
                   step_changing_halfway(scene, 200, true));
}

}  // namespace
}  // namespace millsim
