#!/usr/bin/env bash
# Installs, with apt-get, whatever millsim needs to build and test that is not yet installed,
# and the Debian packages named as arguments (the checks' scripts: tidy.sh, tsan.sh, fuzz.sh).
# Debian 12 packages only. Run by run-example.sh, test.sh and those; safe to run again.
#   scripts/install-deps.sh [PACKAGE ...]
set -euo pipefail

packages=(g++ cmake ninja-build pkg-config libtomlplusplus-dev libcli11-dev libfmt-dev
          libomp-dev libgtest-dev googletest libbenchmark-dev "$@")
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "millsim: installing ${missing[*]}" >&2
  if [ "$(id -u)" -ne 0 ]; then
    echo "millsim: these Debian packages are missing and installing them needs root: ${missing[*]}" >&2
    echo "         run this script as root, or: sudo apt-get install ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
