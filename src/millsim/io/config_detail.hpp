// What config.cpp and scene_config.cpp share: the readers of the tables a mill and a scene
// have in common, and the scene's reader. Internal to the config reading; not part of the
// library's interface (config.hpp is).
#pragma once

#include <toml++/toml.h>

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "millsim/io/config.hpp"
#include "millsim/io/toml_reader.hpp"
#include "millsim/particles/material.hpp"

namespace millsim::config_detail {

/// The names a mill config and a scene config allow at the top level and in [simulation]: what
/// each reader allows, and what a config of neither kind is checked against.
inline constexpr std::array<std::string_view, 6> mill_tables = {
    "simulation", "mill", "charge", "materials", "output", "reference"};
inline constexpr std::array<std::string_view, 5> scene_tables = {"simulation", "particles", "walls",
                                                                 "materials", "output"};
inline constexpr std::array<std::string_view, 6> mill_simulation_keys = {
    "dimension", "time_step", "settle_time", "revolutions", "measure_revolutions", "seed"};
inline constexpr std::array<std::string_view, 4> scene_simulation_keys = {"dimension", "time_step",
                                                                          "duration", "gravity"};

/// simulation.time_step: "auto" (empty) or a number of seconds > 0.
std::optional<double> read_time_step(TableReader& section);
/// A [materials.*] table: stiffnesses, restitution and friction, with MODEL.md's defaults.
ContactMaterial read_material(TableReader section);
/// output.directory: a non-empty path, default "out".
std::string read_output_directory(TableReader& section);

/// A scene config (particles and walls, no mill) from its parsed document.
SceneConfig read_scene_config(const toml::table& document, const std::string& source);

}  // namespace millsim::config_detail
