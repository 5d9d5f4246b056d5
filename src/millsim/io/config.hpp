// The mill description a user writes (README "Config reference"), read from TOML.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "millsim/particles/material.hpp"

namespace millsim {

struct SizeClass {
  double diameter = 0.0;       ///< m
  double mass_fraction = 0.0;  ///< of the charge mass, sums to 1 over the classes
};

/// Measured and published power of a validation case ([reference] table), for `validate`.
struct ReferencePower {
  std::string case_name;
  double measured_kw = 0.0;
  std::optional<double> paper_kw;
  double tolerance = 0.15;  ///< allowed relative error against measured
};

struct MillConfig {
  std::string source;  ///< the file it came from, for messages

  // [simulation]
  int dimension = 2;
  std::optional<double> time_step;  ///< s; empty = "auto"
  double settle_time = 1.0;         ///< s
  double revolutions = 6.0;
  int measure_revolutions = 4;
  std::uint64_t seed = 1;

  // [mill]
  double diameter = 0.0;                 ///< m, inside the shell
  double length = 0.0;                   ///< m
  std::optional<double> speed_fraction;  ///< of critical speed
  std::optional<double> speed_rpm;
  int lifter_count = 0;
  double lifter_height = 0.0;       ///< m, radial
  double lifter_width = 0.0;        ///< m, tangential
  bool periodic = false;            ///< 3D: simulate a periodic axial slab instead of end plates
  double slab_length = 0.0;         ///< m, 3D periodic: the slab's length; power scales to length
  double cone_length = 0.0;         ///< m, 3D: axial length of each conical end; 0 = flat ends
  double cone_angle_degrees = 0.0;  ///< 3D: angle between a cone and the plane of a flat end

  // [charge]
  double filling = 0.0;
  double porosity = 0.4;
  double density = 7800.0;  ///< kg/m³
  std::vector<SizeClass> sizes;
  std::string size_description;  ///< how the sizes were given, for reports

  // [materials]
  ContactMaterial ball_ball;
  ContactMaterial ball_wall;

  // [output]
  std::string output_directory = "out";
  double snapshot_interval = 0.05;  ///< s; 0 = none
  bool snapshot_csv = true;         ///< output.snapshot_format "csv" or "both"
  bool snapshot_vtk = false;        ///< output.snapshot_format "vtk" or "both"

  std::optional<ReferencePower> reference;

  /// Where each key that was given came from, by dotted name: "lab.toml:14", or
  /// "command line (--set mill.speed=0.7)" for an override. Keys left at their defaults are
  /// absent.
  std::map<std::string, std::string, std::less<>> key_locations;

  /// Where `dotted_key` was given, for a message about it found after reading (an unstable
  /// time step, a charge that does not fit): as in key_locations, or "`source` (not given: its
  /// default)" for a key left at its default. Use as "{location_of(key)}: {key}: message;
  /// allowed: ...".
  std::string location_of(std::string_view dotted_key) const;
};

/// One particle of a scene ([[particles]]). Vectors have `dimension` used components; in 2D the
/// spin is angular_velocity[0] (about the out-of-plane axis).
struct SceneParticle {
  std::array<double, 3> position{};          ///< m
  std::array<double, 3> velocity{};          ///< m/s
  std::array<double, 3> angular_velocity{};  ///< rad/s
  double diameter = 0.0;                     ///< m
  double density = 7800.0;                   ///< kg/m³
};

/// An infinite plane wall of a scene ([[walls]]): particles live where (x − point)·normal > 0.
struct SceneWall {
  std::array<double, 3> point{};
  std::array<double, 3> normal{};  ///< unit (normalised when read)
};

/// A scene: particles and plane walls without a mill (README "Scenes"), for drop and impact
/// tests and code verification.
struct SceneConfig {
  std::string source;

  // [simulation]
  int dimension = 2;
  std::optional<double> time_step;  ///< s; empty = "auto"
  double duration = 0.0;            ///< s
  std::array<double, 3> gravity{};  ///< m/s²; default −9.81 along the last axis

  std::vector<SceneParticle> particles;
  std::vector<SceneWall> walls;

  ContactMaterial ball_ball;
  ContactMaterial ball_wall;

  // [output]
  std::string output_directory = "out";
  double trajectory_interval = 0.0;  ///< s; 0: trajectory rows at the start and end only

  std::map<std::string, std::string, std::less<>> key_locations;
  std::string location_of(std::string_view dotted_key) const;
};

/// What a config file describes: a mill (it has a [mill] table) or a scene (no [mill]).
using JobConfig = std::variant<MillConfig, SceneConfig>;

/// Reads a mill or a scene config from TOML text. Throws InputError.
JobConfig parse_config(std::string_view toml_text, const std::string& source,
                       const std::vector<std::string>& overrides = {});
/// Reads a mill or a scene config file. Throws InputError.
JobConfig load_config(const std::string& path, const std::vector<std::string>& overrides = {});

/// Reads a mill config from TOML text. `source` names it in messages. Throws InputError.
MillConfig parse_mill_config(std::string_view toml_text, const std::string& source,
                             const std::vector<std::string>& overrides = {});
/// Reads a mill config file. Throws InputError (also for a missing or unreadable file).
MillConfig load_mill_config(const std::string& path,
                            const std::vector<std::string>& overrides = {});

/// The graded charge millsim uses for `top_size` (docs/model.md): Bond's equilibrium ball
/// charge, cumulative mass passing d = (d / top)^3.84, in four classes of ratio 0.8.
std::vector<SizeClass> graded_charge(double top_size);

}  // namespace millsim
