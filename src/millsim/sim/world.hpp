// World<D>: particles, walls and contacts, advanced one time step at a time by step(), which
// runs the named stages of docs/architecture.md and does nothing else.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <tuple>
#include <utility>
#include <vector>

#include "millsim/contact/linear_spring_dashpot.hpp"
#include "millsim/geometry/walls.hpp"
#include "millsim/measure/shell_impacts.hpp"
#include "millsim/measure/spectrum.hpp"
#include "millsim/particles/material.hpp"
#include "millsim/particles/particle_store.hpp"
#include "millsim/search/neighbour_list.hpp"

namespace millsim {

template <int D>
struct WorldSettings {
  double time_step = 1e-5;  ///< Δt, s
  Vec<D> gravity{};         ///< m/s²
  ContactMaterial ball_ball;
  ContactMaterial ball_wall;
  bool allow_tension = false;  ///< see LinearSpringDashpot; false is the model of MODEL.md
  /// Neighbour-list skin, m; 0 (the default): chosen at each rebuild (World::choose_skin).
  double skin = 0.0;
};

/// With the skin chosen by the World, each neighbour list is made to last about this many
/// steps at the speed of the fastest particle (the list lasts until some particle has moved
/// half a skin). A longer-lived list lists more pairs that are not touching, which every step
/// pays for; a shorter one is rebuilt more often. The optimum is broad (bench/results.md): with
/// 45 rather than 30 the 3D mills measured ran 1–5 % faster and the periodic slabs of 1e3 to
/// 1e6 balls the same; 60 slowed the slabs by 1–3 %. A 2D mill's fast balls meet the ceiling
/// below first.
inline constexpr double skin_target_steps = 45.0;
/// ... and the chosen skin stays between these fractions of the smallest radius: at the
/// floor, a still charge rebuilds only when something moves; at the ceiling, fast particles
/// rebuild every few steps rather than list a growing crowd of neighbours. The crowd grows as
/// ((2r + skin) / 2r)^D: 2D affords three radii (the 2D SAG scene, whose 150 mm balls fall at
/// 10 m/s, runs faster with its lists lasting 28 steps instead of 10: bench/results.md), 3D
/// keeps one, the ceiling of before (no 3D scene measured reaches it).
inline constexpr double skin_floor = 0.05;
template <int D>
inline constexpr double skin_ceiling = D == 2 ? 3.0 : 1.0;

/// Energy accounts since the world was made, J. The balance
/// shell_work = Δkinetic + Δpotential + Δstored + dissipated holds to discretisation error.
struct EnergyAccount {
  double shell_work = 0.0;  ///< work done on the particles by the turning shell and lifters
  double dissipated = 0.0;  ///< dashpots, friction slip and springs forgotten by broken contacts
};

/// Neighbour-list rebuilds between renumberings of the particles into cell order in the mill
/// and scene jobs (World::set_cell_order_interval). On the turning 2D SAG mill, every 10th
/// rebuild misses the first-level cache as seldom as every rebuild does, for 40 % of the extra
/// instructions: the order decays slowly, most particles taking hundreds of steps to cross a
/// cell.
inline constexpr int cell_order_interval = 10;

/// How far each split among threads moves the runs' shares towards their measured speeds
/// (balanced_run_shares). A run's speed over the ~30 steps between two splits is a noisy
/// measure: on the 2D SAG scene, two threads, the runs' median step times between splits
/// differed by ±7 % with no pattern from one split to the next, and their ratio of time to
/// weight was the same on average. A small step filters that noise: a quarter of the way left
/// the threads waiting for each other 9 % of the time, half the way 12 % (eight alternating
/// runs each, bench/results.md).
inline constexpr double run_share_gain = 0.25;

/// The runs' shares of the pairs' weight for the next split among threads (World::step): each
/// run's measured speed since the last split, weights[r] / seconds[r], as a share of all the
/// runs' speeds, taken run_share_gain of the way from the current share and kept within a
/// factor of two of an even share (then scaled to add up to one). Until every run has weight
/// and time, the shares are only brought within those bounds.
std::vector<double> balanced_run_shares(const std::vector<double>& shares,
                                        const std::vector<double>& weights,
                                        const std::vector<double>& seconds);

/// Flags that threads set and wait on within a step: World's cross pairs, each holding a number
/// that grows from step to step, and the counters of its blocks split between runs, zeroed before
/// each step's threads start. Nothing is in flight between steps, so a copy starts with none, and
/// they are made again (zero, below any step's number) when needed.
class StepFlags {
 public:
  StepFlags() = default;
  StepFlags(const StepFlags& /*other*/) {}
  StepFlags& operator=(const StepFlags& other) {
    if (this != &other) {
      flags_.reset();
      size_ = 0;
    }
    return *this;
  }
  StepFlags(StepFlags&&) = default;
  StepFlags& operator=(StepFlags&&) = default;
  ~StepFlags() = default;
  /// At least `count` flags, all zero if they had to be made.
  void reserve(std::size_t count) {
    if (count <= size_) return;
    flags_ = std::make_unique<std::atomic<std::uint64_t>[]>(count);
    size_ = count;
  }
  std::atomic<std::uint64_t>& operator[](std::size_t k) { return flags_[k]; }

 private:
  std::unique_ptr<std::atomic<std::uint64_t>[]> flags_;
  std::size_t size_ = 0;
};

template <int D>
class World {
 public:
  /// Per particle: the shell and up to three lifters; in 3D also the walls of one end (a
  /// flat plate, or a cone and its trunnion plate) and one spare.
  static constexpr int max_wall_contacts = D == 2 ? 4 : max_mill_contacts<3> + 1;
  /// Whether the world keeps each particle's r ω(n−½) in an array of its own for the kernels
  /// (2D), or they multiply it out from the radius and spin (3D): see rim_speed_step_.
  static constexpr bool keeps_step_rim = D == 2;

  World(const WorldSettings<D>& settings, const Walls<D>& walls);

  /// The shares of the pairs' weight that the runs of a step split among threads start from,
  /// one per thread (adding up to one); from then on they follow the runs' measured times
  /// (balanced_run_shares). Where the runs end changes who does what, never a result: for tests
  /// of that.
  void set_run_shares(std::vector<double> shares) {
    split_share_ = std::move(shares);
    split_rebuild_ = -1;  // split again at the next step
  }
  /// Where the runs of the last step split among threads began, one past the last at the end
  /// (particle indices; {0} before any such step).
  const std::vector<std::uint32_t>& run_starts() const { return split_particle_; }

  /// The particles, in the order the step works on them. Particles are added at the end;
  /// with cell ordering on (set_cell_order_interval) they are renumbered at neighbour-list
  /// rebuilds, and a particle is known for good by its id, the index it was added at.
  /// Changes made through the reference are seen by the next step. Ask for it again after
  /// every step() to change the particles: a step that follows another with no call here in
  /// between takes the velocity estimates the last step made for it (debug builds check that
  /// nothing changed, and stop if something did).
  ParticleStore<D>& particles() {
    estimates_made_ = false;
    return particles_;
  }
  const ParticleStore<D>& particles() const { return particles_; }
  /// The id of the particle at this index of particles().
  std::size_t particle_id(std::size_t index) const {
    return index < particle_id_.size() ? particle_id_[index] : index;
  }
  /// The index in particles() of the particle with this id.
  std::size_t particle_index(std::size_t id) const {
    return id < particle_index_.size() ? particle_index_[id] : id;
  }
  /// Whether the next step will take the velocity estimates the last step made (true after a
  /// step, false once particles() has given the particles out to be changed).
  bool estimates_made() const { return estimates_made_; }
  /// A copy of the particles in the order of their ids, as they were added.
  ParticleStore<D> particles_by_id() const;

  /// From now on, every `rebuilds`-th rebuild of the neighbour list (from the next one) also
  /// renumbers the particles in the order of the search grid's cells, so that the step reads
  /// particles near each other in space from nearby memory (0, the default: never). The
  /// physics is the same; only the order of sums changes, and with it the last bits.
  void set_cell_order_interval(int rebuilds) { cell_order_interval_ = rebuilds; }
  /// Whether each wall candidate keeps the list of lifters it may touch (on by default; see
  /// refresh_nearby_lifters). Off, every step finds them from the candidate's angle. The
  /// contacts, and so the results, are the same bit for bit either way; tests switch it off
  /// to show that.
  void set_nearby_lifter_lists(bool on) {
    nearby_lifter_lists_ = on;
    nearby_lifters_.clear();
  }
  /// Whether the pair and wall stages' lanes (core/lanes.hpp) and the integration use AVX2
  /// instructions, as they do by default where the processor has them; off, the instructions of
  /// any x86-64 processor. The
  /// results are the same bit for bit either way; tests switch it off to show that.
  void set_avx2_lanes(bool on);
  bool avx2_lanes() const { return avx2_lanes_; }
  /// Whether, when every particle has the same mass (a charge of one ball size), the pair and
  /// wall kernels take the dashpots' coefficients made once for that mass (the default), or
  /// work them out for each contact as for a charge of several sizes. The same bits either way;
  /// tests switch it off to show that.
  void set_uniform_mass_shortcut(bool on) {
    uniform_mass_shortcut_ = on;
    check_uniform_mass();
  }
  /// Whether the kernels take that shortcut now (as of the last step).
  bool uniform_mass() const { return uniform_mass_; }
  /// From the next rebuild, `bytes` replaces both built-in sizes from which the step prefetches
  /// (world_detail::prefetch_threshold_bytes, for prefetch_pairs' arrays, and
  /// pair_window_threshold_bytes, for the 3D window's); 0 puts them back. Prefetching changes
  /// no value; tests turn it on in small worlds to show that.
  void set_prefetch_from(std::size_t bytes) { prefetch_from_bytes_ = bytes; }
  /// The pair kernel's window of prefetched particles as of the last rebuild (0: none).
  std::size_t pair_window() const { return pair_window_; }
  /// How often the lists of nearby lifters were made, at rebuilds and because the mill had
  /// turned too far since.
  long nearby_lifter_refreshes() const { return nearby_lifter_refreshes_; }
  Walls<D>& walls() { return walls_; }
  const Walls<D>& walls() const { return walls_; }
  const WorldSettings<D>& settings() const { return settings_; }
  /// The skin of the current neighbour list, m (WorldSettings::skin, or the World's choice).
  double neighbour_skin() const { return neighbours_.skin(); }

  /// Collisions that end from now on are added to `spectrum` (nullptr: not recorded).
  void record_collisions_in(ImpactSpectrum* spectrum) { spectrum_ = spectrum; }
  /// The same for where wall collisions began (nullptr: none).
  void record_impacts_in(ShellImpacts* impacts) { impacts_ = impacts; }

  /// Advances the world by one time step.
  void step();

  double time() const { return time_; }
  long steps() const { return steps_; }
  const EnergyAccount& energy_account() const { return account_; }
  /// Torque the drive applied to the shell in the last step (about +z), N m.
  double shell_torque() const { return shell_torque_; }
  /// Energy dissipated in the last step, J.
  double last_step_dissipation() const { return last_step_dissipation_; }
  long neighbour_rebuilds() const { return neighbours_.rebuild_count(); }
  std::size_t touching_contacts() const;
  /// Wall contacts left out since the world was made because every one of the particle's
  /// max_wall_contacts slots of wall-contact history held another wall: a particle pressed
  /// into more walls at once than that (five or more of a scene's planes in 2D, say). A mill's
  /// particle touches at most the shell, three lifters (the search tests no more) and, in 3D,
  /// an end plate or a cone and its trunnion plate: as many as the slots in 2D, one fewer in
  /// 3D. The runs warn of any.
  long dropped_wall_contacts() const { return dropped_wall_contacts_; }
  /// Particles that may touch a wall before the next neighbour-list rebuild.
  std::size_t wall_candidate_count() const { return wall_candidates_.size(); }
  /// Pairs per block of the pair stage, and wall candidates per block of the wall stage: the
  /// unit of the threads' work and of partial sums, chosen at each neighbour-list rebuild from
  /// the list alone, never from the number of threads.
  std::size_t pair_block_size() const { return pair_block_; }
  std::size_t wall_block_size() const { return wall_block_; }
  /// Wall blocks whose candidates belong to more than one run in the last step split among
  /// threads (each run does its own part of them), for tests.
  std::size_t shared_wall_block_count() const { return shared_wall_blocks_.size(); }

  double kinetic_energy() const;        ///< translation and rotation, J
  double potential_energy() const;      ///< −Σ m g·x, J
  double stored_spring_energy() const;  ///< held by the springs of all current contacts, J
  /// The deepest overlap of any current contact as a fraction of the smaller radius (of the
  /// particle, against a wall): the pairs' at the positions now, the walls' as the last step
  /// found them. A linear spring soft for its balls and speeds lets them sink into each other
  /// and, past 1, through walls.
  double largest_overlap_fraction() const;

 private:
  // The stages of step(), in order.
  /// Makes a new neighbour list if `moved` (some particle has moved half a skin since the last
  /// one: estimate_current_velocities says) or particles were added.
  void refresh_neighbours(bool moved);
  /// The skin for the list about to be built: 2 skin_target_steps Δt |u̇|max, within
  /// [skin_floor, skin_ceiling<D>] of the smallest radius.
  double choose_skin() const;
  /// u̇(n), ω(n) of every particle; returns whether some particle has moved more than half the
  /// skin since the neighbour list was made, found in the same pass (or particles were added).
  /// Runs only when the last step has not made them (estimates_made_).
  bool estimate_current_velocities();
  /// The estimate at the time of the positions of a velocity (spin) known at the half step:
  /// u̇(n) ≈ u̇(n−½) + ½ Δt F/m, with the last step's force (and ω the same way with the torque
  /// and the inverse inertia). Written once for the three places that make it.
  template <class V>
  static V estimate_now(const V& half_step_value, double inverse, const V& sum, double half_step) {
    return half_step_value + (half_step * inverse) * sum;
  }
  /// In debug builds, stops if the estimates the last step made differ from those of the
  /// particles now (they were changed through a reference kept across steps).
  void check_estimates_made() const;
  /// Whether the pair, wall and integration stages all run on one thread this step; then
  /// run_stages_in_one_pass does them.
  bool stages_on_one_thread();
  /// The three stages interleaved, on one thread: a particle is advanced as soon as its forces
  /// are summed. Returns what accumulate_forces_and_integrate returns.
  bool run_stages_in_one_pass();
  /// The same on several threads, each on its own run of particles (split_pairs_among).
  bool run_stages_split_among_threads();
  /// The cross pairs into run `run` (their second particle in it) evaluated in this step, their
  /// forces in cross_force_ and outcomes in pair_status_ and pair_energy_: by this thread if no
  /// other has taken them, else waited for.
  void do_cross_pairs(std::size_t run);
  /// A run's part of mixed block b done: the block's dissipation and ended collisions summed
  /// from its pairs' outcomes, by the thread of the last run to finish its part of it.
  void finish_mixed_part(std::size_t b);
  /// Where wall block `block` is in shared_wall_blocks_ (it must be there).
  std::size_t shared_wall_block_index(std::size_t block) const;
  /// The shared wall blocks' sums and ended collisions, added up from their runs' parts in run
  /// order after the runs (each part is cleared for the next step).
  void add_up_shared_wall_blocks();
  /// Zeroes the force and torque sums of particles [begin, end).
  void zero_sums(std::size_t begin, std::size_t end);
  /// One thread's run of particles [particle_begin, particle_end), with the wall candidates
  /// [candidate_begin, candidate_end) that are theirs, taken through the wall and integration
  /// stages as the pair stage completes their sums.
  class ParticleRun {
   public:
    /// `run`: which of the step's runs it is, for its parts of shared wall blocks.
    ParticleRun(World& world, std::size_t particle_begin, std::size_t particle_end,
                std::size_t candidate_begin, std::size_t candidate_end, std::size_t run = 0);
    /// Every particle of the run below `complete` has all its pair forces: does the wall blocks
    /// whose candidates all do, and advances the particles that have all their forces.
    void advance_below(std::size_t complete);
    bool moved = false;  ///< whether an advanced particle has moved half a skin

   private:
    World& world_;
    std::size_t advanced_;
    std::size_t particle_end_;
    std::size_t candidate_begin_, candidate_end_;
    std::size_t next_wall_block_, wall_block_end_;
    std::size_t run_;
  };
  void evaluate_pair_contacts();
  /// Block b of the pairs on this thread: its listed pairs found and evaluated, their forces
  /// added to both particles in pair order, the block's dissipation and ended collisions kept.
  void evaluate_pair_block(std::size_t b);
  /// The pair stage's last part: the step's dissipation so far and the ended collisions.
  void finish_pair_stage();
  /// The pairs of block `block` listed in `listed` (those that overlap or did until now), in
  /// pair order, lane_count at a time (core/lanes.hpp): their contacts are worked out side by
  /// side, then each pair's outcome applied in pair order as one at a time would. Adds the
  /// pairs' dissipation to `dissipated` and lists the collisions that end; or, with
  /// `each_apart` (a block that two threads share), keeps each pair's outcome in pair_status_
  /// and pair_energy_ instead, to be summed in pair order once both are done. With `stored`
  /// (cross pairs: do_cross_pairs), outcomes kept apart too, and the k-th listed pair's force
  /// and moment, if it touches, put in stored[k] instead of added to its particles. Compiled
  /// twice, for processors with AVX2 and for any x86-64; the same bits either way.
  struct PairForce;
  void evaluate_listed_pairs(std::size_t block, const std::uint32_t* listed, std::size_t count,
                             double& dissipated, std::uint32_t& ended, bool each_apart = false,
                             PairForce* stored = nullptr);
#if defined(__x86_64__)
  __attribute__((target("avx2"))) void evaluate_listed_pairs_avx2(
      std::size_t block, const std::uint32_t* listed, std::size_t count, double& dissipated,
      std::uint32_t& ended, bool each_apart, PairForce* stored);
#endif
  /// evaluate_listed_pairs' choice of the kernel's three ways of keeping outcomes, inlined into
  /// both versions (AVX2 and any x86-64).
  [[gnu::always_inline]] inline void evaluate_listed_pairs_each_way(
      std::size_t block, const std::uint32_t* listed, std::size_t count, double& dissipated,
      std::uint32_t& ended, bool each_apart, PairForce* stored);
  [[gnu::always_inline]] inline void evaluate_listed_pairs_in_lanes(
      std::size_t block, const std::uint32_t* listed, std::size_t count, double& dissipated,
      std::uint32_t& ended, bool each_apart, PairForce* stored);
  /// Lists in `listed` the pairs of [begin, end) whose second particle is below `below` and that
  /// overlap or did until now, in pair order, the last one repeated up to a whole group of
  /// lanes; returns how many there are.
  std::size_t list_pairs_for_law(std::size_t begin, std::size_t end, std::size_t below,
                                 std::uint32_t* listed) const;
  /// The same, without the repeats, for a world periodic or not, and for `below` at or beyond
  /// the last particle (every pair is the caller's) or not.
  template <bool periodic, bool every_pair>
  std::size_t list_pairs_of(std::size_t begin, std::size_t end, std::size_t below,
                            std::uint32_t* listed) const;
#if defined(__x86_64__)
  /// list_pairs_of with AVX2, four pairs at a time: the same list.
  template <bool periodic, bool every_pair>
  __attribute__((target("avx2"))) std::size_t list_pairs_avx2(std::size_t begin, std::size_t end,
                                                              std::size_t below,
                                                              std::uint32_t* listed) const;
#endif
  /// A listed pair's outcome: its collision ended with `energy`, or it touches and dissipated
  /// `energy` in this step; into the block's sums, or kept apart (evaluate_listed_pairs).
  [[gnu::always_inline]] void record_pair_end(std::uint32_t pair, double energy, std::size_t begin,
                                              std::uint32_t& ended, bool each_apart) {
    if (each_apart) {
      pair_status_[pair] = PairStatus::ended;
      pair_energy_[pair] = energy;
    } else {
      pair_ended_[begin + ended++] = {.type = ContactType::ball_ball, .energy = energy};
    }
  }
  [[gnu::always_inline]] void record_pair_touch(std::uint32_t pair, double energy,
                                                double& dissipated, bool each_apart) {
    if (each_apart) {
      pair_status_[pair] = PairStatus::touching;
      pair_energy_[pair] = energy;
    } else {
      dissipated += energy;
    }
  }
  /// Asks the processor to fetch what the pair kernel will read and write of listed pairs
  /// [begin, end): their history, and both particles' velocities, spins, masses and sums.
  [[gnu::always_inline]] inline void prefetch_pairs(const std::uint32_t* listed, std::size_t begin,
                                                    std::size_t end);
  /// Asks the processor to fetch every cache line of the pair kernel's particle arrays (those
  /// of prefetch_pairs, and the positions and radii) that holds a part of particles [from, to),
  /// into its second-level cache (pair_window_).
  [[gnu::always_inline]] inline void prefetch_particles(std::size_t from, std::size_t to);
  void split_pairs_among(int threads);
  /// Whether the pair stage runs on several threads; if so, makes sure its split of particles
  /// and pairs among them (split_pairs_among) is that of the current list and thread count.
  bool pairs_split_among_threads();
  /// body(begin, end) for runs of particles that together are all of them, once each: on
  /// several threads each its own run of particles of the pair stage (so that a thread's
  /// particles stay in its core's cache from stage to stage), else on one thread, or split
  /// evenly if there are many particles but few pairs. Returns whether any call returned true.
  template <class Body>
  bool for_each_particle_run(Body&& body);
  /// A wall slot's history, with the overlap its stored-energy account needs (a pair's is
  /// worked out from the positions instead: stored_spring_energy).
  struct WallHistory : ContactHistory<D> {
    double overlap = 0.0;  ///< δ at the last evaluation, m
    /// Where the collision began: std::atan2(y, x) of the contact point at its first step
    /// (ShellImpacts).
    double start_angle = 0.0;
  };
  /// A wall contact of a candidate (the contact itself is kept beside it, in an array of
  /// WallContact): where its history is, and what the contact law made of it.
  struct WallWork {
    std::uint32_t particle = 0;
    std::uint32_t slot = 0;  ///< in wall_slot_history_
    Vec<D> force{};
    Spin<D> moment{};  ///< −r n × F_t
    double dissipated = 0.0;
  };
  /// The contact law of `count` wall contacts, lane_count at a time (core/lanes.hpp): each
  /// contact's force, moment and dissipation, and its history updated. Compiled twice, as
  /// evaluate_listed_pairs is; the same bits as the law on one contact.
  void evaluate_wall_laws(const WallContact<D>* contact, WallWork* work, std::size_t count);
#if defined(__x86_64__)
  __attribute__((target("avx2"))) void evaluate_wall_laws_avx2(const WallContact<D>* contact,
                                                               WallWork* work, std::size_t count);
#endif
  [[gnu::always_inline]] inline void evaluate_wall_laws_in_lanes(const WallContact<D>* contact,
                                                                 WallWork* work, std::size_t count);
  /// Whether the mill has conical ends (never in 2D).
  bool mill_has_cones() const;
  /// Whether particle i is surely clear of the shell of radius shell_radius and, in a 3D
  /// mill with flat ends, of the end plates (a wall-stage shortcut: evaluate_wall_block).
  bool clear_of_shell_and_ends(std::uint32_t i, double shell_radius) const;
  void refresh_nearby_lifters();
  bool lifters_moved_too_far() const;
  void evaluate_wall_contacts();
  /// A collision that ended in a parallel stage, recorded in the spectrum after it in a fixed
  /// order (blocks in order, then in the order they were found), so any thread count gives the
  /// same spectrum.
  struct EndedCollision {
    ContactType type = ContactType::ball_ball;
    float start_angle = 0.0F;  ///< a wall collision's WallHistory::start_angle, rad
    double energy = 0.0;
  };
  /// One contact's terms of its wall block's sums: dissipation, and, unless the wall is a plane
  /// (which does not turn with the mill), torque and work.
  struct WallTerm {
    double dissipated = 0.0;
    double torque = 0.0;
    double work = 0.0;
    bool turns = false;
  };
  /// A wall block's sums, made contact by contact in the candidates' order: by one thread
  /// going through the block, or from the runs' parts (add_up_shared_wall_blocks), with the
  /// same additions.
  struct WallBlockSum {
    double torque = 0.0;
    double work = 0.0;
    double dissipated = 0.0;
    void add(const WallTerm& term) {
      dissipated += term.dissipated;
      if (term.turns) {
        torque += term.torque;
        work += term.work;
      }
    }
  };
  /// One run's part of a wall block that several runs share: its contacts' terms and the
  /// collisions that ended, in the order found. On a cache line of its own: the runs' threads
  /// write their parts at once.
  struct alignas(64) WallPart {
    std::vector<WallTerm> terms;
    std::vector<EndedCollision> ended;
  };
  /// Block b of the wall candidates on this thread: their contacts found and evaluated, each
  /// candidate's wall forces added to its sums, the block's torque, work, dissipation and ended
  /// collisions kept.
  void evaluate_wall_block(std::size_t b);
  /// The same for the block's candidates [begin, end) alone, with the block's sums and ended
  /// collisions kept in `part` (nullptr: the whole block, kept as evaluate_wall_block keeps
  /// them) to be added up with the other runs' parts (add_up_shared_wall_blocks).
  void evaluate_wall_candidates(std::size_t b, std::size_t begin, std::size_t end, WallPart* part);
  /// Block b's sums and count of ended collisions, kept for finish_wall_stage.
  void keep_wall_block(std::size_t b, const WallBlockSum& sum, std::uint32_t ended) {
    wall_block_torque_[b] = sum.torque;
    wall_block_work_[b] = sum.work;
    wall_block_dissipated_[b] = sum.dissipated;
    wall_block_ended_[b] = ended;
  }
  /// The wall stage's last part: the block sums added up in block order.
  void finish_wall_stage();
  /// Also makes the next step's velocity estimates, and returns whether some particle has moved
  /// more than half the skin since the neighbour list was made.
  bool accumulate_forces_and_integrate();
  /// Particles [begin, end) advanced by the loop for this world (integrate_particles).
  bool integrate_run(std::size_t begin, std::size_t end);
  /// The arrays the integration reads and writes, by pointer, for its loops to hold in locals
  /// (through the vectors the compiler could not tell that the loops' stores leave the vectors'
  /// and the list's members unchanged). In the order the loops bind them.
  struct IntegrationArrays {
    Vec<D>* force;
    const Spin<D>* torque;
    Vec<D>* velocity;
    Vec<D>* position;
    Spin<D>* spin;
    const double* mass;
    const double* inverse_mass;
    const double* inverse_inertia;
    const double* radius;
    Vec<D>* velocity_now;     ///< u̇(n+1) estimates (velocity_now_)
    Spin<D>* rim_now;         ///< r ω(n+1) estimates (rim_speed_now_)
    Spin<D>* rim_step;        ///< r ω(n+½) (rim_speed_step_; 2D only)
    const Vec<D>* reference;  ///< positions at the last rebuild
  };
  IntegrationArrays integration_arrays();
  /// Its loop over particles [begin, end), for a periodic slab or not. Processors with AVX2 run
  /// a second version, the same bits either way (integrate_particles_avx2): in 2D four discs at
  /// a time (a 2D world is never periodic), in 3D four spheres at a time, periodic or not.
  template <bool periodic>
  [[gnu::always_inline]] inline bool integrate_particles(std::size_t begin, std::size_t end);
  __attribute__((target("avx2"))) bool integrate_particles_avx2(std::size_t begin, std::size_t end);
  void advance_walls();

  /// Puts every per-particle array in the new order: `previous[k]` is the index before of the
  /// particle that moves to index k.
  void reorder_particles(const std::vector<std::uint32_t>& previous);

  /// Period of the mill's axis when it is a periodic slab, else 0.
  double axial_period() const;

  /// Whether every particle has the same mass (a charge of one ball size), and if so the
  /// dashpots' coefficients of every pair and of every wall contact, the same bits
  /// LinearSpringDashpot::damping gives from the masses. Made again whenever the particles may
  /// have changed.
  void check_uniform_mass();

  void record_ended(const std::vector<EndedCollision>& ended,
                    const std::vector<std::uint32_t>& block_ended, std::size_t block_capacity);

  WorldSettings<D> settings_;
  Walls<D> walls_;
  ParticleStore<D> particles_;
  LinearSpringDashpot ball_ball_law_;
  LinearSpringDashpot ball_wall_law_;
  NeighbourList<D> neighbours_;
  ImpactSpectrum* spectrum_ = nullptr;
  ShellImpacts* impacts_ = nullptr;

  // u̇(n) ≈ u̇(n−½) + ½ ü(n−1) Δt and the same for ω: the velocities at the time of the
  // positions, which the dashpots and springs use so that the work they account for is the
  // work the leapfrog update does (docs/model.md, "energy account").
  std::vector<Vec<D>> velocity_now_;
  // The spins as the contact laws take them, times the radius: r ω(n), from that estimate, and
  // (2D only) r ω(n−½), over the last step. Made where the spins are (integration, or
  // estimate_current_velocities), so that the kernels gather one array per particle for each,
  // not two and a product: the 2D SAG scene's pair kernel 3.4 % fewer instructions, its step
  // 1.4 % (bench/results.md). The same products, so the same bits. A 3D world's kernels take
  // r ω(n−½) from the radius and spin instead: there each sphere's three more components stored
  // at every step cost more than the product saves (the 1e6-ball slab 2 %, the 996-ball one 2 %
  // and the 3D 20 k mill 1 % faster on one thread without them; bench/results.md).
  std::vector<Spin<D>> rim_speed_now_;
  std::vector<Spin<D>> rim_speed_step_;  // empty in 3D (keeps_step_rim)
  /// r ω(n−½) of particle i as the kernels take it: kept in rim_speed_step_ (2D) or multiplied
  /// out (3D), the same product either way.
  Spin<D> step_rim(std::uint32_t i) const {
    if constexpr (keeps_step_rim) {
      return rim_speed_step_[i];
    } else {
      return particles_.radius[i] * particles_.angular_velocity[i];
    }
  }
  // Particles all of one mass (check_uniform_mass): the kernels then take the dashpots'
  // coefficients as they are instead of working them out for each contact and step (a square
  // root and two divisions for four contacts, which the 3D law waits on). A charge of several
  // sizes works them out: looking them up by the two sizes took as long (bench/results.md).
  bool uniform_mass_ = false;
  bool uniform_mass_shortcut_ = true;
  ContactDamping uniform_pair_damping_;
  ContactDamping uniform_wall_damping_;
  // Whether velocity_now_ and the rim speeds are those of the particles now, made by the last
  // step's integration in the same pass (saving a pass over the particle arrays, which in 3D lie
  // beyond the second-level cache), and whether a particle had then moved half a skin. Cleared
  // when particles() gives the particles out to be changed.
  bool estimates_made_ = false;
  bool moved_half_skin_ = false;

  // A pair's contact in one step: the force on the second particle and the moment per unit
  // radius, −n × F_t, that both particles receive (scaled by their radii).
  struct PairForce {
    Vec<D> force{};
    Spin<D> moment{};
  };
  // What happened to a pair in this step, and its energy: dissipated if touching, the
  // collision's total if it ended.
  enum class PairStatus : std::uint8_t { apart, touching, ended };
  // Several threads (evaluate_pair_contacts): per thread, the first of its particles and of
  // its pairs (and one past the last, at the end), for split_threads_ threads and the list of
  // rebuild split_rebuild_; the cross pairs, in pair order, and their forces this step; and per
  // pair this step's status and energy, summed into the blocks afterwards.
  std::vector<std::uint32_t> split_particle_{0}, split_pair_{0};
  int split_threads_ = 0;
  long split_rebuild_ = -1;
  // Balancing the runs by their measured times (split_pairs_among): per run, its share of the
  // pairs' weight, the weight it was given at the last split, and the seconds its thread has
  // spent on it since. Where each run ends changes only who does what, never a result.
  std::vector<double> split_share_;
  std::vector<double> split_weight_;
  std::vector<double> run_seconds_;
  std::vector<std::uint32_t> cross_pairs_;
  std::vector<PairForce> cross_force_;
  std::vector<PairStatus> pair_status_;
  std::vector<double> pair_energy_;
  // Per block of pairs, whether it is split between two threads' runs or holds a cross pair
  // (then its pairs' status and energy are kept apart), and those blocks in order.
  std::vector<std::uint8_t> block_mixed_;
  // The blocks split between runs, in order; how many runs hold pairs of each; and how many of
  // those have done their part in this step (finish_mixed_part).
  std::vector<std::uint32_t> split_blocks_, split_block_parts_;
  StepFlags split_block_done_;
  // Per thread (run_stages_split_among_threads), the first of its wall candidates; the wall
  // blocks that hold candidates of two threads, and each run's part of them (run t's part of
  // shared block k at k × runs + t).
  std::vector<std::uint32_t> split_candidate_;
  std::vector<std::uint32_t> shared_wall_blocks_;
  std::vector<WallPart> shared_wall_parts_;
  // The number of steps that have split the stages among threads, this one included.
  std::uint64_t split_step_count_ = 0;
  // The cross pairs by the run of their second particle (indices into cross_pairs_, run u's
  // from cross_of_run_begin_[u]), and per run how far the steps have evaluated them
  // (do_cross_pairs: the flag holds a number from split_step_count_).
  std::vector<std::uint32_t> cross_of_run_, cross_of_run_begin_;
  StepFlags cross_done_;
  // Work is split in blocks of a fixed size; each block keeps its own sums and ended
  // collisions, added up in block order, so results do not depend on the number of threads.
  std::size_t pair_block_ = 1024;  // pairs per block, and candidates per wall block, chosen
  std::size_t wall_block_ = 256;   // at each rebuild (block_size_for in world_detail.hpp)
  std::vector<EndedCollision> pair_ended_;  // block b's at [b × pair_block_, ...)
  std::vector<std::uint32_t> pair_block_ended_;
  std::vector<double> pair_block_dissipated_;

  // Particles that may touch a wall before the next neighbour-list rebuild.
  std::vector<std::uint32_t> wall_candidates_;
  // Per wall candidate (in the order of wall_candidates_), max_wall_contacts slots of
  // wall-contact history keyed by wall id: the ids candidate by candidate (k × slots + slot),
  // the histories slot by slot (wall_history_index); per particle, which candidate's slots are
  // its own (no_wall_slots: none, it is not a candidate); and the arrays the next rebuild fills.
  static constexpr std::uint32_t no_wall_slots = 0xffffffffU;
  std::vector<std::int32_t> wall_slot_id_, next_wall_slot_id_;
  std::vector<WallHistory> wall_slot_history_, next_wall_slot_history_;
  /// Where candidate k's slot `slot` keeps its history in wall_slot_history_: slot by slot, each
  /// slot an array over the candidates. Most touching candidates hold their one contact in slot
  /// 0, so the histories a step reads lie close together in that array, in candidate order;
  /// candidate by candidate (six 48-byte slots each in 3D) every one was a cache line of its own
  /// (bench/results.md, fortieth session: the 1e6-ball slab 7 % faster on one thread).
  std::size_t wall_history_index(std::size_t k, std::size_t slot) const {
    return slot * wall_candidates_.size() + k;
  }
  std::vector<std::uint32_t> wall_slots_of_;
  // Scratch of the candidates' listing: where each thread's candidates begin (and, last, how
  // many there are), which particles are candidates, and the slots of those that left.
  std::vector<std::uint32_t> candidate_share_;
  std::vector<std::uint8_t> is_candidate_;
  std::vector<std::vector<std::uint32_t>> leaving_slots_;
  // Per wall candidate, the lifters it may touch until the next rebuild or until the lifters
  // have moved lifter_travel_ (arc length at the shell) since they were listed, at mill angle
  // nearby_lifter_angle_ (refresh_nearby_lifters).
  bool nearby_lifter_lists_ = true;
  bool avx2_lanes_ = false;
  /// Whether the step prefetches what it will read out of memory order (the pair kernel's
  /// prefetch_pairs, the one-pair-at-a-time first pass, the wall slots' histories, the 3D
  /// integration): set at each rebuild from the size of the particle arrays (above 1 MiB).
  bool prefetch_pairs_ = false;
  /// In 3D worlds whose arrays outgrow the last-level cache, how many particles beyond a pair's
  /// first the pair kernel has the particle arrays fetched: as it goes down the pairs it asks
  /// for every line of those arrays up to first + pair_window_ (prefetch_particles), so that
  /// the second particles, met out of order up to a layer of cells ahead in the cell order,
  /// are in the second-level cache when their pairs come; prefetch_pairs then brings each
  /// pair's lines from there into the first-level cache. (Pair by pair alone, the fetch from
  /// memory came too late: the 1e6-ball slab 30 % slower, bench/results.md, forty-first
  /// session.) Set at each rebuild (world_detail::pair_window_for); 0: no window.
  std::size_t pair_window_ = 0;
  std::size_t prefetch_from_bytes_ = 0;  // set_prefetch_from; 0: the built-in sizes
  std::vector<NearbyLifters> nearby_lifters_;
  double nearby_lifter_angle_ = 0.0;
  double lifter_travel_ = 0.0;
  int nearby_lifter_count_ = 0;
  long nearby_lifter_refreshes_ = 0;
  long dropped_wall_contacts_ = 0;          // (added to by the threads' wall stages, atomically)
  std::vector<EndedCollision> wall_ended_;  // block b's at [b × wall_block_ × max, ...)
  std::vector<std::uint32_t> wall_block_ended_;
  std::vector<double> wall_block_dissipated_, wall_block_torque_, wall_block_work_;

  // Per index the particle's id, and per id its index; extended when particles are added.
  std::vector<std::uint32_t> particle_id_;
  std::vector<std::uint32_t> particle_index_;
  int cell_order_interval_ = 0;
  // Buffers that reorder_particles swaps with the arrays it copies into the new order, one per
  // element type (Spin<D> is double in 2D and Vec<3> in 3D), so that reordering allocates
  // nothing.
  std::tuple<std::vector<Vec<D>>, std::vector<double>, std::vector<std::uint32_t>> reorder_scratch_;

  double time_ = 0.0;
  long steps_ = 0;
  EnergyAccount account_;
  double shell_torque_ = 0.0;
  double last_step_dissipation_ = 0.0;
};

extern template class World<2>;
extern template class World<3>;

/// Velocity and spin of the particle at index `i` at the time of the positions (what outputs
/// write): the leapfrog's half-step values moved on by half a step of the last step's
/// acceleration, exact in free flight. Before the first step the force is zero, and the values
/// are those given.
template <int D>
std::pair<Vec<D>, Spin<D>> motion_at_positions(const World<D>& world, std::size_t i) {
  const ParticleStore<D>& p = world.particles();
  const double half = 0.5 * world.settings().time_step;
  return {p.velocity[i] + (half * p.inverse_mass[i]) * p.force[i],
          p.angular_velocity[i] + (half * p.inverse_inertia[i]) * p.torque[i]};
}

}  // namespace millsim
