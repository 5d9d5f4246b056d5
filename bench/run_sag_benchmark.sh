#!/usr/bin/env bash
# Runs the paper's headline 2D scene (bench/sag-12m-2d.toml: 12 m SAG mill, ~7 200 discs,
# 2 s of settling + two revolutions at 5 rpm = 24 s of turning) on one core and prints the wall
# time, the real-time factor and particle-steps per second. Record results in bench/results.md.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target millsim >/dev/null
out=${1:-runs/bench/sag-12m-2d}
./build/release/millsim run -q bench/sag-12m-2d.toml --out "$out"
python3 - "$out/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
print(f"machine: {open('/proc/cpuinfo').read().split('model name')[1].split(':')[1].splitlines()[0].strip()}")
print(f"discs {s['particle_count']}, time step {s['time_step_s']:.4g} s, steps {s['steps']}")
print(f"simulated {s['simulated_seconds']:.2f} s in {s['wall_seconds']:.1f} s of wall time: "
      f"real-time factor {s['simulated_seconds'] / s['wall_seconds']:.3f}")
print(f"particle-steps per second {s['particle_steps_per_second']:.4g}")
print(f"power {s['power_kw']:.5g} kW (dissipation {s['power_dissipation_kw']:.5g} kW)")
PY
