// spectrum.csv (io/output.hpp, README "Outputs") from a spectrum of known collisions: each
// collision in the row whose energy edges enclose it, counts per second over the measured
// window, energies, cumulative energies and the ball_wall columns as the walls' sums.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "millsim/builtin_example.hpp"
#include "millsim/io/config.hpp"
#include "millsim/io/output.hpp"
#include "millsim/sim/mill_run.hpp"

namespace millsim {
namespace {

/// The CSV's rows as maps from column name to value.
std::vector<std::map<std::string, double>> read_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::stringstream header(line); std::getline(header, line, ',');) names.push_back(line);
  std::vector<std::map<std::string, double>> rows;
  while (std::getline(in, line)) {
    std::map<std::string, double> row;
    std::stringstream cells(line);
    std::string cell;
    for (const std::string& name : names) {
      std::getline(cells, cell, ',');
      row[name] = std::strtod(cell.c_str(), nullptr);
    }
    rows.push_back(row);
  }
  return rows;
}

TEST(SpectrumCsv, EachCollisionIsInItsBinWithRatesAndCumulativeEnergies) {
  MillResult result;
  // A real plan (the built-in 2D example), whose figures summary.json can write.
  result.plan = plan_mill(parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", {}));
  result.window_start.time = 1.0;
  result.window_end.time = 3.0;  // 2 s measured
  ImpactSpectrum& s = result.spectrum;
  s.record(ContactType::ball_ball, 1.0e-3);
  s.record(ContactType::ball_ball, 1.1e-3);  // the same bin: [1e-3, 1.585e-3)
  s.record(ContactType::ball_ball, 0.5);
  s.record(ContactType::ball_shell, 0.5);
  s.record(ContactType::ball_lifter, 2.0e-8);

  const std::filesystem::path directory = std::filesystem::temp_directory_path() /
                                          ("millsim_spectrum_csv_" + std::to_string(::getpid()));
  std::filesystem::create_directories(directory);
  write_results(directory, result);
  const auto rows = read_csv(directory / "spectrum.csv");
  std::filesystem::remove_all(directory);

  ASSERT_EQ(rows.size(), s.bin_count());
  const auto row_of = [&](double energy) {
    for (const auto& row : rows) {
      if (row.at("energy_low_j") <= energy && energy < row.at("energy_high_j")) return row;
    }
    ADD_FAILURE() << "no row for " << energy << " J";
    return rows.front();
  };
  const auto low = row_of(1.0e-3);
  EXPECT_EQ(low.at("ball_ball_count"), 2.0);
  EXPECT_EQ(low.at("ball_ball_per_s"), 1.0);
  EXPECT_NEAR(low.at("ball_ball_energy_j"), 2.1e-3, 1e-9);
  EXPECT_NEAR(low.at("ball_ball_cumulative_energy_j"), 2.1e-3, 1e-9);
  const auto high = row_of(0.5);
  EXPECT_EQ(high.at("ball_ball_count"), 1.0);
  EXPECT_EQ(high.at("ball_shell_count"), 1.0);
  EXPECT_EQ(high.at("ball_shell_per_s"), 0.5);
  EXPECT_NEAR(high.at("ball_ball_cumulative_energy_j"), 0.5021, 1e-9);
  EXPECT_NEAR(high.at("ball_shell_cumulative_energy_j"), 0.5, 1e-9);
  // ball_wall: shell and lifter together.
  EXPECT_EQ(high.at("ball_wall_count"), 1.0);
  EXPECT_NEAR(high.at("ball_wall_energy_j"), 0.5, 1e-9);
  EXPECT_NEAR(high.at("ball_wall_cumulative_energy_j"), 0.5 + 2.0e-8, 1e-6);  // 6 digits
  EXPECT_EQ(row_of(2.0e-8).at("ball_lifter_count"), 1.0);
  // The lifter's collision in ball_wall's own row (the cumulative figure above cannot show a
  // 2e-8 J term at 6 digits).
  EXPECT_EQ(row_of(2.0e-8).at("ball_wall_count"), 1.0);
  EXPECT_NEAR(row_of(2.0e-8).at("ball_wall_energy_j"), 2.0e-8, 1e-13);
  // The last row's cumulative energy is the total of its type.
  EXPECT_NEAR(rows.back().at("ball_ball_cumulative_energy_j"),
              s.total_energy(ContactType::ball_ball), 1e-12);
  EXPECT_EQ(rows.front().count("ball_end_plate_count"), 0u) << "a 2D mill has no end plates";
}

}  // namespace
}  // namespace millsim
