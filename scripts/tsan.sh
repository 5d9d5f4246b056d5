#!/usr/bin/env bash
# The whole test suite under ThreadSanitizer: clang, libomp with its Archer tool (which tells TSan
# about OpenMP's barriers), the tsan preset; any data race in millsim's code fails the run.
# libomp itself is not built with TSan; ignore_noninstrumented_modules (the preset's TSAN_OPTIONS)
# leaves its own memory handling unreported, and nothing else is suppressed. CI runs it after
# clang-tidy (about 5 minutes on two cores, most of it the build).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh clang libclang-rt-14-dev libomp-14-dev
cmake --preset tsan >/dev/null
cmake --build --preset tsan
ctest --preset tsan
