#!/usr/bin/env bash
# Runs the paper's headline 2D scene (bench/sag-12m-2d.toml: 12 m SAG mill, ~7 200 discs,
# 2 s of settling + two revolutions at 5 rpm = 24 s of turning) and prints the wall time, the
# real-time factor and particle-steps per second. Record results in bench/results.md.
#   bench/run_sag_benchmark.sh [THREADS] [OUTPUT_DIRECTORY] [--set KEY=VALUE ...]
# (default: 1 thread; --set as for `millsim run`). Issue 5's target 1 fixes the time step at
# 1/15 of the smallest ball-ball contact (`millsim info bench/sag-12m-2d.toml` gives it:
# 0.0008989 s):
#   bench/run_sag_benchmark.sh 2 runs/bench/sag-12m-2d-t15 --set simulation.time_step=5.993e-5
# MILLSIM_BUILD=DIR uses the build in DIR as it is; otherwise this installs what is missing and
# builds build/release first.
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: $0 [THREADS] [OUTPUT_DIRECTORY] [--set KEY=VALUE ...]"
threads=1
out=runs/bench/sag-12m-2d
# The positionals are optional: whatever comes before the first --set.
if [ $# -gt 0 ] && [ "$1" != --set ]; then threads=$1; shift; fi
if [ $# -gt 0 ] && [ "$1" != --set ]; then out=$1; shift; fi
case "$threads" in ''|*[!0-9]*|0) echo "$usage (THREADS: a whole number from 1)" >&2; exit 2 ;; esac
for argument in "$@"; do
  case "$argument" in --set|*=*) ;; *) echo "$usage (\"$argument\" is not --set KEY=VALUE)" >&2; exit 2 ;; esac
done
build=${MILLSIM_BUILD:-build/release}
if [ -z "${MILLSIM_BUILD:-}" ]; then
  bash scripts/install-deps.sh
  cmake --preset release >/dev/null
  cmake --build --preset release --target millsim >/dev/null
fi
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//'), $threads thread(s)"
echo "millsim: $build ($("$build/millsim" --version))"
"$build/millsim" run -q -j "$threads" bench/sag-12m-2d.toml --out "$out" "$@"
# Real-time factor: simulated mill seconds (settling included) per wall second; and the same for
# the turning alone (after settling: the spin-up and the revolutions).
settle=$(awk -F'= *' '/^settle_time/ {print $2 + 0}' bench/sag-12m-2d.toml)
for argument in "$@"; do  # a --set of the settling time replaces the file's
  case "$argument" in simulation.settle_time=*) settle=${argument#simulation.settle_time=} ;; esac
done
awk -F'[:,]' -v settle="$settle" \
  '/"simulated_seconds"/ {s = $2} /"wall_seconds"/ {w = $2} /"settle_wall_seconds"/ {ws = $2}
  END {printf "simulated %.2f s in %.1f s of wall time: real-time factor %.3f\n", s, w, s / w
       printf "turning (after %.2f s of settling in %.1f s): %.2f s in %.1f s, real-time factor %.3f\n",
              settle, ws, s - settle, w - ws, (s - settle) / (w - ws)}' \
  "$out/summary.json"
