#!/usr/bin/env bash
# Compares two builds of millsim_scene_bench on the same scene: paired runs, each pair's order
# alternating (A then B, then B then A), and the ratio B/A of the particle-steps per second of
# each pair; then the median, mean, lowest and highest ratio.
#
#   bench/compare_builds.sh PAIRS BENCH_A BENCH_B -- SCENE_BENCH_ARGUMENTS...
#
# e.g. a build of the last commit against the working tree's, on the 1e6-ball slab:
#   bench/compare_builds.sh 6 /tmp/base/build/release/bench/millsim_scene_bench \
#     build/release/bench/millsim_scene_bench -- bench/scaling-mill.toml \
#     --load-state runs/bench/scaling/base.state --tile 1000 --warmup 30 --steps 100 -j 1
#
# Why pairs: the shared benchmark host's speed moves by 10-25 % within minutes, more than
# most changes; two runs back to back see nearly the same host, and alternating the order
# cancels a steady drift, but not all of it. A build against itself (2026-12-06), one thread:
# the 996-ball slab (60 000 steps) gave medians of 0.999 (four pairs, 0.987-1.018) and 1.007
# (six pairs, 0.983-1.064); the 1e6-ball slab (100 steps), 0.966 (six pairs, 0.899-1.020).
# Read a median within a few per cent of 1 as no change unless every pair agrees, and repeat
# the comparison before believing a small one. BENCH_A and BENCH_B may be any command that
# takes the scene bench's arguments and prints its `particle-steps/s` line (a wrapper script
# setting an environment variable, say). Record what it prints in bench/results.md.
set -euo pipefail
if [ $# -lt 4 ] || [ "$4" != "--" ]; then
  echo "usage: $0 PAIRS BENCH_A BENCH_B -- SCENE_BENCH_ARGUMENTS..." >&2
  exit 2
fi
pairs=$1
case "$pairs" in '' | *[!0-9]* | 0*)
  echo "$0: PAIRS must be a whole number from 1, not '$pairs'" >&2
  exit 2
  ;;
esac
bench_a=$2
bench_b=$3
shift 4
rate_of() {
  local output rate
  output=$("$@" 2>&1) || true
  rate=$(awk '/^particle-steps\/s/ {print $2}' <<< "$output")
  if [ -z "$rate" ]; then
    echo "$0: no particle-steps/s line from: $*" >&2
    tail -n 5 <<< "$output" >&2  # the bench's own message
    exit 1
  fi
  echo "$rate"
}
ratios=()
for pair in $(seq 1 "$pairs"); do
  if ((pair % 2)); then
    a=$(rate_of "$bench_a" "$@")
    b=$(rate_of "$bench_b" "$@")
  else
    b=$(rate_of "$bench_b" "$@")
    a=$(rate_of "$bench_a" "$@")
  fi
  ratio=$(awk -v a="$a" -v b="$b" 'BEGIN {printf "%.4f", b / a}')
  ratios+=("$ratio")
  echo "pair $pair: A $a  B $b  B/A $ratio"
done
printf '%s\n' "${ratios[@]}" | sort -g | awk '
  {r[NR] = $1; sum += $1}
  END {
    median = NR % 2 ? r[(NR + 1) / 2] : (r[NR / 2] + r[NR / 2 + 1]) / 2
    printf "B/A over %d pairs: median %.4f, mean %.4f, lowest %.4f, highest %.4f\n",
           NR, median, sum / NR, r[1], r[NR]
  }'
