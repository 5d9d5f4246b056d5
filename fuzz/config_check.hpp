// What the config fuzzer checks for one input (fuzz/README.md): the text is read as a config
// file, each line after a line "#--set" as a --set override, and what it describes is planned
// and, when small, built (the charge placed, the scene's particles set down), as `millsim run`
// does before its first step, and a small world is stepped a few times. Bad input may only end in
// InputError, millsim's clear message naming the file, line and key; anything else (another
// exception, a crash, a sanitizer's report, a hang) is a finding. Used by the libFuzzer target
// (fuzz/config_fuzzer.cpp) and by the test that replays fuzz/corpus
// (tests/unit/test_fuzz_corpus.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "millsim/core/error.hpp"
#include "millsim/io/config.hpp"
#include "millsim/sim/charge.hpp"
#include "millsim/sim/scene_run.hpp"
#include "millsim/sim/world.hpp"

namespace millsim::fuzz {

/// Worlds above this many particles are planned but not built: placing a large charge takes
/// the fuzzer's time without reaching other code.
inline constexpr std::size_t largest_built_world = 2000;
/// Worlds of at most this many particles also take steps_taken steps (whatever the config's
/// times: the first steps of settling, or of a scene).
inline constexpr std::size_t largest_stepped_world = 300;
inline constexpr int steps_taken = 20;

template <int D>
void step_if_small(World<D> world) {
  if (world.particles().size() > largest_stepped_world) return;
  for (int k = 0; k < steps_taken; ++k) world.step();
}

/// The config text and the --set overrides of one input.
struct ConfigInput {
  std::string text;
  std::vector<std::string> overrides;
};

inline ConfigInput split_input(std::string_view data) {
  ConfigInput input;
  constexpr std::string_view marker = "\n#--set\n";
  const std::size_t at = data.find(marker);
  input.text = std::string(data.substr(0, at));
  if (at == std::string_view::npos) return input;
  std::string_view rest = data.substr(at + marker.size());
  while (!rest.empty()) {
    const std::size_t end = rest.find('\n');
    input.overrides.emplace_back(rest.substr(0, end));
    if (end == std::string_view::npos) break;
    rest.remove_prefix(end + 1);
  }
  return input;
}

/// Reads, plans and (when small) builds the config of one input. Returns true when it was
/// accepted, false when refused with an InputError; lets any other exception through.
inline bool check_config(std::string_view data) {
  const ConfigInput input = split_input(data);
  try {
    const JobConfig job = parse_config(input.text, "fuzz.toml", input.overrides);
    std::visit(
        [](const auto& config) {
          if constexpr (std::is_same_v<std::decay_t<decltype(config)>, MillConfig>) {
            const MillPlan plan = plan_mill(config);
            if (static_cast<std::size_t>(plan.particle_count) > largest_built_world) return;
            if (plan.config.dimension == 2) {
              step_if_small(build_mill_world<2>(plan));
            } else {
              step_if_small(build_mill_world<3>(plan));
            }
          } else {
            const ScenePlan plan = plan_scene(config);
            if (plan.config.particles.size() > largest_built_world) return;
            if (plan.config.dimension == 2) {
              step_if_small(build_scene_world<2>(plan));
            } else {
              step_if_small(build_scene_world<3>(plan));
            }
          }
        },
        job);
    return true;
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace millsim::fuzz
