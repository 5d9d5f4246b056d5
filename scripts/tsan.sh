#!/usr/bin/env bash
# The Determinism tests (1, 2 and 3 threads give the same bits) under ThreadSanitizer: clang,
# libomp with its Archer tool (which tells TSan about OpenMP's barriers), the tsan preset; any
# data race in millsim's code fails the run (tests/tsan.supp says what is not reported). CI runs
# it after clang-tidy (a few minutes on two cores).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh clang libclang-rt-14-dev libomp-14-dev
cmake --preset tsan >/dev/null
cmake --build --preset tsan
ctest --preset tsan
