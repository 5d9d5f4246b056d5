#!/usr/bin/env bash
# clang-tidy, with the checks of .clang-tidy, on every source file of src/, apps/, bench/ and
# tests/ as the release build compiles it; fails on any finding. CI runs it after the tests
# (about 8 minutes on two cores).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh clang-tidy
cmake --preset release >/dev/null
# The compile commands, and the header the build generates (src/millsim/core/version.cpp
# includes it).
cmake --build --preset release --target millsim_version_info >/dev/null
# Only the findings are printed (run-clang-tidy's exit status says whether there were any).
run-clang-tidy -p build/release -j "$(nproc)" -quiet "$PWD/(src|apps|bench|tests)/" 2>&1 |
  { grep -v -E '^(clang-tidy|[0-9]+ warnings? generated|Suppressed [0-9]+ warnings|Use -header-filter)' || true; }
