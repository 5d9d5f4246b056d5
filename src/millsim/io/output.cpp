#include "millsim/io/output.hpp"

#include <fmt/format.h>
#include <fmt/os.h>
#include <toml++/toml.h>

#include <fstream>
#include <sstream>

#include "millsim/sim/mill_run.hpp"

namespace millsim {
namespace {

/// Writes `text` to `path` through a temporary file, so that a reader never sees half a file.
void write_file(const std::filesystem::path& path, const std::string& text) {
  const std::filesystem::path temporary = path.string() + ".partial";
  {
    std::ofstream out(temporary, std::ios::binary);
    out << text;
    if (!out) throw std::runtime_error(fmt::format("cannot write {}", temporary.string()));
  }
  std::filesystem::rename(temporary, path);
}

std::string power_table(const std::vector<PowerInterval>& rows, bool numbered) {
  std::string text = numbered ? "revolution," : "";
  text += "start_s,end_s,torque_nm,power_kw,dissipation_kw,kinetic_energy_slice_j\n";
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const PowerInterval& p = rows[k];
    if (numbered) text += fmt::format("{},", k + 1);
    text += fmt::format("{:.6f},{:.6f},{:.6g},{:.6g},{:.6g},{:.6g}\n", p.start_time, p.end_time,
                        p.torque, p.power / 1000.0, p.dissipation_power / 1000.0, p.kinetic_energy);
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
    text += fmt::format(",{0}_count,{0}_per_s,{0}_energy_j", name);
  }
  text += ",ball_wall_count,ball_wall_per_s,ball_wall_energy_j\n";
  for (std::size_t bin = 0; bin < s.bin_count(); ++bin) {
    text += fmt::format("{:.4g},{:.4g}", s.bin_lower_edge(bin), s.bin_upper_edge(bin));
    long wall_count = 0;
    double wall_energy = 0.0;
    for (const ContactType t : types) {
      text += fmt::format(",{},{:.6g},{:.6g}", s.count(t, bin),
                          static_cast<double>(s.count(t, bin)) / window, s.energy(t, bin));
      if (t != ContactType::ball_ball) {
        wall_count += s.count(t, bin);
        wall_energy += s.energy(t, bin);
      }
    }
    text += fmt::format(",{},{:.6g},{:.6g}\n", wall_count, static_cast<double>(wall_count) / window,
                        wall_energy);
  }
  return text;
}

}  // namespace

void write_snapshot(const std::filesystem::path& directory, int index, const World<3>& world) {
  const auto path = directory / fmt::format("snapshot_{:06d}.csv", index);
  auto out = fmt::output_file(path.string());
  const auto& p = world.particles();
  out.print("# time_s = {:.9g}, shell_angle_rad = {:.9g}\n", world.time(),
            world.walls().mill ? world.walls().mill->angle : 0.0);
  out.print("id,x,y,z,vx,vy,vz,wx,wy,wz,radius,fx,fy,fz\n");
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3& x = p.position[i];
    const Vec3& v = p.velocity[i];
    const Vec3& w = p.angular_velocity[i];
    const Vec3& f = p.force[i];
    out.print(
        "{},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g},"
        "{:.7g},{:.7g}\n",
        i, x[0], x[1], x[2], v[0], v[1], v[2], w[0], w[1], w[2], p.radius[i], f[0], f[1], f[2]);
  }
}

void write_snapshot(const std::filesystem::path& directory, int index, const World<2>& world) {
  const auto path = directory / fmt::format("snapshot_{:06d}.csv", index);
  auto out = fmt::output_file(path.string());
  const auto& p = world.particles();
  out.print("# time_s = {:.9g}, shell_angle_rad = {:.9g}\n", world.time(),
            world.walls().mill ? world.walls().mill->angle : 0.0);
  out.print("id,x,y,vx,vy,omega,radius,fx,fy\n");
  for (std::size_t i = 0; i < p.size(); ++i) {
    out.print("{},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g},{:.7g}\n", i, p.position[i][0],
              p.position[i][1], p.velocity[i][0], p.velocity[i][1], p.angular_velocity[i],
              p.radius[i], p.force[i][0], p.force[i][1]);
  }
}

std::string summary_json(const MillResult& r) {
  const MillPlan& plan = r.plan;
  const MillConfig& c = plan.config;
  toml::table sizes_table;
  toml::array discs;
  for (const DiscClass& d : plan.discs) {
    discs.push_back(
        toml::table{{"diameter_m", d.diameter}, {"count", d.count}, {"mass_kg", d.mass}});
  }
  toml::table summary{
      {"config", c.source},
      {"power_kw", r.power_kw},
      {"power_dissipation_kw", r.power_dissipation_kw},
      {"power_std_kw", r.power_std_kw},
      {"torque_nm", r.torque_nm},
      {"energy_balance_error", r.energy_balance_error},
      {"critical_speed_rpm", plan.critical_speed_rpm},
      {"speed_rpm", plan.speed_rpm},
      {"speed_fraction_of_critical", plan.speed_fraction},
      {"particle_count", plan.particle_count},
      {"time_step_s", plan.time_step},
      {"steps", r.steps},
      {"simulated_seconds", r.simulated_seconds},
      {"wall_seconds", r.wall_seconds},
      {"particle_steps_per_second", r.particle_steps_per_second},
      {"measured_revolutions", c.measure_revolutions},
      {"slice_charge_mass_kg", plan.slice_mass},
      {"mill_charge_mass_kg", plan.mill_charge_mass},
      {"power_scale", plan.power_scale},
      {"charge_centre_of_mass_m", toml::array{r.charge_centre[0], r.charge_centre[1]}},
      {"charge_orbital_speed_ratio", r.orbital_speed_ratio},
      {c.dimension == 2 ? "discs" : "balls", discs},
      {"dimension", c.dimension},
  };
  if (c.reference) {
    toml::table reference{{"case", c.reference->case_name},
                          {"measured_power_kw", c.reference->measured_kw},
                          {"tolerance", c.reference->tolerance}};
    if (c.reference->paper_kw) reference.insert("paper_power_kw", *c.reference->paper_kw);
    summary.insert("reference", reference);
  }
  std::ostringstream text;
  text << toml::json_formatter{summary} << "\n";
  return text.str();
}

std::string summary_line(const MillResult& r) {
  return fmt::format(
      "power {:.4g} kW (dissipation {:.4g} kW, ±{:.2g} kW between revolutions) at {:.3g} rpm "
      "({:.0f}% of critical); {} {}, {} steps in {:.1f} s ({:.3g} particle-steps/s)",
      r.power_kw, r.power_dissipation_kw, r.power_std_kw, r.plan.speed_rpm,
      100.0 * r.plan.speed_fraction, r.plan.particle_count,
      r.plan.config.dimension == 2 ? "discs" : "balls", r.steps, r.wall_seconds,
      r.particle_steps_per_second);
}

void write_results(const std::filesystem::path& directory, const MillResult& result) {
  write_file(directory / "power.csv", power_table(result.revolutions, true));
  write_file(directory / "power_timeseries.csv", power_table(result.series, false));
  write_file(directory / "spectrum.csv", spectrum_table(result));
  write_file(directory / "summary.json", summary_json(result));
}

}  // namespace millsim
