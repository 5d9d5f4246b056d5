#!/usr/bin/env python3
"""Writes a LIGGGHTS input for the same mill as a millsim 3D config (bench/mill-3d-20k.toml).

Used by bench/run_liggghts_comparison.sh. Standard library only.

  make_input.py CONFIG STATE OUTDIR --mode timing --warmup W --steps N
  make_input.py CONFIG STATE OUTDIR --mode power

CONFIG  the millsim TOML (mill, lifters, charge, materials, time step are read from it)
STATE   a state written by `millsim_scene_bench CONFIG --save-state FILE` after settling: the
        balls start where millsim's settled charge lies (same positions, velocities, spins)
OUTDIR  gets mill.stl (shell + lifters + end plates), mill.data (the balls) and in.mill

Geometry, in millsim's frame: mill axis z from 0 to L, gravity -y, the shell turning
counter-clockwise about +z, lifter k centred at angle 2 pi k / n (millsim's shell angle 0 is
where its settled state was saved; the state file holds the angle and the mesh is written
turned to it). Each lifter is a flat bar: inner face at radius R - h, side faces at +-w/2 from
its centre line, running the full length (millsim's box lifter; the part beyond the shell is
unreachable and left open). The shell is a 180-gon with its vertices on the circle (the flats
lie up to R (1 - cos 1 deg) = 69 um inside it), each face one full-length pair of triangles;
end plates are flat squares (4 x 4 cells) wider than the shell at z = 0 and z = L; all in one
mesh (472 triangles) that turns with `fix move/mesh ... rotate`. Few, long triangles keep
LIGGGHTS' mesh work small (a 9760-triangle version ran slower).

Contact model (docs/model.md): linear spring-dashpot, Coulomb friction, no rolling resistance.
LIGGGHTS `model hooke/stiffness tangential history`, with absolute_damping off, applies
    F_n = k_n delta - (m_eff * gamman) v_n,  F_t (spring) = -k_t s,  F_t damping = -(m_eff * gammat) v_t
so gamman and gammat are damping coefficients PER UNIT EFFECTIVE MASS (1/s). millsim's Corkum
damping c_n = 2 zeta sqrt(k_n m*), zeta = -ln e / sqrt(ln^2 e + pi^2), and c_s = 2 zeta
sqrt(k_s m*), therefore
    gamman = c_n / m* = 2 zeta sqrt(k_n / m*),   gammat = c_s / m* = 2 zeta sqrt(k_s / m*)
with m* = m/2 for two equal balls (type 1-1) and m* = m for a ball on the wall (type 1-2; a
mesh wall has infinite mass, LIGGGHTS then uses m_eff = m of the ball). With one ball size this
is exact per type pair. limitForce on gives millsim's no-tension rule (the normal force is
clipped at zero).
"""
import argparse
import math
import struct
import tomllib
from pathlib import Path


def corkum_zeta(e):
    ln = math.log(e)
    return -ln / math.sqrt(ln * ln + math.pi * math.pi)


def read_state(path):
    data = Path(path).read_bytes()
    (count,) = struct.unpack_from("<Q", data, 0)
    offset = 8
    arrays = []
    for _ in range(5):  # position, velocity, angular velocity, force, torque
        values = struct.unpack_from("<%dd" % (3 * count), data, offset)
        offset += 24 * count
        arrays.append([values[3 * i:3 * i + 3] for i in range(count)])
    (angle,) = struct.unpack_from("<d", data, offset)
    offset += 8
    if offset != len(data):
        raise SystemExit(f"{path}: {len(data)} bytes, expected {offset} for {count} balls")
    return arrays[0], arrays[1], arrays[2], angle


def facet(out, a, b, c):
    ux, uy, uz = (b[i] - a[i] for i in range(3))
    vx, vy, vz = (c[i] - a[i] for i in range(3))
    nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
    norm = math.sqrt(nx * nx + ny * ny + nz * nz) or 1.0
    out.append(f"facet normal {nx / norm:.9e} {ny / norm:.9e} {nz / norm:.9e}\n outer loop\n")
    for p in (a, b, c):
        out.append(f"  vertex {p[0]:.9e} {p[1]:.9e} {p[2]:.9e}\n")
    out.append(" endloop\nendfacet\n")


def quad(out, a, b, c, d):
    facet(out, a, b, c)
    facet(out, a, c, d)


def write_mesh(path, radius, length, lifters, height, width, angle,
               shell_segments=180, axial_segments=1, plate_cells=4):
    out = ["solid mill\n"]
    zs = [length * k / axial_segments for k in range(axial_segments + 1)]
    # Shell: a 180-gon with its vertices on the circle.
    for j in range(shell_segments):
        t0 = angle + 2 * math.pi * j / shell_segments
        t1 = angle + 2 * math.pi * (j + 1) / shell_segments
        p0 = (radius * math.cos(t0), radius * math.sin(t0))
        p1 = (radius * math.cos(t1), radius * math.sin(t1))
        for k in range(axial_segments):
            quad(out, (*p0, zs[k]), (*p1, zs[k]), (*p1, zs[k + 1]), (*p0, zs[k + 1]))
    # Lifters: inner face at R - h and two side faces reaching a little beyond the shell.
    inner = radius - height
    outer = radius + 0.25 * height
    half = 0.5 * width
    for n in range(lifters):
        t = angle + 2 * math.pi * n / lifters
        ra = (math.cos(t), math.sin(t))
        tb = (-ra[1], ra[0])

        def at(a, b):
            return (a * ra[0] + b * tb[0], a * ra[1] + b * tb[1])

        corners = [at(outer, -half), at(inner, -half), at(inner, half), at(outer, half)]
        for f in range(3):
            p, q = corners[f], corners[f + 1]
            for k in range(axial_segments):
                quad(out, (*p, zs[k]), (*q, zs[k]), (*q, zs[k + 1]), (*p, zs[k + 1]))
    # End plates: squares a little wider than the shell (their corners lie outside it).
    side = 2.0 * radius + 0.04
    xs = [-0.5 * side + side * k / plate_cells for k in range(plate_cells + 1)]
    for z in (0.0, length):
        for i in range(plate_cells):
            for j in range(plate_cells):
                quad(out, (xs[i], xs[j], z), (xs[i + 1], xs[j], z),
                     (xs[i + 1], xs[j + 1], z), (xs[i], xs[j + 1], z))
    out.append("endsolid mill\n")
    Path(path).write_text("".join(out))
    return sum(1 for line in out if line.startswith("facet"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("config")
    parser.add_argument("state")
    parser.add_argument("outdir")
    parser.add_argument("--mode", choices=["timing", "power"], default="timing")
    parser.add_argument("--warmup", type=int, default=1000)
    parser.add_argument("--steps", type=int, default=5000)
    parser.add_argument("--lift", type=int, default=30000,
                        help="power: steps at full speed before the window")
    parser.add_argument("--window", type=int, default=20000,
                        help="power: steps averaged (a multiple of 100)")
    parser.add_argument("--skin", type=float, default=None,
                        help="neighbour skin, m (default: a quarter of the ball diameter, 5 mm for 20 mm "
                             "balls; LIGGGHTS ran 3000 steps of the bench in 18.1, 19.4 and 18.5 s "
                             "at 5, 2 and 1 mm)")
    args = parser.parse_args()

    cfg = tomllib.loads(Path(args.config).read_text())
    sim, mill, lift, charge = cfg["simulation"], cfg["mill"], cfg["mill"]["lifters"], cfg["charge"]
    mats = cfg["materials"]
    if sim.get("dimension") != 3 or mill.get("periodic", False):
        raise SystemExit("only a whole 3D mill (dimension = 3, not periodic) is supported")
    if "ball_diameter" not in charge:
        raise SystemExit("only one ball size (charge.ball_diameter) is supported")
    dt = float(sim["time_step"])
    diameter = float(mill["diameter"])
    radius = 0.5 * diameter
    length = float(mill["length"])
    d = float(charge["ball_diameter"])
    rho = float(charge.get("density", 7800))
    g = 9.81
    # millsim: N_c = (60 / 2 pi) sqrt(2 g / (D - d)); omega = fraction * 2 pi N_c / 60.
    if "speed" in mill:
        omega = float(mill["speed"]) * math.sqrt(2 * g / (diameter - d))
    else:
        omega = float(mill["speed_rpm"]) * 2 * math.pi / 60
    period = 2 * math.pi / omega
    mass = rho * math.pi * d ** 3 / 6

    def damping(material, m_star):
        z = corkum_zeta(float(material["restitution"]))
        kn, kt = float(material["normal_stiffness"]), float(material["tangential_stiffness"])
        return kn, kt, 2 * z * math.sqrt(kn / m_star), 2 * z * math.sqrt(kt / m_star), z

    bb = damping(mats["ball_ball"], 0.5 * mass)
    bw = damping(mats["ball_wall"], mass)
    mu_bb = float(mats["ball_ball"]["friction"])
    mu_bw = float(mats["ball_wall"]["friction"])
    skin = args.skin if args.skin is not None else 0.25 * d

    positions, velocities, spins, angle = read_state(args.state)
    out = Path(args.outdir)
    out.mkdir(parents=True, exist_ok=True)
    facets = write_mesh(out / "mill.stl", radius, length, int(lift["count"]),
                        float(lift["height"]), float(lift["width"]), angle)

    # The box holds the turning end plates: their corners reach sqrt(2) (R + 0.02).
    lo, hi = -math.sqrt(2.0) * (radius + 0.02) - 0.02, math.sqrt(2.0) * (radius + 0.02) + 0.02
    lines = [f"millsim state {args.state} ({len(positions)} balls)\n\n",
             f"{len(positions)} atoms\n2 atom types\n\n",
             f"{lo} {hi} xlo xhi\n{lo} {hi} ylo yhi\n{-0.05} {length + 0.05} zlo zhi\n\n",
             "Atoms\n\n"]
    lines += [f"{i + 1} 1 {d!r} {rho!r} {p[0]!r} {p[1]!r} {p[2]!r}\n"
              for i, p in enumerate(positions)]
    lines.append("\nVelocities\n\n")
    lines += [f"{i + 1} {v[0]!r} {v[1]!r} {v[2]!r} {w[0]!r} {w[1]!r} {w[2]!r}\n"
              for i, (v, w) in enumerate(zip(velocities, spins))]
    (out / "mill.data").write_text("".join(lines))

    header = f"""# LIGGGHTS input generated by bench/liggghts/make_input.py from {args.config}
# mill D = {diameter} m, L = {length} m, {lift['count']} lifters {lift['height']} x {lift['width']} m,
# {len(positions)} balls of {d} m, {rho} kg/m3 (m = {mass:.6g} kg), {omega:.6g} rad/s, dt = {dt}
# Corkum: zeta(e={mats['ball_ball']['restitution']}) = {bb[4]:.6f}, zeta(e={mats['ball_wall']['restitution']}) = {bw[4]:.6f}
# gamman = 2 zeta sqrt(kn / m*), gammat = 2 zeta sqrt(kt / m*) (per unit effective mass, 1/s);
# m* = m/2 ball-ball (type 1 1), m ball-wall (type 1 2)
atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
processors 1 1 *
units si
read_data mill.data
neighbor {skin} bin
neigh_modify delay 0

fix m1 all property/global kn peratomtypepair 2 {bb[0]!r} {bw[0]!r} {bw[0]!r} {bw[0]!r}
fix m2 all property/global kt peratomtypepair 2 {bb[1]!r} {bw[1]!r} {bw[1]!r} {bw[1]!r}
fix m3 all property/global gamman peratomtypepair 2 {bb[2]!r} {bw[2]!r} {bw[2]!r} {bw[2]!r}
fix m4 all property/global gammat peratomtypepair 2 {bb[3]!r} {bw[3]!r} {bw[3]!r} {bw[3]!r}
fix m5 all property/global coefficientFriction peratomtypepair 2 {mu_bb!r} {mu_bw!r} {mu_bw!r} {mu_bw!r}

pair_style gran model hooke/stiffness tangential history limitForce on
pair_coeff * *
timestep {dt}
fix gravi all gravity {g} vector 0.0 -1.0 0.0

{{mesh_fix}}
fix walls all wall/gran model hooke/stiffness tangential history mesh n_meshes 1 meshes mill limitForce on
fix integr all nve/sphere

{{thermo}}
thermo 1000
thermo_modify lost error norm no
"""
    if args.mode == "timing":
        # Timed without stress tracking (plain mesh/surface): LIGGGHTS at its fastest.
        header = header.replace("{mesh_fix}", "fix mill all mesh/surface file mill.stl type 2")
        header = header.replace("{thermo}", "thermo_style custom step atoms ke cpu")
        body = f"""
fix turn all move/mesh mesh mill rotate origin 0.0 0.0 0.0 axis 0.0 0.0 1.0 period {period!r}
# untimed: the shell at full speed from the settled state (as millsim_scene_bench --warmup)
run {args.warmup}
# timed
run {args.steps}
"""
    else:
        header = header.replace("{mesh_fix}", "fix mill all mesh/surface/stress file mill.stl type 2"
                                " stress on reference_point 0.0 0.0 0.0")
        header = header.replace("{thermo}", "variable torque_z equal f_mill[6]\n"
                                "thermo_style custom step atoms ke f_mill[6] cpu")
        body = f"""
# As millsim_power_window: the shell turning at full speed from the settled state, {args.lift}
# steps to lift the charge, then the torque of the balls on the mesh about +z averaged over
# {args.window} steps (the drive torque is its opposite).
fix turn all move/mesh mesh mill rotate origin 0.0 0.0 0.0 axis 0.0 0.0 1.0 period {period!r}
run {args.lift}
fix torque all ave/time 1 100 100 v_torque_z file torque.txt
run {args.window}
"""
    (out / "in.mill").write_text(header + body)
    print(f"wrote {out}/in.mill, mill.data ({len(positions)} balls), mill.stl ({facets} facets);"
          f" omega {omega:.6g} rad/s, period {period:.6g} s")
    print(f"gamman bb {bb[2]:.6g} bw {bw[2]:.6g}  gammat bb {bb[3]:.6g} bw {bw[3]:.6g} (1/s)")
    if args.mode == "power":
        print(f"power: {args.lift} steps at full speed, then {args.window} steps averaged")


if __name__ == "__main__":
    main()
