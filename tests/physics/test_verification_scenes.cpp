// The verification scenes of examples/verification/ (docs/verification.md), run end to end by
// the millsim program as a user would, their final.csv and trajectory.csv checked against the
// analytic answers of the linear spring–dashpot model: the Chung & Ooi (2011) impact benchmarks
// (normal impacts of two spheres and of a sphere on a wall, a restitution sweep, oblique impacts
// from 5° to 85°, impacts with spin) and the bouncing, free-fall and sliding-to-rolling cases.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "millsim/core/constants.hpp"
#include "millsim/particles/material.hpp"
#include "physics/impact_answers.hpp"
#include "support/temporary_directory.hpp"

namespace {

namespace fs = std::filesystem;
using millsim::ContactMaterial;
using millsim::pi;
using millsim::impact_answers::no_tension_impact;
using millsim::impact_answers::record;

// The parameters the scenes were written with (scripts/generate-verification-scenes.py).
constexpr double diameter = 0.02;
constexpr double radius = diameter / 2.0;
constexpr double density = 4000.0;
const double mass = density * pi * diameter * diameter * diameter / 6.0;
constexpr double k_n = 1.0e6;
constexpr double g = 9.81;

/// A CSV file of numbers with a header row: column by name, row by index.
struct Table {
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;

  std::size_t column(const std::string& name) const {
    for (std::size_t c = 0; c < names.size(); ++c) {
      if (names[c] == name) return c;
    }
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
  double at(std::size_t row, const std::string& name) const { return rows.at(row)[column(name)]; }
};

Table read_csv(const fs::path& path) {
  Table table;
  std::ifstream file(path);
  EXPECT_TRUE(file.good()) << "cannot read " << path;
  std::string line;
  if (std::getline(file, line)) {
    std::stringstream header(line);
    for (std::string name; std::getline(header, name, ',');) table.names.push_back(name);
  }
  while (std::getline(file, line)) {
    std::vector<double> row;
    std::stringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
    table.rows.push_back(row);
  }
  return table;
}

class VerificationScene : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = millsim::testing::fresh_directory("verify");
    ASSERT_FALSE(root_.empty());
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(root_, ignored);
  }

  /// Runs `millsim run examples/verification/NAME.toml EXTRA` and returns its output directory.
  fs::path run(const std::string& name, const std::string& extra = {}) {
    fs::path out = root_ / name;
    const std::string command = std::string("\"") + MILLSIM_BINARY + "\" run -q \"" +
                                MILLSIM_SOURCE_DIR + "/examples/verification/" + name +
                                ".toml\" --out \"" + out.string() + "\" " + extra +
                                " >/dev/null 2>\"" + (root_ / "stderr").string() + "\"";
    const int status = std::system(command.c_str());
    EXPECT_TRUE(status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0)
        << command << "\n"
        << std::ifstream(root_ / "stderr").rdbuf();
    return out;
  }

  fs::path root_;
};

/// The restitution of a no-tension impact with the wall material (docs/model.md).
double effective_restitution(double e, double effective_mass) {
  return no_tension_impact(ContactMaterial{k_n, 2.0 * k_n / 3.0, e, 0.1}, effective_mass)
      .restitution;
}

TEST_F(VerificationScene, TwoIdenticalSpheresReboundWithTheRestitutionOfTheLinearModel) {
  const Table end = read_csv(run("normal-impact-two-spheres") / "final.csv");
  ASSERT_EQ(end.rows.size(), 2u);
  const double e_eff = effective_restitution(0.5, mass / 2.0);
  const double v0 = 0.2;
  record("restitution_expected", e_eff);
  record("restitution_measured", -end.at(0, "vx") / v0);
  EXPECT_NEAR(-end.at(0, "vx") / v0, e_eff, 0.01 * e_eff);
  EXPECT_NEAR(end.at(1, "vx") / v0, e_eff, 0.01 * e_eff);
  EXPECT_NEAR(end.at(0, "vx") + end.at(1, "vx"), 0.0, 1e-12) << "momentum";
  for (const char* spin : {"wx", "wy", "wz"}) EXPECT_EQ(end.at(0, spin), 0.0);
}

TEST_F(VerificationScene, RestitutionSweepOfASphereOnAWall) {
  for (const double e : {0.2, 0.5, 0.8, 0.95, 1.0}) {
    const Table end = read_csv(
        run("normal-impact-wall", "--set materials.ball_wall.restitution=" + std::to_string(e)) /
        "final.csv");
    const double expected = effective_restitution(e, mass);
    const double measured = end.at(0, "vz") / 0.2;
    record("restitution_" + std::to_string(e), measured);
    EXPECT_NEAR(measured, expected, 0.01 * expected) << "e = " << e;
    EXPECT_EQ(end.at(0, "vx"), 0.0);
  }
}

/// Each particle of an oblique-impact scene: incidence angle (rad), and its rebound.
struct Rebound {
  double angle, normal_restitution, tangential_restitution, spin, rebound_angle;
};

std::vector<Rebound> oblique_rebounds(const Table& end, double speed) {
  std::vector<Rebound> out;
  for (std::size_t k = 0; k < end.rows.size(); ++k) {
    const double angle = (5.0 * static_cast<double>(k + 1)) * pi / 180.0;
    const double vn = speed * std::cos(angle);
    const double vt = speed * std::sin(angle);
    out.push_back({angle, end.at(k, "vz") / vn, end.at(k, "vx") / vt, end.at(k, "wy"),
                   std::atan2(end.at(k, "vx"), end.at(k, "vz"))});
  }
  return out;
}

// Chung & Ooi test 4, e = 0.5, μ = 0.1. In gross sliding (tan θ ≥ 3.5 μ (1 + e_eff): the
// contact point slides throughout) the friction impulse is μ times the normal one:
//   v_t'/v_t = 1 − μ (1 + e_eff) / tan θ,  ω' = 2.5 μ (1 + e_eff) v cos θ / R,
//   tan(rebound angle) = (tan θ − μ (1 + e_eff)) / e_eff.
// At smaller angles the contact sticks for part of the impact and the friction impulse is
// less: v_t'/v_t is above the sliding value and the spin below it (Coulomb's bound).
TEST_F(VerificationScene, ObliqueImpactsFollowCoulombInGrossSlidingAndItsBoundBelow) {
  const double mu = 0.1;
  const double speed = 3.9;
  const double e_eff = effective_restitution(0.5, mass);
  const double impulse = mu * (1.0 + e_eff);  // friction impulse per m v_n in sliding
  const auto rebounds =
      oblique_rebounds(read_csv(run("oblique-impact-angles") / "final.csv"), speed);
  ASSERT_EQ(rebounds.size(), 17u);
  int sliding = 0;
  for (const Rebound& r : rebounds) {
    const std::string at = "at " + std::to_string(std::lround(r.angle * 180.0 / pi)) + " deg";
    EXPECT_NEAR(r.normal_restitution, e_eff, 0.01 * e_eff) << at;
    const double et = 1.0 - impulse / std::tan(r.angle);
    const double spin = 2.5 * impulse * speed * std::cos(r.angle) / radius;
    if (std::tan(r.angle) >= 3.5 * impulse) {
      ++sliding;
      // On the friction's part, 1 − e_t (e_t itself is mostly the 1 at these angles).
      EXPECT_NEAR(1.0 - r.tangential_restitution, 1.0 - et, 0.01 * (1.0 - et)) << at;
      EXPECT_NEAR(r.spin, spin, 0.02 * spin) << at;
      const double rebound = std::atan((std::tan(r.angle) - impulse) / e_eff);
      EXPECT_NEAR(r.rebound_angle, rebound, 0.01 * rebound) << at;
    } else {
      EXPECT_GE(r.tangential_restitution, et - 1e-3) << at << ": more than μ times the impulse";
      EXPECT_LE(r.spin, spin * (1.0 + 1e-3)) << at;
      EXPECT_GT(r.spin, 0.0) << at;
    }
  }
  EXPECT_EQ(sliding, 12) << "30° to 85° slide throughout";
}

// e = 1, k_s = 2 k_n / 7: the sphere's tangential oscillation sqrt(k_s / (2m/7)) has the
// normal frequency sqrt(k_n / m), and F_t / F_n = (2/7) tan θ throughout a sticking impact.
// So for tan θ ≤ 3.5 μ the contact sticks throughout and leaves after half a tangential period
// with its contact-point velocity reversed: the tangential impulse is 2 (2m/7) v_t, so
//   v_t'/v_t = 1 − 4/7 = 3/7,  ω' = (5/2)(4/7) v_t / R = 10 v sin θ / (7 R).
// For tan θ ≥ 3.5 μ (1 + e) = 7 μ it slides throughout (the Coulomb answers with e = 1).
TEST_F(VerificationScene, ElasticObliqueImpactsStickOrSlideAsTheClosedFormSays) {
  const double mu = 0.1;
  const double speed = 3.9;
  const auto rebounds =
      oblique_rebounds(read_csv(run("oblique-impact-angles-elastic") / "final.csv"), speed);
  ASSERT_EQ(rebounds.size(), 17u);
  int sticking = 0;
  int sliding = 0;
  for (const Rebound& r : rebounds) {
    const std::string at = "at " + std::to_string(std::lround(r.angle * 180.0 / pi)) + " deg";
    EXPECT_NEAR(r.normal_restitution, 1.0, 0.005) << at;
    const double t = std::tan(r.angle);
    if (t <= 3.5 * mu) {
      ++sticking;
      EXPECT_NEAR(r.tangential_restitution, 3.0 / 7.0, 0.01 * 3.0 / 7.0) << at;
      const double spin = 10.0 * speed * std::sin(r.angle) / (7.0 * radius);
      EXPECT_NEAR(r.spin, spin, 0.01 * spin) << at;
    } else if (t >= 7.0 * mu) {
      ++sliding;
      const double et = 1.0 - 2.0 * mu / t;
      // On the friction's part, 1 − e_t, as in the inelastic test above (1 % of e_t itself
      // would allow 56 % of the friction's part at 85°).
      EXPECT_NEAR(1.0 - r.tangential_restitution, 1.0 - et, 0.01 * (1.0 - et)) << at;
      const double spin = 5.0 * mu * speed * std::cos(r.angle) / radius;
      EXPECT_NEAR(r.spin, spin, 0.02 * spin) << at;
    } else {
      // Partly slipping: between the two closed forms.
      EXPECT_GE(r.tangential_restitution, 1.0 - 2.0 * mu / t - 1e-3) << at;
      EXPECT_GE(r.tangential_restitution, 3.0 / 7.0 - 1e-3) << at;
    }
  }
  EXPECT_EQ(sticking, 3) << "5°, 10°, 15° stick (tan θ ≤ 0.35)";
  EXPECT_EQ(sliding, 11) << "35° to 85° slide (tan θ ≥ 0.7)";
}

// Chung & Ooi test 6: v_n = 0.2 m/s, spin ω0 about y, no tangential velocity. The contact point
// slips at R ω0 along −x; in gross sliding (R ω0 ≥ 3.5 μ (1 + e_eff) v_n) friction gives
//   v_x' = μ (1 + e_eff) v_n,  ω' = ω0 − 2.5 μ (1 + e_eff) v_n / R.
TEST_F(VerificationScene, SpinningSpheresLeaveAsCoulombSays) {
  const double mu = 0.1;
  const double vn = 0.2;
  const double spins[] = {0.0, 2.0, 5.0, 10.0, 20.0, 40.0, 80.0, 160.0};
  const double e_eff = effective_restitution(0.5, mass);
  const double impulse = mu * (1.0 + e_eff) * vn;  // per unit mass
  const Table end = read_csv(run("impact-with-spin") / "final.csv");
  ASSERT_EQ(end.rows.size(), 8u);
  int sliding = 0;
  for (std::size_t k = 0; k < 8; ++k) {
    const double w0 = spins[k];
    const std::string at = "at spin " + std::to_string(w0);
    EXPECT_NEAR(end.at(k, "vz") / vn, e_eff, 0.01 * e_eff) << at;
    if (w0 == 0.0) {
      EXPECT_EQ(end.at(k, "vx"), 0.0);
      EXPECT_EQ(end.at(k, "wy"), 0.0);
    } else if (radius * w0 >= 3.5 * impulse) {
      ++sliding;
      EXPECT_NEAR(end.at(k, "vx"), impulse, 0.01 * impulse) << at;
      const double loss = 2.5 * impulse / radius;
      EXPECT_NEAR(w0 - end.at(k, "wy"), loss, 0.01 * loss) << at;
    } else {
      EXPECT_LE(end.at(k, "vx"), impulse * (1.0 + 1e-3)) << at;
      EXPECT_GT(end.at(k, "vx"), 0.0) << at;
    }
  }
  EXPECT_EQ(sliding, 4) << "20 to 160 rad/s slide throughout";
}

/// The highest centre height of each flight after the first bounce, from trajectory rows.
std::vector<double> apexes(const Table& trajectory, const std::string& height) {
  std::vector<double> out;
  bool airborne = true;
  bool bounced = false;
  double highest = 0.0;
  for (std::size_t row = 0; row < trajectory.rows.size(); ++row) {
    const double h = trajectory.at(row, height);
    if (airborne && h < radius) {
      if (bounced) out.push_back(highest);
      airborne = false;
    } else if (!airborne && h >= radius) {
      airborne = true;
      bounced = true;
      highest = h;
    }
    if (airborne) highest = std::max(highest, h);
  }
  return out;
}

// Dropped from h0 = 0.1 m: the k-th apex is at (h0 − r) e_eff^(2k) + r. (Gravity during the
// 0.4 ms contacts shifts this by far less than the tolerance.)
TEST_F(VerificationScene, BouncingBallApexesFallByTheRestitutionSquared) {
  for (const int d : {3, 2}) {
    const std::string name = "bouncing-" + std::to_string(d) + "d";
    const auto tops = apexes(read_csv(run(name) / "trajectory.csv"), d == 3 ? "z" : "y");
    ASSERT_GE(tops.size(), 5u) << name;
    const double e_eff = effective_restitution(0.8, mass);
    for (std::size_t k = 1; k <= 5; ++k) {
      const double expected =
          (0.1 - radius) * std::pow(e_eff, 2.0 * static_cast<double>(k)) + radius;
      EXPECT_NEAR(tops[k - 1], expected, 0.01 * (expected - radius)) << name << " bounce " << k;
    }
  }
}

// No walls: x(t) = x0 + v0 t + g t²/2, which the leapfrog reproduces to round-off.
TEST_F(VerificationScene, FreeFallIsExact) {
  for (const int d : {3, 2}) {
    const std::string name = "free-fall-" + std::to_string(d) + "d";
    const Table path = read_csv(run(name) / "trajectory.csv");
    ASSERT_EQ(path.rows.size(), 51u) << name;
    const std::string up = d == 3 ? "z" : "y";
    for (std::size_t row = 0; row < path.rows.size(); ++row) {
      const double t = path.at(row, "time_s");
      EXPECT_NEAR(path.at(row, "x"), 2.0 * t, 1e-9) << name << " t = " << t;
      EXPECT_NEAR(path.at(row, up), 2.0 * t - 0.5 * g * t * t, 1e-9) << name << " t = " << t;
      EXPECT_NEAR(path.at(row, "v" + up), 2.0 - g * t, 1e-9) << name << " t = " << t;
    }
  }
}

// Set down sliding at v0 = 2 m/s without spin (μ = 0.3): friction μ m g slows the centre and
// spins the body up until the contact point stops slipping, at t = 2 v0 / (7 μ g) with speed
// 5 v0 / 7 for a sphere, t = v0 / (3 μ g) and 2 v0 / 3 for a disc.
TEST_F(VerificationScene, SlidingBodiesStartRollingWhenAndAsFastAsTheorySays) {
  const double v0 = 2.0;
  const double mu = 0.3;
  for (const int d : {3, 2}) {
    const std::string name = "sliding-to-rolling-" + std::to_string(d) + "d";
    const Table path = read_csv(run(name) / "trajectory.csv");
    const double roll_time = d == 3 ? 2.0 * v0 / (7.0 * mu * g) : v0 / (3.0 * mu * g);
    const double roll_speed = d == 3 ? 5.0 * v0 / 7.0 : 2.0 * v0 / 3.0;
    double rolling_from = -1.0;
    for (std::size_t row = 0; row < path.rows.size(); ++row) {
      // Contact-point velocity along x: v_x − R ω_y (sphere), v_x + R ω (disc).
      const double slip = d == 3 ? path.at(row, "vx") - radius * path.at(row, "wy")
                                 : path.at(row, "vx") + radius * path.at(row, "omega");
      if (std::abs(slip) < 1e-3 * v0) {
        rolling_from = path.at(row, "time_s");
        break;
      }
    }
    record(name + "_rolling_from", rolling_from);
    // Rows come every 1 ms: the first rolling row is within 1 ms after the start of rolling.
    EXPECT_NEAR(rolling_from, roll_time, 0.01 * roll_time + 1e-3) << name;
    EXPECT_NEAR(path.rows.empty() ? 0.0 : path.at(path.rows.size() - 1, "vx"), roll_speed,
                0.01 * roll_speed)
        << name;
  }
}

}  // namespace
