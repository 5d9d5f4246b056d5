#!/usr/bin/env bash
# The Determinism tests (1, 2 and 3 threads give the same bits) under ThreadSanitizer: clang,
# libomp with its Archer tool (which tells TSan about OpenMP's barriers), the tsan preset; any
# data race in millsim's code fails the run (tests/tsan.supp says what is not reported). CI runs
# it after clang-tidy (a few minutes on two cores).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
packages=(clang libclang-rt-14-dev libomp-14-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -ne 0 ]; then
    echo "millsim: the TSan build needs ${missing[*]}; run as root, or: sudo apt-get install ${missing[*]}" >&2
    exit 1
  fi
  echo "millsim: installing ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
cmake --preset tsan >/dev/null
cmake --build --preset tsan
ctest --preset tsan
