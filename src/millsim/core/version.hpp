#pragma once

#include <string>

namespace millsim {

/// The program's version and the source revision it was built from (`git describe --always
/// --dirty` at build time; "unknown" outside a git checkout), e.g. "0.1.0 (331296c8a1b2)":
/// printed by `millsim --version` and written into every summary.json, so that results can be
/// traced to the code that made them.
std::string version_text();

}  // namespace millsim
