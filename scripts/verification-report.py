#!/usr/bin/env python3
"""Runs the oblique-impact verification scenes and writes docs/verification/oblique-impact.csv,
docs/verification/oblique-impact.svg and the markdown table of docs/verification.md (stdout).

usage: scripts/verification-report.py [MILLSIM_BINARY]   (default build/release/millsim)
Only the Python standard library is used (the plot is plain SVG).
"""
import csv
import math
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "verification"
RADIUS, DENSITY, K_N, SPEED, MU = 0.01, 4000.0, 1.0e6, 3.9, 0.1
MASS = DENSITY * math.pi * (2 * RADIUS) ** 3 / 6


def effective_restitution(e, m=MASS, k=K_N):
    """No-tension restitution of the linear spring-dashpot (docs/model.md)."""
    if e >= 1.0:
        return 1.0
    z = -math.log(e) / math.sqrt(math.log(e) ** 2 + math.pi**2)
    a = math.asin(z)
    return math.exp(-math.tan(a) * (math.pi - 2 * a))


def run(binary, scene, directory):
    subprocess.run([binary, "run", "-q", str(ROOT / "examples" / "verification" / f"{scene}.toml"),
                    "--out", str(directory)], check=True, stdout=subprocess.DEVNULL)
    rows = list(csv.DictReader(open(directory / "final.csv")))
    out = []
    for k, r in enumerate(rows):
        angle = math.radians(5 * (k + 1))
        vn, vt = SPEED * math.cos(angle), SPEED * math.sin(angle)
        out.append(dict(angle=5 * (k + 1), en=float(r["vz"]) / vn, et=float(r["vx"]) / vt,
                        spin=float(r["wy"]) * RADIUS / SPEED,
                        rebound=math.degrees(math.atan2(float(r["vx"]), float(r["vz"])))))
    return out


def analytic(angle_deg, e_eff, stick_closed_form):
    """Gross-sliding answers, and for the elastic k_s = 2k_n/7 scene the sticking ones; None
    where the linear model has no closed form (partial slip)."""
    a = math.radians(angle_deg)
    t = math.tan(a)
    imp = MU * (1 + e_eff)
    if t >= 3.5 * imp:
        et = 1 - imp / t
        return dict(et=et, spin=2.5 * imp * math.cos(a),
                    rebound=math.degrees(math.atan((t - imp) / e_eff)))
    if stick_closed_form and t <= 3.5 * MU:
        return dict(et=3 / 7, spin=10 * math.sin(a) / 7,
                    rebound=math.degrees(math.atan(3 / 7 * t / e_eff)))
    return None


def svg_plot(series, path):
    """Three panels: tangential restitution, normalised spin R w / v, rebound angle."""
    panels = [("et", "tangential restitution v_t'/v_t", 0.0, 1.0),
              ("spin", "rebound spin R ω'/v", 0.0, 0.5),
              ("rebound", "rebound angle (deg)", 0.0, 90.0)]
    W, H, L, B, T, R = 330, 270, 50, 40, 25, 10
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{3 * W}" height="{H + 30}" '
             'font-family="sans-serif" font-size="11">', '<rect width="100%" height="100%" fill="white"/>']
    for p, (key, title, lo, hi) in enumerate(panels):
        x0 = p * W + L
        w, h = W - L - R, H - B - T
        X = lambda a: x0 + w * a / 90.0
        Y = lambda v: T + h * (1 - (v - lo) / (hi - lo))
        parts.append(f'<rect x="{x0}" y="{T}" width="{w}" height="{h}" fill="none" stroke="black"/>')
        parts.append(f'<text x="{x0 + w / 2}" y="{T - 8}" text-anchor="middle">{title}</text>')
        for a in range(0, 91, 15):
            parts.append(f'<line x1="{X(a)}" y1="{T + h}" x2="{X(a)}" y2="{T + h + 4}" stroke="black"/>'
                         f'<text x="{X(a)}" y="{T + h + 16}" text-anchor="middle">{a}</text>')
        for k in range(5):
            v = lo + (hi - lo) * k / 4
            parts.append(f'<line x1="{x0 - 4}" y1="{Y(v)}" x2="{x0}" y2="{Y(v)}" stroke="black"/>'
                         f'<text x="{x0 - 6}" y="{Y(v) + 4}" text-anchor="end">{v:g}</text>')
        parts.append(f'<text x="{x0 + w / 2}" y="{T + h + 32}" text-anchor="middle">incidence angle (deg)</text>')
        for name, colour, points, curve in series:
            # Analytic curve: a fine line where a closed form exists.
            segment = []
            for i in range(1, 900):
                a = i / 10
                value = curve(a)
                if value is None:
                    if len(segment) > 1:
                        parts.append(f'<polyline fill="none" stroke="{colour}" stroke-width="1.2" points="{" ".join(segment)}"/>')
                    segment = []
                    continue
                segment.append(f"{X(a):.1f},{Y(value[key]):.1f}")
            if len(segment) > 1:
                parts.append(f'<polyline fill="none" stroke="{colour}" stroke-width="1.2" points="{" ".join(segment)}"/>')
            for pt in points:
                parts.append(f'<circle cx="{X(pt["angle"]):.1f}" cy="{Y(pt[key]):.1f}" r="3" fill="none" stroke="{colour}"/>')
    y = H + 20
    for i, (name, colour, _, _) in enumerate(series):
        parts.append(f'<circle cx="{60 + 500 * i}" cy="{y - 4}" r="3" fill="none" stroke="{colour}"/>'
                     f'<text x="{70 + 500 * i}" y="{y}">{name}: millsim (circles), closed form (line)</text>')
    parts.append("</svg>")
    path.write_text("\n".join(parts) + "\n")


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "build" / "release" / "millsim")
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        damped = run(binary, "oblique-impact-angles", pathlib.Path(tmp) / "a")
        elastic = run(binary, "oblique-impact-angles-elastic", pathlib.Path(tmp) / "b")
    e_eff = effective_restitution(0.5)
    with open(OUT / "oblique-impact.csv", "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["scene", "incidence_deg", "normal_restitution", "tangential_restitution",
                      "spin_R_w_over_v", "rebound_deg", "closed_form_tangential_restitution",
                      "closed_form_spin", "closed_form_rebound_deg"])
        for scene, rows, e, stick in (("e=0.5", damped, e_eff, False), ("e=1,ks=2kn/7", elastic, 1.0, True)):
            for r in rows:
                c = analytic(r["angle"], e, stick)
                out.writerow([scene, r["angle"], f'{r["en"]:.5f}', f'{r["et"]:.5f}', f'{r["spin"]:.5f}',
                              f'{r["rebound"]:.3f}'] +
                             ([f'{c["et"]:.5f}', f'{c["spin"]:.5f}', f'{c["rebound"]:.3f}'] if c else ["", "", ""]))
    svg_plot([("e = 0.5, k_s = 2k_n/3", "#c03020", damped, lambda a: analytic(a, e_eff, False)),
              ("e = 1, k_s = 2k_n/7", "#2050c0", elastic, lambda a: analytic(a, 1.0, True))],
             OUT / "oblique-impact.svg")
    print("| incidence (°) | e=0.5: v_t'/v_t | closed form | R ω'/v | closed form | rebound (°) | closed form "
          "| e=1: v_t'/v_t | closed form | R ω'/v | closed form |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for d, el in zip(damped, elastic):
        c = analytic(d["angle"], e_eff, False)
        ce = analytic(el["angle"], 1.0, True)
        f = lambda c, k, p=4: f"{c[k]:.{p}f}" if c else "—"
        print(f'| {d["angle"]} | {d["et"]:.4f} | {f(c, "et")} | {d["spin"]:.4f} | {f(c, "spin")} | '
              f'{d["rebound"]:.2f} | {f(c, "rebound", 2)} | {el["et"]:.4f} | {f(ce, "et")} | '
              f'{el["spin"]:.4f} | {f(ce, "spin")} |')


if __name__ == "__main__":
    main()
