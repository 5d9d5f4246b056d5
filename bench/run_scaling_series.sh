#!/usr/bin/env bash
# Issue 5, target 3: particle-steps per second from 1e3 to 1e6 balls (3D), and memory per
# particle. Settling 1e6 balls from random placement is far too expensive, so the series tiles
# a settled periodic slab (bench/scaling-mill.toml: 996 balls of 10 mm in a 0.041 m slab of a
# 0.3 m mill at 75 % of critical, dt 1.516e-5 s = 1/15 of the ball-ball contact):
#
#   1. settle the slab once (0.8 s, shell still), turn it 33 000 steps (0.5 s, half a
#      revolution) and save the state (kept in the work directory, reused while the command is
#      the same);
#   2. for K = 1, 10, 100, 1000 (996 ... 996 000 balls) start from that state with
#      `millsim_scene_bench --load-state ... --tile K`: K copies of the slab end to end, a slab
#      K times longer; a warmup, then a fixed number of timed steps (fewer for larger K, at
#      least four neighbour-list rebuilds);
#   3. the same with --shuffle (the particles' order in memory drawn at random) at K = 1 and
#      K = 1000: tiling copies the base slab's memory order in blocks, which keeps neighbours in
#      space near in memory; a freshly placed 1e6 charge has no such luck.
#
# The ordered series (step 2) runs ROUNDS times (default 3), one round after another, so that a
# shared machine's slow minute falls on one run of a point, not on the point: each point's rate
# is the median of its rounds. Prints one row per run (particles, steps, wall and CPU seconds,
# particle-steps per wall and per CPU second, bytes per particle: resident growth and the array
# estimate, neighbour-list rebuilds), then each point's median rates and the ratio of the
# slowest to the fastest of them. CPU time is the figure to read on a shared machine. About a
# minute a round on one thread (once the base slab is
# saved); 1.1 GB of resident growth at the largest point (1068 B per ball at d9cbdac, 972 B before
# the skin's 45 steps of cf7bec7, 1003 B at f300219, 1030 B at b13b5d1, 1199 B at a6911f1, 1.84 GB
# before 5635d51).
#
#   bench/run_scaling_series.sh [THREADS [ROUNDS]]     (default: 1 thread, 3 rounds)
#
# Environment: MILLSIM_BUILD (a build directory to use as it is; default build/release, built
# with the release preset), SCALING_WORK (work directory for the state and the full outputs,
# default runs/bench/scaling).
set -euo pipefail
cd "$(dirname "$0")/.."

threads=${1:-1}
rounds=${2:-3}
for number in "$threads" "$rounds"; do
  case "$number" in ''|*[!0-9]*|0) echo "usage: $0 [THREADS [ROUNDS]] (whole numbers from 1)" >&2; exit 2 ;; esac
done
config=bench/scaling-mill.toml
work=${SCALING_WORK:-runs/bench/scaling}
build=${MILLSIM_BUILD:-build/release}

if [ -z "${MILLSIM_BUILD:-}" ]; then
  bash scripts/install-deps.sh
  cmake --preset release >/dev/null
  cmake --build --preset release --target millsim millsim_scene_bench >/dev/null
fi  # a given MILLSIM_BUILD is used as it is (not rebuilt)
bench="$build/bench/millsim_scene_bench"

echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//'), $(nproc) cores;" \
  "load average $(cut -d' ' -f1-3 /proc/loadavg); $threads thread(s)"
# The revision the binaries were built from (the millsim beside the bench), not the tree's.
echo "millsim: $build ($("$build/millsim" --version))"

mkdir -p "$work"
state="$work/base.state"
base_cmd=("$bench" "$config" --warmup 0 --steps 33000 -j 1 --save-state "$state")
# The state is reused while the command and the config's text are the same (an edited config
# with the same particle count would otherwise load the old charge).
base_key="${base_cmd[*]:1} config md5 $(md5sum < "$config" | cut -d' ' -f1)"
if [ -f "$state" ] && [ "$(cat "$work/base.cmd" 2>/dev/null)" = "$base_key" ]; then
  echo "base slab: reusing $state"
else
  echo "base slab: settling and turning it once (1 thread): ${base_cmd[*]}"
  rm -f "$work/base.cmd"
  "${base_cmd[@]}" > "$work/base.txt"
  grep -E '^(particles|prepared|timed)' "$work/base.txt"
  echo "$base_key" > "$work/base.cmd"
fi

# One run of a point: round, K, warmup steps, timed steps, then extra options. Full output in
# $work.
rates=()
point() {
  local round=$1 tile=$2 warmup=$3 steps=$4
  shift 4
  local name="tile-$tile${1:+-${1#--}}-j$threads-r$round"
  "$bench" "$config" --load-state "$state" --tile "$tile" --warmup "$warmup" --steps "$steps" \
    -j "$threads" "$@" > "$work/$name.txt"
  awk -v tile="$tile" -v round="$round" -v extra="${*:-}" '
    /^particles /           { n = $2 }
    /^timed steps/          { steps = $3; wall = $5; cpu = $10; sub(/^\(/, "", cpu) }
    /^particle-steps\/s/    { rate_wall = $2; rate_cpu = $5 }
    /^neighbour rebuilds/   { rebuilds = $3 }
    /^memory\/particle/     { resident = $2 }
    /^memory estimate/      { estimate = $3 }
    END { printf "| %d%s | %d | %d | %d | %.1f | %.1f | %.3g | %.3g | %d | %d | %d |\n", tile,
            extra == "" ? "" : " " extra, round, n, steps, wall, cpu, rate_wall, rate_cpu,
            resident, estimate, rebuilds }' "$work/$name.txt" | tee -a "$work/table-j$threads.md"
  [ -z "${1:-}" ] && rates+=("$tile $(awk '/^particle-steps\/s/ {print $5, $2}' "$work/$name.txt")")
  return 0
}

echo
echo "| K | round | particles | timed steps | wall s | CPU s | particle-steps/s (wall) | particle-steps/s (CPU) | bytes/particle (resident) | bytes/particle (arrays) | rebuilds |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
: > "$work/table-j$threads.md"
for round in $(seq 1 "$rounds"); do
  point "$round" 1 2000 100000
  point "$round" 10 500 10000
  point "$round" 100 100 1000
  point "$round" 1000 50 300
done
point 1 1 2000 100000 --shuffle
point 1 1000 50 300 --shuffle

# Each point's median over the rounds (the mean of the middle two for an even count), then the
# slowest and fastest of those.
printf '%s\n' "${rates[@]}" | sort -k1,1n -k2,2g | awk '
  function median(v, n) { return n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2 }
  { tile[$1] = 1; count[$1]++; cpu[$1, count[$1]] = $2; wall_of[$1, count[$1]] = $3 }
  END {
    printf "\n| K | runs | median particle-steps/s (wall) | median particle-steps/s (CPU) |\n"
    printf "|---|---|---|---|\n"
    first = 1
    for (k = 1; k <= 1000; k *= 10) {
      if (!(k in tile)) continue
      n = count[k]
      for (i = 1; i <= n; i++) { c[i] = cpu[k, i]; w[i] = wall_of[k, i] }
      # sort both lists of this point (n is small)
      for (i = 2; i <= n; i++) for (j = i; j > 1 && c[j] < c[j - 1]; j--) { t = c[j]; c[j] = c[j - 1]; c[j - 1] = t }
      for (i = 2; i <= n; i++) for (j = i; j > 1 && w[j] < w[j - 1]; j--) { t = w[j]; w[j] = w[j - 1]; w[j - 1] = t }
      mc = median(c, n); mw = median(w, n)
      printf "| %d | %d | %.3g | %.3g |\n", k, n, mw, mc
      if (first || mc < cpu_low) cpu_low = mc
      if (first || mc > cpu_high) cpu_high = mc
      if (first || mw < wall_low) wall_low = mw
      if (first || mw > wall_high) wall_high = mw
      first = 0
    }
    printf "\nordered series, K = 1 ... 1000, slowest / fastest of the medians:" \
           " %.3f per CPU second, %.3f per wall second (issue 5: within 30 %%:\n" \
           "  at least 0.70 of the fastest; 0.77 if read as fastest / slowest <= 1.3)\n",
           cpu_low / cpu_high, wall_low / wall_high
  }'
