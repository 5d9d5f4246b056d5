#!/usr/bin/env bash
# Times the 3D benchmark scene (bench/mill-3d-20k.toml: about 20 000 balls of 20 mm in a
# 0.9 m x 0.73 m mill, dt 1e-5 s) with millsim_scene_bench's defaults: settles the config's
# 0.5 s, turns 1000 steps untimed, then times STEPS steps (default 2000) on 1 and on 2 threads.
# Record results in bench/results.md.
#   bench/run_3d_benchmark.sh [STEPS]
# MILLSIM_BUILD=DIR uses the build in DIR as it is; otherwise this installs what is missing and
# builds build/release first.
set -euo pipefail
cd "$(dirname "$0")/.."
steps=${1:-2000}
case "$steps" in ''|*[!0-9]*|0) echo "usage: $0 [STEPS] (a whole number of steps from 1)" >&2; exit 2 ;; esac
if [ $# -gt 1 ]; then echo "usage: $0 [STEPS]" >&2; exit 2; fi
build=${MILLSIM_BUILD:-build/release}
if [ -z "${MILLSIM_BUILD:-}" ]; then
  bash scripts/install-deps.sh
  cmake --preset release >/dev/null
  cmake --build --preset release --target millsim millsim_scene_bench >/dev/null
fi
echo "millsim: $build ($("$build/millsim" --version))"
for threads in 1 2; do
  "$build/bench/millsim_scene_bench" bench/mill-3d-20k.toml --steps "$steps" -j "$threads"
  echo
done
