#!/usr/bin/env bash
# Times the 3D benchmark scene (bench/mill-3d-20k.toml: about 20 000 balls of 20 mm in a
# 0.9 m x 0.73 m mill, dt 1e-5 s): settles 0.5 s, turns 1000 steps untimed, then times a fixed
# number of steps (default 2000) on 1 and on 2 threads. Record results in bench/results.md.
#   bench/run_3d_benchmark.sh [STEPS]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target millsim_scene_bench >/dev/null
steps=${1:-2000}
for threads in 1 2; do
  ./build/release/bench/millsim_scene_bench bench/mill-3d-20k.toml --steps "$steps" -j "$threads"
  echo
done
