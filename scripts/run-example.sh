#!/usr/bin/env bash
# Quick start 1: install what is missing, build millsim, and run the built-in example mill.
# Extra arguments go to `millsim run` (e.g. --set mill.speed=0.75).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target millsim
./build/release/millsim run "$@"
