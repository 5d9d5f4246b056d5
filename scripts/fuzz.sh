#!/usr/bin/env bash
# Fuzzes config reading (fuzz/README.md): builds the libFuzzer target with clang and the address
# and undefined-behaviour sanitizers (the fuzz preset) and runs it for SECONDS (default 600),
# starting from fuzz/corpus and the shipped configs. New interesting inputs go to
# build/fuzz/work, a failing input to build/fuzz/found/ (with libFuzzer's report on stderr).
#   scripts/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
case "$seconds" in ''|*[!0-9]*|0) echo "usage: $0 [SECONDS]" >&2; exit 2 ;; esac
bash scripts/install-deps.sh clang libclang-rt-14-dev libomp-14-dev
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz
mkdir -p build/fuzz/work build/fuzz/found build/fuzz/seeds
cp examples/*.toml examples/*/*.toml bench/*.toml build/fuzz/seeds/
# One thread: OpenMP's threads only add noise to a fuzzer's coverage.
OMP_NUM_THREADS=1 build/fuzz/millsim_config_fuzzer build/fuzz/work fuzz/corpus build/fuzz/seeds \
  -dict=fuzz/config.dict -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 \
  -max_len=4096 -artifact_prefix=build/fuzz/found/ -print_final_stats=1
