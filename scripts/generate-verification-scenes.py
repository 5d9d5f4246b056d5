#!/usr/bin/env python3
"""Writes the verification scene configs in examples/verification/ (docs/verification.md).

The scenes follow the impact benchmarks of Chung & Ooi (2011), "Benchmark tests for verifying
discrete element modelling codes at particle impact level", Granular Matter 13:643-656 (their
geometry and speeds, millsim's linear spring-dashpot with the stated k_n, k_s, e, mu), and the
classic bouncing, free-fall and sliding-to-rolling cases. Re-run it after changing a parameter
here; the configs are committed so that a user never needs this script to run them.
"""
import math
import pathlib

HERE = pathlib.Path(__file__).resolve().parent.parent / "examples" / "verification"

# Alumina sphere of Chung & Ooi's tests: 20 mm, 4000 kg/m3.
DIAMETER = 0.02
RADIUS = DIAMETER / 2
DENSITY = 4000.0
MASS = DENSITY * math.pi * DIAMETER**3 / 6
K_N = 1.0e6  # N/m: contact duration ~0.4 ms for this sphere on a wall
STEPS_PER_CONTACT = 500


def damping_ratio(e):
    return -math.log(e) / math.sqrt(math.log(e) ** 2 + math.pi**2)


def contact_duration(k, m, e):
    z = damping_ratio(e)
    return math.pi / (math.sqrt(k / m) * math.sqrt(1 - z * z))


def fmt(x):
    return repr(float(x))


def vec(v):
    return "[" + ", ".join(fmt(x) for x in v) + "]"


def material(name, k_n, k_s, e, mu):
    return (f"[materials.{name}]\nnormal_stiffness = {fmt(k_n)}\ntangential_stiffness = {fmt(k_s)}\n"
            f"restitution = {fmt(e)}\nfriction = {fmt(mu)}\n")


def particle(position, velocity, spin=None, diameter=DIAMETER, density=DENSITY):
    text = f"[[particles]]\nposition = {vec(position)}\nvelocity = {vec(velocity)}\n"
    if spin is not None:
        text += f"angular_velocity = {spin if isinstance(spin, (int, float)) else vec(spin)}\n"
    return text + f"diameter = {fmt(diameter)}\ndensity = {fmt(density)}\n"


def floor(dimension):
    point = [0.0] * dimension
    normal = [0.0] * (dimension - 1) + [1.0]
    return f"[[walls]]\npoint = {vec(point)}\nnormal = {vec(normal)}\n"


def simulation(dimension, time_step, duration, gravity=None):
    text = f"[simulation]\ndimension = {dimension}\ntime_step = {fmt(time_step)}\nduration = {fmt(duration)}\n"
    if gravity is not None:
        text += f"gravity = {vec(gravity)}\n"
    return text


def output(directory, interval):
    return f'[output]\ndirectory = "{directory}"\ntrajectory_interval = {fmt(interval)}\n'


def write(name, comment, parts):
    text = "".join(f"# {line}\n" if line else "#\n" for line in comment.strip().split("\n"))
    text += "# Written by scripts/generate-verification-scenes.py; the expected answers are in\n"
    text += "# docs/verification.md and tests/physics/test_verification_scenes.cpp.\n\n"
    text += "\n".join(parts)
    (HERE / name).write_text(text)


def approach_gap(normal_speed, dt):
    # The touch falls half-way between two position samples (tests/physics/impact_answers.hpp).
    return normal_speed * 40.5 * dt


def main():
    HERE.mkdir(parents=True, exist_ok=True)
    e = 0.5
    mu = 0.1
    t_wall = contact_duration(K_N, MASS, e)
    dt = t_wall / STEPS_PER_CONTACT

    # Chung & Ooi test 1: two identical spheres, head on, 10 m/s each way... here 0.2 m/s.
    v = 0.2
    t_pair = contact_duration(K_N, MASS / 2, e)
    dt_pair = t_pair / STEPS_PER_CONTACT
    gap = approach_gap(2 * v, dt_pair)
    write("normal-impact-two-spheres.toml",
          "Chung & Ooi test 1: normal impact of two identical spheres (no gravity).\n"
          "Expected: both rebound with the no-tension restitution e_eff(e) of the linear model\n"
          "(docs/model.md), momentum conserved, the ball-ball force lasting t* = (pi - 2 asin z)/w_d.",
          [simulation(3, dt_pair, 20 * t_pair, [0, 0, 0]),
           particle([-RADIUS - gap / 2, 0, 0], [v, 0, 0]),
           particle([RADIUS + gap / 2, 0, 0], [-v, 0, 0]),
           material("ball_ball", K_N, 2 * K_N / 3, e, mu),
           output("out/normal-impact-two-spheres", 0)])

    # Chung & Ooi tests 2 and 3: sphere on a wall; the restitution sweep is done with
    # --set materials.ball_wall.restitution=...
    write("normal-impact-wall.toml",
          "Chung & Ooi tests 2 and 3: normal impact of a sphere on a rigid plane (no gravity).\n"
          "Sweep the restitution with --set materials.ball_wall.restitution=0.2 (and so on);\n"
          "expected: rebound speed ratio e_eff(e), no spin.",
          [simulation(3, dt, 20 * t_wall, [0, 0, 0]),
           particle([0, 0, RADIUS + approach_gap(0.2, dt)], [0, 0, -0.2]),
           floor(3),
           material("ball_wall", K_N, 2 * K_N / 3, e, mu),
           output("out/normal-impact-wall", 0)])

    # Chung & Ooi test 4: constant speed, incidence angle 5..85 degrees, one sphere per angle,
    # side by side along y (they never touch).
    def oblique(name, comment, e_wall, k_s, speed=3.9):
        t = contact_duration(K_N, MASS, e_wall)
        step = t / STEPS_PER_CONTACT
        parts = [simulation(3, step, 20 * t, [0, 0, 0])]
        for i, angle in enumerate(range(5, 90, 5)):
            a = math.radians(angle)
            vn, vt = speed * math.cos(a), speed * math.sin(a)
            parts.append(f"# incidence {angle} degrees from the normal\n" +
                         particle([0, 4 * DIAMETER * i, RADIUS + approach_gap(vn, step)],
                                  [vt, 0, -vn], [0, 0, 0]))
        parts += [floor(3), material("ball_wall", K_N, k_s, e_wall, mu), output(f"out/{name[:-5]}", 0)]
        write(name, comment, parts)

    oblique("oblique-impact-angles.toml",
            "Chung & Ooi test 4: oblique impact of a sphere on a rigid plane at 3.9 m/s, incidence\n"
            "5 to 85 degrees from the normal (particle k at 5(k+1) degrees), e = 0.5, mu = 0.1.\n"
            "Expected in gross sliding (tan theta >= 3.5 mu (1 + e_eff)): tangential restitution\n"
            "1 - mu (1 + e_eff) / tan theta, rebound spin 2.5 mu (1 + e_eff) v cos theta / R.",
            e, 2 * K_N / 3)
    oblique("oblique-impact-angles-elastic.toml",
            "Chung & Ooi test 4 with e = 1 and k_s = 2 k_n / 7, where the linear model has a closed\n"
            "answer at every angle that sticks or slides throughout: the tangential oscillation\n"
            "(frequency sqrt(7 k_s / 2 m)) then has the normal one's frequency, so a sphere that\n"
            "sticks (tan theta <= 3.5 mu) leaves with its contact-point velocity reversed:\n"
            "tangential restitution 3/7, spin 10 v sin theta / (7 R); in gross sliding\n"
            "(tan theta >= 7 mu) the Coulomb answers with e = 1.",
            1.0, 2 * K_N / 7)

    # Chung & Ooi test 6: constant normal velocity, no tangential velocity, spin from 0 to
    # large, particle k spinning at spins[k] about y.
    vn = 0.2
    spins = [0.0, 2.0, 5.0, 10.0, 20.0, 40.0, 80.0, 160.0]
    parts = [simulation(3, dt, 20 * t_wall, [0, 0, 0])]
    for i, w in enumerate(spins):
        parts.append(f"# spin {w} rad/s about y: contact-point slip R w = {RADIUS * w:g} m/s\n" +
                     particle([0, 4 * DIAMETER * i, RADIUS + approach_gap(vn, dt)], [0, 0, -vn], [0, w, 0]))
    parts += [floor(3), material("ball_wall", K_N, 2 * K_N / 3, e, mu), output("out/impact-with-spin", 0)]
    write("impact-with-spin.toml",
          "Chung & Ooi test 6: normal impact at 0.2 m/s of spheres spinning about an axis in the\n"
          "plane (no gravity). Expected when the slip R w0 >= 3.5 mu (1 + e_eff) v_n (gross\n"
          "sliding): tangential velocity mu (1 + e_eff) v_n along -(slip), spin reduced by\n"
          "2.5 mu (1 + e_eff) v_n / R; the normal rebound e_eff v_n for all.",
          parts)

    # Bouncing, free fall, sliding to rolling, with gravity; 3D and 2D.
    for d in (3, 2):
        t = contact_duration(K_N, MASS, 0.8)
        step = t / 100
        h0 = 0.1
        up = [0.0] * (d - 1)
        write(f"bouncing-{d}d.toml",
              f"A {'sphere' if d == 3 else 'disc'} dropped from rest at centre height {h0} m on a floor (e = 0.8).\n"
              "Expected: apex heights of successive bounces (h0 - r) e_eff^(2k) + r.",
              [simulation(d, step, 1.2, None), particle(up + [h0], [0.0] * d, None),
               floor(d), material("ball_wall", K_N, 2 * K_N / 3, 0.8, 0.5),
               output(f"out/bouncing-{d}d", 1e-4)])
        write(f"free-fall-{d}d.toml",
              f"A {'sphere' if d == 3 else 'disc'} thrown up at 45 degrees, no walls.\n"
              "Expected: x(t) = x0 + v0 t + g t^2 / 2 exactly (the leapfrog is exact for constant force).",
              [simulation(d, 1e-4, 0.5, None), particle([0.0] * d, ([2.0] + [0.0] * (d - 2) + [2.0]), None),
               output(f"out/free-fall-{d}d", 0.01)])
        v0 = 2.0
        write(f"sliding-to-rolling-{d}d.toml",
              f"A {'sphere' if d == 3 else 'disc'} set down on a floor sliding at {v0} m/s without spin (mu = 0.3).\n"
              + ("Expected: it rolls from t = 2 v0 / (7 mu g) at 5 v0 / 7." if d == 3 else
                 "Expected: it rolls from t = v0 / (3 mu g) at 2 v0 / 3."),
              [simulation(d, t / 50, 0.5, None), particle(up[:-1] + [0.0] + [RADIUS] if d == 3 else [0.0, RADIUS], [v0] + [0.0] * (d - 1), None),
               floor(d), material("ball_wall", K_N, 2 * K_N / 3, 0.5, 0.3),
               output(f"out/sliding-to-rolling-{d}d", 1e-3)])


if __name__ == "__main__":
    main()
