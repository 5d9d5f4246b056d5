// The contact law on Lanes (several contacts at once, core/lanes.hpp) gives each lane the very
// bits the law on one double gives that contact: forces, dissipation and the history it leaves.
// The pair stage relies on it to be the same whether a contact is worked out in lanes or alone
// (the threads' shared pairs are). Contacts are drawn at random across every outcome of the law:
// sticking, slipping, breaking under tension, new (no spring yet), a spring along the normal.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <random>

#include "millsim/contact/linear_spring_dashpot.hpp"
#include "millsim/core/lanes.hpp"

namespace millsim {
namespace {

constexpr auto lanes = static_cast<std::size_t>(lane_count);

/// Whether two doubles have the same bits (+0 and −0 differ, as they may not for ==).
bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

template <int D>
Vec<D> random_vector(std::mt19937_64& random, double scale) {
  std::uniform_real_distribution<double> uniform(-scale, scale);
  Vec<D> v;
  for (int a = 0; a < D; ++a) v[a] = uniform(random);
  return v;
}

template <int D>
struct Drawn {
  ContactInput<D> input;
  ContactHistory<D> history;
  ContactDamping damping;
};

/// One contact of kind `kind % 5`: 0 sticking (small slip), 1 slipping (fast slip), 2 pulled
/// apart (the dashpot beats the spring), 3 touching for the first time, 4 a stored spring
/// along the new normal (it cannot be turned into the tangent plane; 3D only, in 2D another
/// stored spring).
template <int D>
Drawn<D> draw_contact(std::mt19937_64& random, int kind, const LinearSpringDashpot& law) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Drawn<D> c;
  Vec<D> n = random_vector<D>(random, 1.0);
  n *= 1.0 / norm(n);
  c.input.normal = n;
  c.input.overlap = 1e-4 * (0.1 + unit(random));
  const double slip_speed = kind % 5 == 1 ? 2.0 : 1e-4;
  c.input.velocity = random_vector<D>(random, slip_speed);
  c.input.step_velocity = random_vector<D>(random, slip_speed);
  // Rotation's part of the slip lies in the tangent plane, as n × (r_A ω_A + r_B ω_B) does (in
  // 2D, a length along the tangent; so is the 2D spring).
  const auto tangential = [&](const Vec<D>& v) -> SpinOf<D> {
    if constexpr (D == 2) {
      return v[0];
    } else {
      return v - dot(v, n) * n;
    }
  };
  c.input.spin_velocity = tangential(random_vector<D>(random, slip_speed));
  c.input.step_spin_velocity = tangential(random_vector<D>(random, slip_speed));
  c.history.normal_spring_origin = 0.5 * c.input.overlap * unit(random);
  if (kind % 5 == 2) {
    // Separating fast from a small overlap: the dashpot pulls harder than the spring pushes.
    c.input.velocity += 5.0 * n;
    c.history.normal_spring_origin = 0.99 * c.input.overlap;
  }
  if (kind % 5 != 3) {
    c.history.tangential_spring = tangential(random_vector<D>(random, 10.0));
  }
  if constexpr (D == 3) {
    if (kind % 5 == 4) c.history.tangential_spring = 3.0 * n;
  }
  c.history.dissipated = unit(random);
  c.damping = law.damping(0.5 + unit(random));
  return c;
}

template <int D>
void expect_lanes_match_doubles(bool allow_tension) {
  const ContactMaterial material{1e6, 7e5, 0.5, 0.4};
  const LinearSpringDashpot law(material, allow_tension);
  std::mt19937_64 random(42);
  const double dt = 1e-5;
  int broke = 0, slipped = 0, stuck = 0;
  for (int round = 0; round < 200; ++round) {
    std::array<Drawn<D>, lanes> contact;
    for (std::size_t l = 0; l < lanes; ++l) {
      contact[l] = draw_contact<D>(random, round + static_cast<int>(l), law);
    }
    // The same contacts in lanes.
    ContactInput<D, Lanes> in;
    ContactHistory<D, Lanes> history;
    ContactDampingOf<Lanes> damping;
    for (std::size_t l = 0; l < lanes; ++l) {
      const ContactInput<D>& one = contact[l].input;
      for (int a = 0; a < D; ++a) {
        in.normal[a][l] = one.normal[a];
        in.velocity[a][l] = one.velocity[a];
        in.step_velocity[a][l] = one.step_velocity[a];
        if constexpr (D == 3) {
          in.spin_velocity[a][l] = one.spin_velocity[a];
          in.step_spin_velocity[a][l] = one.step_spin_velocity[a];
          history.tangential_spring[a][l] = contact[l].history.tangential_spring[a];
        }
      }
      if constexpr (D == 2) {
        in.spin_velocity[l] = one.spin_velocity;
        in.step_spin_velocity[l] = one.step_spin_velocity;
        history.tangential_spring[l] = contact[l].history.tangential_spring;
      }
      in.overlap[l] = one.overlap;
      history.normal_spring_origin[l] = contact[l].history.normal_spring_origin;
      history.dissipated[l] = contact[l].history.dissipated;
      damping.normal[l] = contact[l].damping.normal;
      damping.tangential[l] = contact[l].damping.tangential;
    }
    const ContactOutput<D, Lanes> out = law.evaluate(in, damping, history, dt);
    for (std::size_t l = 0; l < lanes; ++l) {
      ContactHistory<D> alone = contact[l].history;
      double spring_before = 0.0;
      if constexpr (D == 2) {
        spring_before = std::abs(alone.tangential_spring);
      } else {
        spring_before = norm(alone.tangential_spring);
      }
      const ContactOutput<D> expected =
          law.evaluate(contact[l].input, contact[l].damping, alone, dt);
      SCOPED_TRACE(testing::Message() << "round " << round << ", lane " << l);
      for (int a = 0; a < D; ++a) {
        EXPECT_TRUE(same_bits(out.force[a][l], expected.force[a]));
        EXPECT_TRUE(same_bits(out.tangential_force[a][l], expected.tangential_force[a]));
        if constexpr (D == 3) {
          EXPECT_TRUE(same_bits(history.tangential_spring[a][l], alone.tangential_spring[a]));
        }
      }
      if constexpr (D == 2) {
        EXPECT_TRUE(same_bits(history.tangential_spring[l], alone.tangential_spring));
      }
      EXPECT_TRUE(same_bits(out.dissipated[l], expected.dissipated));
      EXPECT_TRUE(same_bits(history.normal_spring_origin[l], alone.normal_spring_origin));
      EXPECT_TRUE(same_bits(history.dissipated[l], alone.dissipated));
      // Which outcome the contact had, so that the test can say it met them all.
      if (norm(expected.force) == 0.0) {
        ++broke;
      } else if (std::abs(norm(expected.tangential_force) -
                          material.friction *
                              std::abs(dot(expected.force, contact[l].input.normal))) <
                 1e-9 * norm(expected.force)) {
        ++slipped;
      } else if (spring_before > 0.0) {
        ++stuck;
      }
    }
  }
  testing::Test::RecordProperty(fmt::format("broke_{}d", D), broke);
  testing::Test::RecordProperty(fmt::format("slipped_{}d", D), slipped);
  testing::Test::RecordProperty(fmt::format("stuck_{}d", D), stuck);
  if (!allow_tension) {
    EXPECT_GT(broke, 0);
  }
  EXPECT_GT(slipped, 0);
  EXPECT_GT(stuck, 0);
}

TEST(ContactLanes, EachLaneGetsTheBitsOfTheLawOnOneContact2D) {
  expect_lanes_match_doubles<2>(false);
}

TEST(ContactLanes, EachLaneGetsTheBitsOfTheLawOnOneContact3D) {
  expect_lanes_match_doubles<3>(false);
}

TEST(ContactLanes, TheSameWithTensionAllowed) {
  expect_lanes_match_doubles<2>(true);
  expect_lanes_match_doubles<3>(true);
}

TEST(ContactLanes, HelpersWorkLaneByLane) {
  Lanes x{};
  for (std::size_t l = 0; l < lanes; ++l) x[l] = static_cast<double>(l) - 1.5;
  const Lanes roots = lane_sqrt(lane_abs(x));
  const Lanes chosen = select(x > 0.0, x, splat<Lanes>(7.0));
  const Lanes gathered = gather_lanes([](std::size_t l) { return 10.0 * static_cast<double>(l); });
  for (std::size_t l = 0; l < lanes; ++l) {
    EXPECT_EQ(roots[l], std::sqrt(std::abs(static_cast<double>(l) - 1.5)));
    EXPECT_EQ(chosen[l], x[l] > 0.0 ? x[l] : 7.0);
    EXPECT_EQ(gathered[l], 10.0 * static_cast<double>(l));
  }
  // any: whether the mask holds in some lane, for each lane alone and for none.
  EXPECT_FALSE(any(x > 100.0));
  for (std::size_t l = 0; l < lanes; ++l) {
    Lanes one{};
    one[l] = 1.0;
    EXPECT_TRUE(any(one > 0.0)) << "lane " << l;
  }
  EXPECT_TRUE(any(true));
  EXPECT_FALSE(any(false));
  // Spins: a number per lane in 2D, a vector per lane in 3D.
  const Lanes spin_2d = gather_spin_lanes<2>([](std::size_t l) { return static_cast<double>(l); });
  const Vec<3, Lanes> spin_3d = gather_spin_lanes<3>([](std::size_t l) {
    const auto a = static_cast<double>(l);
    return Vec3{{a, 2.0 * a, 3.0 * a}};
  });
  for (std::size_t l = 0; l < lanes; ++l) {
    const auto a = static_cast<double>(l);
    EXPECT_EQ(spin_2d[l], a);
    for (int d = 0; d < 3; ++d) EXPECT_EQ(spin_3d[d][l], (d + 1) * a);
  }
}

TEST(ContactLanes, TwoDimensionalVectorsMoveBetweenLanes) {
  // lanes_of: lane l of component d is f(l)[d]; pairs_of gives each lane's vector back.
  const auto vector_of = [](std::size_t l) {
    const auto a = static_cast<double>(l);
    return Vec2{{1.0 + a, -10.0 * a}};
  };
  const Vec<2, Lanes> lanes_2d = lanes_of(vector_of);
  const std::array<Pair2, lanes> back = pairs_of(lanes_2d);
  for (std::size_t l = 0; l < lanes; ++l) {
    for (int d = 0; d < 2; ++d) {
      EXPECT_EQ(lanes_2d[d][l], vector_of(l)[d]) << "lane " << l << ", component " << d;
      EXPECT_EQ(back[l][d], vector_of(l)[d]) << "lane " << l << ", component " << d;
    }
  }
  // Differences and sums of two components at once: the bits of a Vec2's.
  Vec2 sum{{0.1, -0.3}};
  Vec2 expected = sum;
  add_to(sum, pair_of(Vec2{{0.2, 0.7}}));
  expected += Vec2{{0.2, 0.7}};
  EXPECT_EQ(sum[0], expected[0]);
  EXPECT_EQ(sum[1], expected[1]);
  subtract_from(sum, pair_of(Vec2{{1.0 / 3.0, 2.0 / 3.0}}));
  expected -= Vec2{{1.0 / 3.0, 2.0 / 3.0}};
  EXPECT_EQ(sum[0], expected[0]);
  EXPECT_EQ(sum[1], expected[1]);
}

}  // namespace
}  // namespace millsim
