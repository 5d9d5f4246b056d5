// `millsim sweep` on a small 2D mill (tests/data/sweep-small-mill.toml): the power-versus-speed
// curve a mill engineer expects, rising to a peak below critical speed and falling as the
// charge centrifuges; and the sweep's bookkeeping (thread independence, failed points, refused
// input). Each test runs the built program in a fresh temporary directory.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "support/program_test.hpp"

namespace {

using millsim::testing::Outcome;
using millsim::testing::ProgramTest;
using millsim::testing::quoted;
using millsim::testing::read_all;

namespace fs = std::filesystem;

const std::string small_mill =
    std::string(MILLSIM_SOURCE_DIR) + "/tests/data/sweep-small-mill.toml";

/// A run of a second of simulated time or less, for the bookkeeping tests (with the speed
/// unless the sweep varies it: a key may be given once).
constexpr const char* tiny_run =
    " --set simulation.revolutions=1 --set simulation.measure_revolutions=1"
    " --set simulation.settle_time=0.01";
constexpr const char* tiny_speed = " --set mill.speed=1.5";

/// The fields of one CSV line (RFC 4180 quoting).
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> fields(1);
  bool in_quotes = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (in_quotes && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      fields.back() += '"';
      ++i;
    } else if (c == '"') {
      in_quotes = !in_quotes;
    } else if (c == ',' && !in_quotes) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

/// sweep.csv as one map from column name to cell per point.
std::vector<std::map<std::string, std::string>> read_csv(const fs::path& path) {
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);
  const std::vector<std::string> header = csv_fields(line);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(file, line)) {
    const std::vector<std::string> cells = csv_fields(line);
    EXPECT_EQ(cells.size(), header.size()) << line;
    auto& row = rows.emplace_back();
    for (std::size_t k = 0; k < std::min(cells.size(), header.size()); ++k) {
      row[header[k]] = cells[k];
    }
  }
  return rows;
}

class SweepPowerCurve : public ProgramTest {};

TEST_F(SweepPowerCurve, PowerRisesToAPeakBelowCriticalAndFallsAsTheChargeCentrifuges) {
  const Outcome o =
      millsim("sweep " + quoted(small_mill) + " --vary mill.speed=0.5:2.0:0.25 -q --out speed");
  ASSERT_EQ(o.status, 0) << o.err;
  const auto rows = read_csv(work_ / "speed" / "sweep.csv");
  ASSERT_EQ(rows.size(), 7u);
  std::vector<double> speed;
  std::vector<double> power;
  for (const auto& row : rows) {
    ASSERT_EQ(row.at("status"), "ok");
    speed.push_back(std::stod(row.at("mill.speed")));
    power.push_back(std::stod(row.at("power_kw")));
  }
  std::string curve;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    curve += std::to_string(speed[i]) + " " + std::to_string(power[i]) + " kW\n";
  }
  const auto peak = static_cast<std::size_t>(
      std::distance(power.begin(), std::max_element(power.begin(), power.end())));
  EXPECT_GT(peak, 0u) << curve;
  EXPECT_LT(peak, rows.size() - 1) << curve;
  EXPECT_LT(speed[peak], 1.0) << curve;
  EXPECT_LT(power.front(), power[peak]) << curve;
  EXPECT_GE(speed.back(), 1.3);
  EXPECT_LT(power.back(), 0.3 * power[peak]) << curve;
  // The centrifuged charge at twice critical speed has no toe: its cell is empty, in the same
  // column as the tumbling charges' toes (read_csv checks every row has every column).
  EXPECT_FALSE(rows.front().at("charge_toe_angle_rad").empty());
  EXPECT_EQ(rows.back().at("charge_toe_angle_rad"), "");
}

TEST_F(SweepPowerCurve, ResultsDoNotDependOnTheThreadsAndEveryPointHasItsDirectory) {
  const std::string sweep = "sweep " + quoted(small_mill) +
                            " --vary mill.speed=1.5,2 --vary charge.filling=0.2,0.3 -q" + tiny_run;
  const Outcome serial = millsim(sweep + " -j 1 --out one");
  const Outcome parallel = millsim(sweep + " -j 2 --out two");
  // Fewer points than threads: the points together, the threads shared among them (the
  // opening line says how; -q leaves it out). This mill is too small for its step to use a
  // second thread: what is checked here is the jobs' pool and bookkeeping; run_shared's giving
  // each job its share of threads is unit-tested (test_sweep.cpp), and the same bits at any
  // thread count in test_determinism.cpp.
  std::string shared = sweep + " -j 8 --out eight";
  shared.erase(shared.find(" -q "), 3);
  const Outcome nested = millsim(shared);
  ASSERT_EQ(serial.status, 0) << serial.err;
  ASSERT_EQ(parallel.status, 0) << parallel.err;
  ASSERT_EQ(nested.status, 0) << nested.err;
  EXPECT_NE(nested.out.find("(4 at a time, 2 threads each)"), std::string::npos) << nested.out;
  // A line per point as it ends: its number in sweep.csv, and how many are done (it once read
  // "point 3 of 4 done" for the last).
  EXPECT_NE(nested.err.find(" done, 4 of 4 ("), std::string::npos) << nested.err;
  const auto one = read_csv(work_ / "one" / "sweep.csv");
  ASSERT_EQ(one.size(), 4u);
  for (const char* other : {"two", "eight"}) {
    const auto rows = read_csv(work_ / other / "sweep.csv");
    ASSERT_EQ(rows.size(), 4u) << other;
    for (std::size_t i = 0; i < one.size(); ++i) {
      for (const auto& [column, cell] : one[i]) {
        if (column == "wall_seconds" || column == "settle_wall_seconds" ||
            column == "particle_steps_per_second") {
          continue;  // timings
        }
        EXPECT_EQ(cell, rows[i].at(column)) << other << ", point " << i << ", " << column;
      }
    }
  }
  EXPECT_EQ(one[1].at("mill.speed"), "1.5");
  EXPECT_EQ(one[1].at("charge.filling"), "0.3");
  EXPECT_TRUE(fs::exists(work_ / "two" / "001_mill.speed=1.5_charge.filling=0.3" / "summary.json"));
  EXPECT_FALSE(fs::exists(work_ / "two" / "sweep.csv.partial"));
}

TEST_F(SweepPowerCurve, AFailedPointIsReportedAndTheOthersStillRun) {
  // Every point's config and charge are checked before any runs (a filling of 0.95, whose discs
  // do not fit, refuses the whole sweep: tests/unit/test_cli.cpp). What can still fail is the
  // run itself: here point 1's output directory, taken by a file.
  fs::create_directories(work_ / "f");
  std::ofstream(work_ / "f" / "001_charge.filling=0.25") << "a file, not a directory\n";
  const Outcome o =
      millsim("sweep " + quoted(small_mill) + " --vary charge.filling=0.2,0.25,0.3 -q --out f" +
              tiny_run + tiny_speed);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_NE(o.err.find("1 of 3 points failed"), std::string::npos) << o.err;
  const auto rows = read_csv(work_ / "f" / "sweep.csv");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].at("status"), "ok");
  EXPECT_TRUE(rows[1].at("status").starts_with("failed: ")) << rows[1].at("status");
  EXPECT_EQ(rows[1].at("power_kw"), "");
  EXPECT_EQ(rows[2].at("status"), "ok");
  EXPECT_NE(o.out.find("failed: "), std::string::npos) << o.out;
}

TEST_F(SweepPowerCurve, ASecondSweepIntoTheSameDirectoryReplacesTheFirst) {
  const Outcome first =
      millsim("sweep " + quoted(small_mill) + " --vary charge.filling=0.2,0.25,0.3 -q --out r" +
              tiny_run + tiny_speed);
  ASSERT_EQ(first.status, 0) << first.err;
  // A file of the user's in a point directory of the first sweep: kept, with its directory.
  std::ofstream(work_ / "r" / "002_charge.filling=0.3" / "notes.txt") << "mine\n";
  const Outcome second = millsim("sweep " + quoted(small_mill) +
                                 " --vary charge.filling=0.25 --out r" + tiny_run + tiny_speed);
  ASSERT_EQ(second.status, 0) << second.err;
  EXPECT_NE(second.err.find("millsim: removed the results of 3 points of the earlier sweep in r/"),
            std::string::npos)
      << second.err;
  std::vector<std::string> names;
  for (const auto& entry : fs::recursive_directory_iterator(work_ / "r")) {
    names.push_back(fs::relative(entry.path(), work_ / "r").string());
  }
  std::sort(names.begin(), names.end());
  ASSERT_GE(names.size(), 3U);
  // Each of the first sweep's points has another name in the second (its index and value).
  EXPECT_TRUE(std::find(names.begin(), names.end(), "000_charge.filling=0.2") == names.end());
  EXPECT_TRUE(std::find(names.begin(), names.end(), "001_charge.filling=0.25") == names.end());
  EXPECT_TRUE(std::find(names.begin(), names.end(), "002_charge.filling=0.3/notes.txt") !=
              names.end());
  EXPECT_TRUE(std::find(names.begin(), names.end(), "002_charge.filling=0.3/summary.json") ==
              names.end());
  EXPECT_TRUE(std::find(names.begin(), names.end(), "000_charge.filling=0.25/summary.json") !=
              names.end());
  // The table names each point's directory.
  const auto rows = read_csv(work_ / "r" / "sweep.csv");
  ASSERT_EQ(rows.size(), 1U);
  EXPECT_EQ(rows[0].at("directory"), "000_charge.filling=0.25");
  EXPECT_EQ(rows[0].at("status"), "ok");
}

TEST_F(SweepPowerCurve, AnEarlierTableNamesNothingButItsOwnPointDirectories) {
  // A table edited by hand: rows naming a directory of the user's, a link out of --out, and a
  // point directory under a name its row's values do not give. None is touched.
  fs::create_directories(work_ / "u" / "analysis" / "snapshots");
  std::ofstream(work_ / "u" / "analysis" / "impacts.csv") << "mine\n";
  std::ofstream(work_ / "u" / "analysis" / "snapshots" / "figure.png") << "mine\n";
  fs::create_directories(work_ / "elsewhere");
  std::ofstream(work_ / "elsewhere" / "summary.json") << "mine\n";
  fs::create_directory_symlink(work_ / "elsewhere", work_ / "u" / "link");
  fs::create_directories(work_ / "u" / "001_mill.speed=0.6");
  std::ofstream(work_ / "u" / "001_mill.speed=0.6" / "summary.json") << "mine\n";
  std::ofstream(work_ / "u" / "sweep.csv") << "point,directory,mill.speed,status\n"
                                           << "0,analysis,0.5,ok\n"
                                           << "1,link,0.6,ok\n"
                                           << "2,001_mill.speed=0.6,0.6,ok\n";
  const Outcome o = millsim("sweep " + quoted(small_mill) +
                            " --vary charge.filling=0.25 -q --out u" + tiny_run + tiny_speed);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(read_all(work_ / "u" / "analysis" / "impacts.csv"), "mine\n");
  EXPECT_EQ(read_all(work_ / "u" / "analysis" / "snapshots" / "figure.png"), "mine\n");
  EXPECT_EQ(read_all(work_ / "elsewhere" / "summary.json"), "mine\n");
  EXPECT_EQ(read_all(work_ / "u" / "001_mill.speed=0.6" / "summary.json"), "mine\n");
  EXPECT_EQ(o.err.find("removed the results"), std::string::npos) << o.err;
}

TEST_F(SweepPowerCurve, ARefusalWhileClearingTheEarlierSweepClearsNothing) {
  const Outcome first =
      millsim("sweep " + quoted(small_mill) + " --vary charge.filling=0.2,0.3 -q --out w" +
              tiny_run + tiny_speed);
  ASSERT_EQ(first.status, 0) << first.err;
  const std::string table = read_all(work_ / "w" / "sweep.csv");
  const std::string summary = read_all(work_ / "w" / "000_charge.filling=0.2" / "summary.json");
  // The second earlier point holds a directory of the user's under a result's name.
  fs::remove(work_ / "w" / "001_charge.filling=0.3" / "power.csv");
  fs::create_directories(work_ / "w" / "001_charge.filling=0.3" / "power.csv" / "mine");
  const Outcome second = millsim("sweep " + quoted(small_mill) +
                                 " --vary charge.filling=0.25 -q --out w" + tiny_run + tiny_speed);
  EXPECT_EQ(second.status, 2) << second.err;
  EXPECT_NE(second.err.find("a point of the earlier sweep: output.directory: "
                            "\"w/001_charge.filling=0.3\" holds a directory power.csv"),
            std::string::npos)
      << second.err;
  EXPECT_EQ(read_all(work_ / "w" / "sweep.csv"), table);
  EXPECT_EQ(read_all(work_ / "w" / "000_charge.filling=0.2" / "summary.json"), summary);
  EXPECT_FALSE(fs::exists(work_ / "w" / "000_charge.filling=0.25"));
  // A point's own directory that is a link is refused too, before anything is cleared.
  fs::remove_all(work_ / "w" / "001_charge.filling=0.3" / "power.csv");
  fs::create_directories(work_ / "elsewhere");
  fs::create_directory_symlink(work_ / "elsewhere", work_ / "w" / "000_charge.filling=0.25");
  const Outcome linked = millsim("sweep " + quoted(small_mill) +
                                 " --vary charge.filling=0.25 -q --out w" + tiny_run + tiny_speed);
  EXPECT_EQ(linked.status, 2) << linked.err;
  EXPECT_NE(linked.err.find("sweep point w/000_charge.filling=0.25 is a link"), std::string::npos)
      << linked.err;
  EXPECT_EQ(read_all(work_ / "w" / "000_charge.filling=0.2" / "summary.json"), summary);
}

TEST_F(SweepPowerCurve, AnEarlierTableWithoutVariedKeysNamesNothing) {
  // A table no sweep writes (a sweep varies a key): numbered folders of the user's stay.
  fs::create_directories(work_ / "x" / "000");
  std::ofstream(work_ / "x" / "000" / "summary.json") << "mine\n";
  std::ofstream(work_ / "x" / "sweep.csv") << "point,status\n0,ok\n";
  const Outcome o = millsim("sweep " + quoted(small_mill) +
                            " --vary charge.filling=0.25 -q --out x" + tiny_run + tiny_speed);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(read_all(work_ / "x" / "000" / "summary.json"), "mine\n");
}

TEST_F(SweepPowerCurve, AnEarlierTableWithoutItsDirectoriesStillNamesItsPoints) {
  // sweep.csv as sweeps wrote it before it had the directory column: the names come from the
  // index and the values.
  const Outcome first =
      millsim("sweep " + quoted(small_mill) + " --vary charge.filling=0.2,0.3 -q --out v" +
              tiny_run + tiny_speed);
  ASSERT_EQ(first.status, 0) << first.err;
  std::ofstream(work_ / "v" / "sweep.csv") << "point,charge.filling,status,power_kw\n"
                                           << "0,0.2,ok,1\n"
                                           << "1,0.3,ok,1\n";
  const Outcome second = millsim("sweep " + quoted(small_mill) +
                                 " --vary charge.filling=0.25 --out v" + tiny_run + tiny_speed);
  ASSERT_EQ(second.status, 0) << second.err;
  EXPECT_FALSE(fs::exists(work_ / "v" / "000_charge.filling=0.2"));
  EXPECT_FALSE(fs::exists(work_ / "v" / "001_charge.filling=0.3"));
  EXPECT_TRUE(fs::exists(work_ / "v" / "000_charge.filling=0.25" / "summary.json"));
}

TEST_F(SweepPowerCurve, AListValueMayHoldCommasInsideAnArray) {
  // Two size distributions: the commas inside each array belong to it, not to the list.
  const std::string one_size = "[{diameter = 0.025, mass_fraction = 1}]";
  const std::string two_sizes =
      "[{diameter = 0.03, mass_fraction = 0.5}, {diameter = 0.02, mass_fraction = 0.5}]";
  const Outcome o = millsim("sweep " + quoted(small_mill) + " --vary " +
                            quoted("charge.sizes=" + one_size + "," + two_sizes) + " -q --out d" +
                            tiny_run + tiny_speed);
  ASSERT_EQ(o.status, 0) << o.err;
  const auto rows = read_csv(work_ / "d" / "sweep.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("charge.sizes"), one_size);
  EXPECT_EQ(rows[1].at("charge.sizes"), two_sizes);
  EXPECT_EQ(rows[0].at("status"), "ok");
  EXPECT_EQ(rows[1].at("status"), "ok");
  // The same filling in smaller discs on average: more of them.
  EXPECT_GT(std::stoi(rows[1].at("particle_count")), std::stoi(rows[0].at("particle_count")));
}

TEST_F(SweepPowerCurve, ABadKeyOrSpecRefusesTheWholeSweepAndWritesNothing) {
  const Outcome key = millsim("sweep " + quoted(small_mill) + " --vary mill.sped=0.3,0.5 --out s");
  EXPECT_EQ(key.status, 2);
  EXPECT_NE(key.err.find("mill.sped: unknown key"), std::string::npos) << key.err;
  const Outcome value = millsim("sweep " + quoted(small_mill) + " --vary mill.speed=0.5,9 --out s");
  EXPECT_EQ(value.status, 2);
  EXPECT_NE(value.err.find("sweep point 1 (mill.speed=9)"), std::string::npos) << value.err;
  const Outcome spec = millsim("sweep --vary mill.speed=0.3:0.9 --out s");
  EXPECT_EQ(spec.status, 2);
  EXPECT_NE(spec.err.find("command line (--vary mill.speed=0.3:0.9)"), std::string::npos)
      << spec.err;
  EXPECT_NE(spec.err.find("allowed: KEY=START:STOP:STEP"), std::string::npos) << spec.err;
  EXPECT_FALSE(fs::exists(work_ / "s"));
}

}  // namespace
