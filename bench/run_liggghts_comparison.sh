#!/usr/bin/env bash
# Issue 5, target 2: millsim against LIGGGHTS (Debian package `liggghts`) on the same 3D mill
# (bench/mill-3d-20k.toml: 0.9 m x 0.73 m, eight 4 x 4 cm lifters, flat end plates, 19 956
# balls of 20 mm, 30 % filling, 75 % of critical, dt 1e-5 s, the same k_n, k_s, e, mu).
#
#   bench/run_liggghts_comparison.sh [STEPS [ROUNDS]]        speed (about 40 s a round)
#   bench/run_liggghts_comparison.sh --power [LIFT [WINDOW]]   power drawn (about 10 min)
#
# Both: install LIGGGHTS with apt-get if `liggghts` is missing (needs root), build millsim,
# settle the charge once with millsim (simulation.settle_time = 0.4 s, shell still) and save
# the state (kept in the work directory and reused while the settle command is the same); the
# LIGGGHTS runs start from that state. bench/liggghts/make_input.py writes the LIGGGHTS input:
# STL shell + lifters + end plates turned by `fix move/mesh rotate`, the balls, and
# `hooke/stiffness` + `tangential history` with the same stiffnesses and friction and
# millsim's Corkum damping converted to LIGGGHTS' gamman/gammat (see that file).
#
# Speed: the shell turns at full speed for 1000 untimed steps, then STEPS (default 5000) steps
# are timed: millsim on 1 thread, LIGGGHTS on 1 MPI rank, millsim on 2 threads, LIGGGHTS on 2
# ranks, back to back; ROUNDS times (default 3), so that each ratio is of two runs minutes
# apart at most, and a shared machine's slow minute shows as one round out of line. Prints
# particle-steps/s (LIGGGHTS: atoms x steps / loop time of the timed `run`) and the ratio
# millsim/LIGGGHTS of each round, then each code's median rate and the median of the ratios.
#
# Power (not timed, so the two codes run at the same time, each on one core; millsim's result
# does not depend on its thread count): from the settled state the shell turns at full speed at
# once, LIFT steps (default 30000, 0.3 s) lift the charge, then the drive power is averaged
# over WINDOW steps (default 20000, 0.2 s). millsim: bench/liggghts/millsim_power_window.cpp
# (built here with g++ against the millsim build), the shell's work per second as in millsim's
# power_kw; LIGGGHTS: minus the torque about the axis of the balls on the mesh
# (`fix mesh/surface/stress`) times omega.
#
# Environment: MILLSIM_BUILD (a build directory to use as it is; default build/release, built
# with the release preset), MILLSIM_SOURCE (the source tree of that build, default this one),
# LIGGGHTS_WORK (work directory, default runs/liggghts-comparison), SETTLE_TIME (s, default 0.4),
# MILL_CONFIG (the mill, default bench/mill-3d-20k.toml; both codes read it, so a copy with
# another simulation.time_step compares them at that step; it must give a step in seconds, not
# "auto"). Needs python3 (for make_input.py; installed with apt-get if missing).
set -euo pipefail
cd "$(dirname "$0")/.."

steps=5000
mode=speed
lift=30000
window=20000
numbers=()
for arg in "$@"; do
  case "$arg" in
    --power) mode=power ;;
    ''|*[!0-9]*) echo "usage: $0 [STEPS [ROUNDS]] | $0 --power [LIFT [WINDOW]]" >&2; exit 2 ;;
    *) numbers+=("$arg") ;;
  esac
done
rounds=3
if [ "${#numbers[@]}" -gt 2 ]; then
  echo "usage: $0 [STEPS [ROUNDS]] | $0 --power [LIFT [WINDOW]]: at most two numbers" >&2
  exit 2
fi
if [ "$mode" = speed ]; then
  steps=${numbers[0]:-$steps}
  rounds=${numbers[1]:-$rounds}
  if [ "$steps" -eq 0 ] || [ "$rounds" -eq 0 ]; then
    echo "usage: $0 [STEPS [ROUNDS]]: both at least 1" >&2
    exit 2
  fi
else
  lift=${numbers[0]:-$lift}
  window=${numbers[1]:-$window}
  # LIGGGHTS averages the torque over blocks of 100 steps counted from step 0 (make_input.py's
  # fix ave/time), so the lift and the window are whole blocks: a lift of 150 would average
  # half the window, one of 50 nothing. The lift may be 0 (the window then starts as the shell
  # starts to turn).
  if [ $((10#$lift % 100)) -ne 0 ]; then
    echo "usage: $0 --power [LIFT [WINDOW]]: LIFT must be a multiple of 100 steps, not $lift" >&2
    exit 2
  fi
  if [ $((10#$window)) -eq 0 ] || [ $((10#$window % 100)) -ne 0 ]; then
    echo "usage: $0 --power [LIFT [WINDOW]]: WINDOW must be a positive multiple of 100 steps," \
      "not $window" >&2
    exit 2
  fi
fi
warmup=1000
settle=${SETTLE_TIME:-0.4}
config=${MILL_CONFIG:-bench/mill-3d-20k.toml}
work=${LIGGGHTS_WORK:-runs/liggghts-comparison}
build=${MILLSIM_BUILD:-build/release}

echo "== machine: $(nproc) cores; load average $(cut -d' ' -f1-3 /proc/loadavg) (1, 5, 15 min)"

# --- LIGGGHTS from Debian -------------------------------------------------------------------
if ! command -v liggghts >/dev/null; then
  if [ "$(id -u)" != 0 ]; then echo "liggghts is missing; run as root to install it" >&2; exit 1; fi
  apt-cache search liggghts
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends liggghts \
    || { apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends liggghts; }
fi
echo "== $(dpkg-query -W -f '${Package} ${Version}' liggghts 2>/dev/null || echo liggghts)"
# make_input.py needs Python 3.11 (tomllib), Debian 12's python3, which liggghts does not pull in.
if ! command -v python3 >/dev/null; then
  if [ "$(id -u)" != 0 ]; then echo "python3 is missing; run as root to install it" >&2; exit 1; fi
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends python3 \
    || { apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends python3; }
fi

# --- millsim -----------------------------------------------------------------------------------
if [ -z "${MILLSIM_BUILD:-}" ]; then
  bash scripts/install-deps.sh >/dev/null
  cmake --preset release >/dev/null
  cmake --build --preset release --target millsim millsim_scene_bench >/dev/null
fi  # a given MILLSIM_BUILD is used as it is (not rebuilt)
bench="$build/bench/millsim_scene_bench"
millsim="$build/millsim"
src=${MILLSIM_SOURCE:-.}
# The revision the binaries were built from, and the tree whose headers --power compiles against.
echo "== millsim: $build ($("$millsim" --version); source $src: $(git -C "$src" rev-parse --short HEAD 2>/dev/null || echo 'not a git tree')$(git -C "$src" diff --quiet HEAD 2>/dev/null || echo ', with uncommitted changes'))"

mkdir -p "$work"
work=$(cd "$work" && pwd)
state="$work/settled.state"

settle_cmd=("$bench" "$config" --set simulation.settle_time=$settle --warmup 0 --steps 1 -j 1
            --save-state "$state")
# Reused while the command and the config's text are the same.
settle_key="${settle_cmd[*]:1} config md5 $(md5sum < "$config" | cut -d' ' -f1)"
if [ -f "$state" ] && [ "$(cat "$work/settled.cmd" 2>/dev/null)" = "$settle_key" ]; then
  echo "== settled state: reusing $state"
else
  echo "== settling with millsim (settle_time $settle s, 1 thread: the same state for any count)"
  rm -f "$work/settled.cmd"
  "${settle_cmd[@]}" | grep -E '^(particles|prepared)'
  echo "$settle_key" > "$work/settled.cmd"
fi

rate_of_millsim() { awk '/^particle-steps\/s/ {print $2}' "$1"; }
# LIGGGHTS: natoms x steps / loop time of the last `run` (the timed one).
rate_of_liggghts() {
  awk '/^Loop time of/ {t = $4; n = $9; a = $12} END {printf "%.4g\n", a * n / t}' "$1"
}

if [ "$mode" = speed ]; then
  python3 bench/liggghts/make_input.py "$config" "$state" "$work/timing" \
    --mode timing --warmup $warmup --steps "$steps"
  declare -A ms lg
  for round in $(seq 1 "$rounds"); do
    for n in 1 2; do
      echo "== round $round of $rounds: millsim, $n thread(s): $warmup warmup + $steps timed steps"
      "$bench" "$config" --load-state "$state" --warmup $warmup --steps "$steps" -j $n \
        | tee "$work/millsim-$n-$round.txt" | grep -E '^(timed|particle-steps)'
      ms[$n,$round]=$(rate_of_millsim "$work/millsim-$n-$round.txt")
      echo "== round $round of $rounds: LIGGGHTS, $n MPI rank(s): $warmup warmup + $steps timed steps"
      (cd "$work/timing" && mpirun --allow-run-as-root --oversubscribe --bind-to none -np $n liggghts \
        -in in.mill -log "log.np$n.$round" > "screen.np$n.$round")
      grep '^Loop time of' "$work/timing/log.np$n.$round" | tail -1
      lg[$n,$round]=$(rate_of_liggghts "$work/timing/log.np$n.$round")
    done
  done
  # The middle value (the mean of the two middle ones for an even count).
  median() { printf '%s\n' "$@" | sort -g | awk '{v[NR] = $1} END {
    printf "%.4g\n", NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
  echo
  echo "== particle-steps per second ($steps timed steps after $warmup at full speed;" \
    "load average now $(cut -d' ' -f1-3 /proc/loadavg))"
  printf '%-7s %-7s %14s %14s %18s\n' cores round millsim LIGGGHTS millsim/LIGGGHTS
  for n in 1 2; do
    ratios=()
    for round in $(seq 1 "$rounds"); do
      ratio=$(awk -v a="${ms[$n,$round]}" -v b="${lg[$n,$round]}" 'BEGIN {printf "%.2f", a / b}')
      ratios+=("$ratio")
      printf '%-7s %-7s %14s %14s %18s\n' "$n" "$round" "${ms[$n,$round]}" "${lg[$n,$round]}" "$ratio"
    done
    mine=(); theirs=()
    for round in $(seq 1 "$rounds"); do mine+=("${ms[$n,$round]}"); theirs+=("${lg[$n,$round]}"); done
    printf '%-7s %-7s %14s %14s %18s\n' "$n" median "$(median "${mine[@]}")" \
      "$(median "${theirs[@]}")" "$(median "${ratios[@]}")"
  done
  exit 0
fi

# --- power -------------------------------------------------------------------------------------
source_dir=${MILLSIM_SOURCE:-.}
driver="$work/millsim_power_window"
g++ -std=c++20 -O3 -DNDEBUG -fno-math-errno -Wno-psabi -fopenmp -DFMT_SHARED -DTOML_HEADER_ONLY=0 \
  -DTOML_SHARED_LIB=1 -I"$source_dir/src" -I"$build/generated" \
  bench/liggghts/millsim_power_window.cpp "$build/libmillsim_core.a" -ltomlplusplus -lfmt \
  -o "$driver"
echo "== power: $lift steps at full speed from the settled state, then $window steps averaged;" \
  "millsim (1 thread) and LIGGGHTS (1 rank) at the same time"
"$driver" "$config" "$state" "$lift" "$window" 1 > "$work/millsim-power.txt" &
millsim_pid=$!
python3 bench/liggghts/make_input.py "$config" "$state" "$work/power" --mode power \
  --lift "$lift" --window "$window"
(cd "$work/power" && mpirun --allow-run-as-root --oversubscribe --bind-to none -np 1 liggghts \
  -in in.mill -log log.power > screen.power)
wait "$millsim_pid"
cat "$work/millsim-power.txt"
omega=$(awk '/rad\/s, dt =/ {for (i = 1; i <= NF; i++) if ($i == "rad/s,") print $(i - 1)}' \
  "$work/power/in.mill")
# torque.txt: step, mean torque of the balls on the mesh about +z over 100 steps.
liggghts_torque=$(awk '!/^#/ {s += $2; n++} END {printf "%.5f", s / n}' "$work/power/torque.txt")
echo "LIGGGHTS: torque of the balls on the mesh $liggghts_torque N m (omega $omega rad/s)"
echo
echo "== drive power, kW, mean over $window steps after $lift at full speed"
echo "millsim   $(awk '/^power_kw/ {print $2}' "$work/millsim-power.txt")"
echo "LIGGGHTS  $(awk -v t="$liggghts_torque" -v w="$omega" 'BEGIN {printf "%.5f", -t * w / 1000}')"
