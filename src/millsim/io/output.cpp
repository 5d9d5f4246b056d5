#include "millsim/io/output.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "millsim/core/error.hpp"
#include "millsim/core/version.hpp"
#include "millsim/io/partial_file.hpp"
#include "millsim/measure/empirical_power.hpp"
#include "millsim/sim/mill_run.hpp"

namespace millsim {
namespace {

std::string power_table(const std::vector<PowerInterval>& rows, bool numbered) {
  std::string text = numbered ? "revolution," : "";
  text += "start_s,end_s,torque_nm,power_kw,power_dissipation_kw,kinetic_energy_slice_j\n";
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const PowerInterval& p = rows[k];
    if (numbered) text += fmt::format("{},", k + 1);
    text += fmt::format("{},{},{},{},{},{}\n", p.start_time, p.end_time, p.torque, p.power / 1000.0,
                        p.dissipation_power / 1000.0, p.kinetic_energy);
  }
  return text;
}

/// Where the wall collisions began (ShellImpacts), one row a bin of angle.
std::string impacts_table(const MillResult& result) {
  std::vector<ContactType> types = {ContactType::ball_shell, ContactType::ball_lifter};
  if (result.plan.config.dimension == 3) types.push_back(ContactType::ball_end_plate);
  std::string text = "angle_low_rad,angle_high_rad";
  for (const ContactType t : types) {
    text += fmt::format(",{0}_count,{0}_per_s,{0}_energy_j", contact_type_name(t));
  }
  text += "\n";
  if (!result.shell_impacts) return text;
  const ShellImpacts& impacts = *result.shell_impacts;
  const double window = result.window_end.time - result.window_start.time;
  for (int k = 0; k < ShellImpacts::bins; ++k) {
    text += fmt::format("{},{}", k * ShellImpacts::bin_width, (k + 1) * ShellImpacts::bin_width);
    for (const ContactType t : types) {
      text += fmt::format(",{},{},{}", impacts.count(t, k),
                          static_cast<double>(impacts.count(t, k)) / window, impacts.energy(t, k));
    }
    text += "\n";
  }
  return text;
}

/// The liner layer's mean ball count by angle (ChargeProfile), one row a bin.
std::string charge_profile_table(const MillResult& result) {
  std::string text = "angle_low_rad,angle_high_rad,liner_layer_balls\n";
  if (!result.charge_profile) return text;
  const ChargeProfile& profile = *result.charge_profile;
  for (int k = 0; k < ChargeProfile::bins; ++k) {
    text += fmt::format("{},{},{}\n", k * ChargeProfile::bin_width,
                        (k + 1) * ChargeProfile::bin_width, profile.mean_count(k));
  }
  return text;
}

std::string spectrum_table(const MillResult& result) {
  const ImpactSpectrum& s = result.spectrum;
  const double window = result.window_end.time - result.window_start.time;
  // End plates exist only in 3D mills; a 2D file has no column for them.
  std::vector<ContactType> types = {ContactType::ball_ball, ContactType::ball_shell,
                                    ContactType::ball_lifter};
  if (result.plan.config.dimension == 3) types.push_back(ContactType::ball_end_plate);
  std::string text = "energy_low_j,energy_high_j";
  for (const ContactType t : types) {
    const auto name = contact_type_name(t);
    text += fmt::format(",{0}_count,{0}_per_s,{0}_energy_j,{0}_cumulative_energy_j", name);
  }
  text += ",ball_wall_count,ball_wall_per_s,ball_wall_energy_j,ball_wall_cumulative_energy_j\n";
  // Cumulative: the energy of this bin's collisions and of every bin below it (MODEL.md §7).
  std::vector<double> cumulative(types.size(), 0.0);
  double wall_cumulative = 0.0;
  for (std::size_t bin = 0; bin < s.bin_count(); ++bin) {
    text += fmt::format("{},{}", s.bin_lower_edge(bin), s.bin_upper_edge(bin));
    long wall_count = 0;
    double wall_energy = 0.0;
    for (std::size_t k = 0; k < types.size(); ++k) {
      const ContactType t = types[k];
      cumulative[k] += s.energy(t, bin);
      text += fmt::format(",{},{},{},{}", s.count(t, bin),
                          static_cast<double>(s.count(t, bin)) / window, s.energy(t, bin),
                          cumulative[k]);
      if (t != ContactType::ball_ball) {
        wall_count += s.count(t, bin);
        wall_energy += s.energy(t, bin);
      }
    }
    wall_cumulative += wall_energy;
    text += fmt::format(",{},{},{},{}\n", wall_count, static_cast<double>(wall_count) / window,
                        wall_energy, wall_cumulative);
  }
  return text;
}

/// One number of summary.json; `whole` numbers are written as JSON integers. One that is not
/// `present` is a number this run has none of (a toe angle of a centrifuging charge, say): left
/// out of summary.json, listed only where every run's columns must line up (sweep.csv).
struct SummaryNumber {
  std::string name;  ///< dotted for nested objects
  double value = 0.0;
  bool whole = false;
  bool present = true;
};

constexpr double absent = std::numeric_limits<double>::quiet_NaN();

/// summary.json's "empirical" object: the three models' powers, the inputs they were given and
/// the intermediate quantities of each (docs/empirical_power.md).
void append_empirical_numbers(std::vector<SummaryNumber>& numbers, const EmpiricalPower& p) {
  const EmpiricalPowerInputs& in = p.inputs;
  const MorrellPower& m = p.morrell;
  // Bond's power only where its equation gives one (BondPower::applies).
  numbers.push_back(
      {"empirical.bond_kw", p.bond.applies ? p.bond.power_kw : absent, false, p.bond.applies});
  const std::vector<SummaryNumber> empirical{
      {"empirical.hogg_fuerstenau_kw", p.hogg_fuerstenau.power_kw},
      {"empirical.morrell_net_kw", m.net_kw},
      {"empirical.inputs.diameter_m", in.diameter},
      {"empirical.inputs.length_m", in.length},
      {"empirical.inputs.filling", in.filling},
      {"empirical.inputs.speed_rpm", in.speed_rpm},
      {"empirical.inputs.shell_critical_speed_rpm", in.shell_critical_speed_rpm},
      {"empirical.inputs.speed_fraction_of_shell_critical", in.speed_fraction},
      {"empirical.inputs.ball_density_kg_m3", in.ball_density},
      {"empirical.inputs.porosity", in.porosity},
      {"empirical.inputs.bed_density_kg_m3", in.bed_density},
      {"empirical.inputs.ball_charge_mass_kg", in.ball_charge_mass},
      {"empirical.inputs.top_ball_diameter_m", in.top_ball_diameter},
      {"empirical.inputs.repose_angle_rad", in.repose_angle},
      {"empirical.bond.kw_per_ball_tonne", p.bond.kw_per_ball_tonne},
      {"empirical.bond.ball_size_factor_kw_per_tonne", p.bond.ball_size_factor},
      {"empirical.hogg_fuerstenau.segment_half_angle_rad", p.hogg_fuerstenau.half_angle},
      {"empirical.hogg_fuerstenau.centre_of_mass_radius_m",
       p.hogg_fuerstenau.centre_of_mass_radius},
      {"empirical.morrell.charge_motion_kw", m.charge_motion_kw},
      {"empirical.morrell.calibration_k", morrell_calibration},
      {"empirical.morrell.centrifuging_speed_fraction", m.centrifuging_speed_fraction},
      {"empirical.morrell.toe_angle_rad", m.toe_angle},
      {"empirical.morrell.shoulder_angle_rad", m.shoulder_angle},
      {"empirical.morrell.mean_radius_m", m.mean_radius},
      {"empirical.morrell.active_fraction", m.active_fraction},
      {"empirical.morrell.inner_radius_m", m.inner_radius},
      {"empirical.morrell.z", m.z},
  };
  numbers.insert(numbers.end(), empirical.begin(), empirical.end());
}

std::vector<SummaryNumber> summary_numbers(const MillResult& r) {
  const MillPlan& plan = r.plan;
  const MillConfig& c = plan.config;
  const auto count = [](auto n) { return static_cast<double>(n); };
  std::vector<SummaryNumber> numbers{
      {"power_kw", r.power_kw},
      {"power_dissipation_kw", r.power_dissipation_kw},
      {"power_std_kw", r.power_std_kw},
      {"torque_nm", r.torque_nm},
      {"energy_balance_error", r.energy_balance_error},
      {"critical_speed_rpm", plan.critical_speed_rpm},
      {"speed_rpm", plan.speed_rpm},
      {"speed_fraction_of_critical", plan.speed_fraction},
      {"particle_count", count(plan.particle_count), true},
      {"time_step_s", plan.time_step},
      {"critical_time_step_s", plan.critical_time_step},
      {"shortest_contact_duration_s",
       std::min(plan.contact_duration_ball_ball, plan.contact_duration_ball_wall)},
      {"steps", count(r.steps), true},
      {"simulated_seconds", r.simulated_seconds},
      {"wall_seconds", r.wall_seconds},
      {"settle_wall_seconds", r.settle_wall_seconds},
      {"particle_steps_per_second", r.particle_steps_per_second},
      {"measured_revolutions", count(c.measure_revolutions), true},
      {"slice_charge_mass_kg", plan.slice_mass},
      {"mill_charge_mass_kg", plan.mill_charge_mass},
      {"power_scale", plan.power_scale},
      {"charge_orbital_speed_ratio", r.orbital_speed_ratio},
      {"largest_overlap_fraction", r.largest_overlap_fraction},
      {"dimension", count(c.dimension), true},
  };
  // Only where the charge has a toe and a shoulder (not when it lines the whole shell).
  const auto ends = r.charge_profile ? r.charge_profile->toe_and_shoulder() : std::nullopt;
  numbers.push_back({"charge_toe_angle_rad", ends ? ends->toe : absent, false, ends.has_value()});
  numbers.push_back(
      {"charge_shoulder_angle_rad", ends ? ends->shoulder : absent, false, ends.has_value()});
  append_empirical_numbers(numbers, empirical_power(plan));
  const bool reference = c.reference.has_value();
  numbers.push_back({"reference.measured_power_kw", reference ? c.reference->measured_kw : absent,
                     false, reference});
  numbers.push_back(
      {"reference.tolerance", reference ? c.reference->tolerance : absent, false, reference});
  const bool paper = reference && c.reference->paper_kw.has_value();
  numbers.push_back(
      {"reference.paper_power_kw", paper ? *c.reference->paper_kw : absent, false, paper});
  return numbers;
}

/// Puts `number` into `table`, creating the nested objects its dotted name asks for.
void insert_number(toml::table& table, const SummaryNumber& number) {
  toml::table* parent = &table;
  std::string_view name = number.name;
  for (auto dot = name.find('.'); dot != std::string_view::npos; dot = name.find('.')) {
    const std::string_view key = name.substr(0, dot);
    if (!parent->contains(key)) parent->insert(key, toml::table{});
    parent = parent->get_as<toml::table>(key);
    name.remove_prefix(dot + 1);
  }
  if (number.whole) {
    parent->insert_or_assign(name, static_cast<std::int64_t>(number.value));
  } else {
    parent->insert_or_assign(name, number.value);
  }
}

}  // namespace

namespace {

/// A snapshot's rows: each particle by id, with its velocity and spin at the time of the
/// positions, every number in the shortest text that reads back to the same double.
void write_particles(PartialFile& out, const World<3>& world) {
  const auto& p = world.particles();
  out.write("id,x,y,z,vx,vy,vz,wx,wy,wz,radius,fx,fy,fz\n");
  for (std::size_t id = 0; id < p.size(); ++id) {
    const std::size_t i = world.particle_index(id);
    const Vec3& x = p.position[i];
    const auto [v, w] = motion_at_positions(world, i);
    const Vec3& f = p.force[i];
    out.print("{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", id, x[0], x[1], x[2], v[0], v[1], v[2],
              w[0], w[1], w[2], p.radius[i], f[0], f[1], f[2]);
  }
}

void write_particles(PartialFile& out, const World<2>& world) {
  const auto& p = world.particles();
  out.write("id,x,y,vx,vy,omega,radius,fx,fy\n");
  for (std::size_t id = 0; id < p.size(); ++id) {
    const std::size_t i = world.particle_index(id);
    const Vec2& x = p.position[i];
    const auto [v, w] = motion_at_positions(world, i);
    const Vec2& f = p.force[i];
    out.print("{},{},{},{},{},{},{},{},{}\n", id, x[0], x[1], v[0], v[1], w, p.radius[i], f[0],
              f[1]);
  }
}

}  // namespace

SnapshotWriter::SnapshotWriter(std::filesystem::path directory, bool csv, bool vtk)
    : directory_(std::move(directory)), csv_(csv), vtk_(vtk) {}

SnapshotWriter::~SnapshotWriter() {
  if (index_ != nullptr) std::fclose(index_);
}

template <int D>
void SnapshotWriter::write(const World<D>& world) {
  const std::string stem = fmt::format("snapshot_{:06d}", count_);
  if (csv_) {
    PartialFile out(directory_ / (stem + ".csv"));
    write_particles(out, world);
    out.commit();
  }
  if (vtk_) {
    const std::string mill = fmt::format("mill_{:06d}.vtp", count_);
    write_whole_file(directory_ / (stem + ".vtp"), particles_vtp(world));
    write_whole_file(directory_ / mill, mill_vtp(world));
    if (!particle_collection_) {
      particle_collection_ = std::make_unique<PvdCollection>(directory_ / "particles.pvd");
      mill_collection_ = std::make_unique<PvdCollection>(directory_ / "mill.pvd");
    }
    particle_collection_->add(world.time(), {stem + ".vtp"});
    mill_collection_->add(world.time(), {mill});
  }
  const std::string name = stem + (csv_ ? ".csv" : ".vtp");
  // The index gets the snapshot's row once the snapshot is whole, so that every file it names
  // is complete; rows are appended and flushed one by one.
  const std::filesystem::path index_path = directory_ / "index.csv";
  const bool first = index_ == nullptr;
  if (first) {
    index_ = std::fopen(index_path.c_str(), "wb");
    if (index_ == nullptr) {
      throw std::runtime_error(
          fmt::format("{}: cannot write: {}", index_path.string(), std::strerror(errno)));
    }
  }
  const std::string row =
      fmt::format("{}{},{},{},{}\n", first ? "snapshot,file,time_s,shell_angle_rad\n" : "", count_,
                  name, world.time(), world.walls().mill ? world.walls().mill->angle : 0.0);
  errno = 0;
  if (std::fwrite(row.data(), 1, row.size(), index_) == row.size() && std::fflush(index_) == 0) {
    index_end_ += static_cast<long>(row.size());
    ++count_;
    return;
  }
  // Failed (a full disk, say): the index as it was, whole rows only (the file removed if it
  // had none), as the collections are left.
  undo_failed_append(index_, index_path, index_end_, first, errno);
}

template void SnapshotWriter::write(const World<2>&);
template void SnapshotWriter::write(const World<3>&);

std::vector<std::pair<std::string, double>> summary_scalars(const MillResult& result) {
  std::vector<std::pair<std::string, double>> scalars;
  for (const SummaryNumber& n : summary_numbers(result)) {
    if (n.present) scalars.emplace_back(n.name, n.value);
  }
  return scalars;
}

std::vector<std::pair<std::string, double>> summary_columns(const MillResult& result) {
  std::vector<std::pair<std::string, double>> columns;
  for (const SummaryNumber& n : summary_numbers(result)) columns.emplace_back(n.name, n.value);
  return columns;
}

std::string shortest_json_numbers(std::string_view json) {
  std::string out;
  out.reserve(json.size());
  std::size_t k = 0;
  while (k < json.size()) {
    const char c = json[k];
    if (c == '"') {  // a string, copied whole (a backslash escapes the next character)
      const std::size_t start = k++;
      while (k < json.size() && json[k] != '"') k += json[k] == '\\' ? 2 : 1;
      k = std::min(json.size(), k + 1);
      out.append(json.substr(start, k - start));
      continue;
    }
    if (c != '-' && (c < '0' || c > '9')) {
      out.push_back(c);
      ++k;
      continue;
    }
    const std::size_t start = k;
    while (k < json.size() &&
           std::string_view("0123456789+-.eE").find(json[k]) != std::string_view::npos) {
      ++k;
    }
    const std::string_view token = json.substr(start, k - start);
    double value = 0.0;
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    const bool fractional = token.find_first_of(".eE") != std::string_view::npos;
    if (!fractional || error != std::errc{} || end != token.data() + token.size()) {
      out.append(token);  // an integer, or not a number this pass understands: as written
      continue;
    }
    std::string shortest = fmt::format("{}", value);
    if (shortest.find_first_of(".e") == std::string::npos) shortest += ".0";
    out += shortest;
  }
  return out;
}

std::string summary_json(const MillResult& r) {
  const MillPlan& plan = r.plan;
  const MillConfig& c = plan.config;
  toml::array discs;
  for (const DiscClass& d : plan.discs) {
    discs.push_back(
        toml::table{{"diameter_m", d.diameter}, {"count", d.count}, {"mass_kg", d.mass}});
  }
  toml::table summary{
      {"kind", "mill"},
      {"millsim_version", version_text()},
      {"config", c.source},
      {"charge_centre_of_mass_m", toml::array{r.charge_centre[0], r.charge_centre[1]}},
      {c.dimension == 2 ? "discs" : "balls", discs},
  };
  if (c.reference) summary.insert("reference", toml::table{{"case", c.reference->case_name}});
  // JSON has no infinity or NaN: a run whose figures are not finite has diverged, and is
  // reported as failed rather than written.
  for (const SummaryNumber& n : summary_numbers(r)) {
    if (!n.present) continue;
    if (!std::isfinite(n.value)) {
      throw std::runtime_error(
          fmt::format("the run diverged: {} is {} (no results written)", n.name, n.value));
    }
    insert_number(summary, n);
  }
  for (const double x : {r.charge_centre[0], r.charge_centre[1]}) {
    if (!std::isfinite(x)) {
      throw std::runtime_error(
          "the run diverged: charge_centre_of_mass_m is not finite (no "
          "results written)");
    }
  }
  std::ostringstream text;
  text << toml::json_formatter{summary} << "\n";
  return shortest_json_numbers(text.str());
}

std::string summary_line(const MillResult& r) {
  const EmpiricalPower empirical = empirical_power(r.plan);
  // One measured revolution has no spread to show.
  const std::string spread = r.plan.config.measure_revolutions > 1
                                 ? fmt::format("±{:.2g} kW between revolutions", r.power_std_kw)
                                 : std::string("one revolution measured");
  return fmt::format(
      "power {:.4g} kW (dissipation {:.4g} kW, {}) at {:.3g} rpm "
      "({:.0f}% of critical); empirical: {}, Hogg-Fuerstenau {:.4g} kW, Morrell "
      "net {:.4g} kW; {} {}, {} steps in {:.1f} s ({:.3g} particle-steps/s)",
      r.power_kw, r.power_dissipation_kw, spread, r.plan.speed_rpm, 100.0 * r.plan.speed_fraction,
      bond_power_text(empirical.bond), empirical.hogg_fuerstenau.power_kw, empirical.morrell.net_kw,
      r.plan.particle_count, r.plan.config.dimension == 2 ? "discs" : "balls", r.steps,
      r.wall_seconds, r.particle_steps_per_second);
}

void write_results(const std::filesystem::path& directory, const MillResult& result) {
  const std::string summary = summary_json(result);  // checked before any file is written
  write_whole_file(directory / "power.csv", power_table(result.revolutions, true));
  write_whole_file(directory / "power_timeseries.csv", power_table(result.series, false));
  write_whole_file(directory / "spectrum.csv", spectrum_table(result));
  write_whole_file(directory / "charge_profile.csv", charge_profile_table(result));
  write_whole_file(directory / "impacts.csv", impacts_table(result));
  write_whole_file(directory / "summary.json", summary);
}

std::vector<std::string> result_warnings(const MillResult& r) {
  std::vector<std::string> warnings;
  if (!(r.energy_balance_error <= doubtful_energy_balance_error)) {
    // Three digits, without an exponent from 100 % on (2120 %, not 2.12e+03 %).
    const double error = 100.0 * r.energy_balance_error;
    const std::string percent = error >= 100.0
                                    ? fmt::format("{:.0f}", error)
                                    : beyond_text(error, 100.0 * doubtful_energy_balance_error);
    warnings.push_back(fmt::format(
        "the energy balance is off by {} % of the shell's work (more than {:.0f} %): the "
        "time step may be too coarse for these contacts, and the results are doubtful",
        percent, 100.0 * doubtful_energy_balance_error));
  }
  // A balance that does not close explains any disagreement of the two powers.
  // (Two powers that are next to none are not compared: their gap is rounding.)
  const double larger = std::max(
      {std::abs(r.power_kw), std::abs(r.power_dissipation_kw), least_drive_power(r.plan) / 1000.0});
  if (warnings.empty() &&
      std::abs(r.power_kw - r.power_dissipation_kw) > doubtful_power_disagreement * larger) {
    const MillConfig& c = r.plan.config;
    const bool spin_up_measured = c.measure_revolutions >= c.revolutions;
    warnings.push_back(fmt::format(
        "power by torque ({:.4g} kW) and by dissipation ({:.4g} kW) differ by more than {:.0f} %: "
        "the charge was not steady over the measured revolutions ({})",
        r.power_kw, r.power_dissipation_kw, 100.0 * doubtful_power_disagreement,
        spin_up_measured ? "the first revolution, which includes the spin-up, was measured; run "
                           "more revolutions than are measured"
                         : "its energy changed over the window: run more revolutions before "
                           "measuring, or measure more"));
  }
  if (r.dropped_wall_contacts > 0) {
    warnings.push_back(fmt::format(
        "{} wall contacts were left out (a particle pressed into more walls at once than millsim "
        "keeps a contact history for): the results are doubtful",
        r.dropped_wall_contacts));
  }
  if (r.largest_overlap_fraction > doubtful_overlap_fraction) {
    warnings.push_back(fmt::format(
        "contacts overlapped by up to {} % of the smaller ball's radius (more than {:.0f} %): "
        "the springs are soft for these balls and this mill (materials.*.normal_stiffness), "
        "balls sink into each other{}, and the results are doubtful",
        beyond_text(100.0 * r.largest_overlap_fraction, 100.0 * doubtful_overlap_fraction, 2),
        100.0 * doubtful_overlap_fraction,
        r.largest_overlap_fraction >= 1.0 ? " and may pass through one another or a wall" : ""));
  }
  return warnings;
}

}  // namespace millsim
