#!/usr/bin/env bash
# Quick start 2: install what is missing, build millsim and its tests, and run them all.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release
