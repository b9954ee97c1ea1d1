#!/usr/bin/env python3
"""Writes model.yaml of Andrews' squeezing mechanism (Hairer & Wanner, Solving ODEs II, §VII.7;
the test set for IVP solvers, problem "andrews") from the published data and initial angles.

Every centre of mass, joint point, the spring's point D and each body's orientation at t = 0 are
computed here in double precision from the seven initial angles. Each body's frame (d1, d2, d3)
is the global frame turned about z by the body's absolute angle (β, β+Θ, γ, Φ+δ, δ, Ω+ε, ε), so
that the angle is atan2 of d1, read back from two probes per body (angles.py).

    /usr/bin/python3 examples/andrews_squeezer/make_model.py [-o model.yaml] [--check]

--check also compares the kinetic energy of the model's bodies (centres of mass and angular
velocities as functions of the seven angles) with Hairer–Wanner's mass matrix at random angles
and velocities, and the constraint rows with theirs.
"""
import argparse
import math
import os
import random

# Hairer & Wanner (1996), §VII.7, and the test set (andrews): masses, inertias about the centres
# of mass, fixed points, lengths, spring, driving torque.
m = [0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498]
J = [2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5]
xa, ya = -0.06934, -0.00227
xb, yb = -0.03635, 0.03273
xc, yc = 0.014, 0.072
c0, l0 = 4530.0, 0.07785
rr, ra = 0.007, 0.00092
d, da = 0.028, 0.0115
e, ea = 0.02, 0.01421
ss, sa, sb, sc, sd = 0.035, 0.01874, 0.01043, 0.018, 0.02
ta, tb = 0.02308, 0.00916
u, ua, ub = 0.04, 0.01228, 0.00449
zf, zt, fa = 0.02, 0.04, 0.01421
mom = 0.033

# Consistent initial angles (β, Θ, γ, Φ, δ, Ω, ε), velocities zero.
ANGLES0 = [-0.0617138900142764496358948458001, 0.0, 0.455279819163070380255912382449,
           0.222668390165885884674473185609, 0.487364979543842550225598953530,
           -0.222668390165885884674473185609, 1.23054744454982119249735015568]

PROBE_ARM = 0.01  # the second probe of each body: 0.01 along its d1


def ev(a):  # unit vector at angle a
    return (math.cos(a), math.sin(a))


def nv(a):  # (sin a, −cos a): ev(a) turned by −90°
    return (math.sin(a), -math.cos(a))


def add(*terms):
    return (sum(t[0] for t in terms), sum(t[1] for t in terms))


def mul(s, v):
    return (s * v[0], s * v[1])


def geometry(q):
    """Points, centres of mass and absolute angles of the seven bodies for the angles q."""
    be, th, ga, ph, de, om, ep = q
    O, A, B, C = (0.0, 0.0), (xa, ya), (xb, yb), (xc, yc)
    Q = mul(rr, ev(be))                                  # hinge body 1 – body 2
    P = add(Q, mul(-d, ev(be + th)))                     # bodies 2, 3, 4, 6 meet here
    E = add(A, mul(zt, ev(de)))                          # hinge body 5 – body 4
    G = add(A, mul(u, nv(ep)))                           # hinge body 7 – body 6
    D = add(B, mul(sd, ev(ga)), mul(sc, nv(ga)))         # spring end on body 3
    S = [mul(ra, ev(be)),                                # centres of mass
         add(Q, mul(-da, ev(be + th))),
         add(B, mul(sa, nv(ga)), mul(sb, ev(ga))),        # sa along B→P, sb along B→D's sd
         add(E, mul(e - ea, nv(ph + de))),
         add(A, mul(ta, ev(de)), mul(tb, ev(de + math.pi / 2))),
         add(G, mul(zf - fa, ev(om + ep))),
         add(A, mul(ua, nv(ep)), mul(-ub, ev(ep)))]
    alpha = [be, be + th, ga, ph + de, de, om + ep, ep]  # absolute angles
    # P reached along the other three chains (the loop closures)
    P3 = add(B, mul(ss, nv(ga)))
    P4 = add(E, mul(e, nv(ph + de)))
    P6 = add(G, mul(zf, ev(om + ep)))
    return dict(O=O, A=A, B=B, C=C, Q=Q, P=P, E=E, G=G, D=D, S=S, alpha=alpha,
                closure=max(abs(P[i] - X[i]) for X in (P3, P4, P6) for i in (0, 1)))


def hw_mass_matrix(q):
    be, th, ga, ph, de, om, ep = q
    M = [[0.0] * 7 for _ in range(7)]
    M[0][0] = m[0] * ra**2 + m[1] * (rr**2 - 2 * da * rr * math.cos(th) + da**2) + J[0] + J[1]
    M[1][0] = m[1] * (da**2 - da * rr * math.cos(th)) + J[1]
    M[1][1] = m[1] * da**2 + J[1]
    M[2][2] = m[2] * (sa**2 + sb**2) + J[2]
    M[3][3] = m[3] * (e - ea)**2 + J[3]
    M[4][3] = m[3] * ((e - ea)**2 + zt * (e - ea) * math.sin(ph)) + J[3]
    M[4][4] = (m[3] * (zt**2 + 2 * zt * (e - ea) * math.sin(ph) + (e - ea)**2)
               + m[4] * (ta**2 + tb**2) + J[3] + J[4])
    M[5][5] = m[5] * (zf - fa)**2 + J[5]
    M[6][5] = m[5] * ((zf - fa)**2 - u * (zf - fa) * math.sin(om)) + J[5]
    M[6][6] = (m[5] * ((zf - fa)**2 - 2 * u * (zf - fa) * math.sin(om) + u**2)
               + m[6] * (ua**2 + ub**2) + J[5] + J[6])
    for i in range(7):
        for j in range(i + 1, 7):
            M[i][j] = M[j][i]
    return M


def check():
    """Kinetic energy of the bodies vs ½ q̇ᵀ M_HW q̇ (velocities of the centres of mass and the
    angular velocities by central differences), and the loop closure at t = 0."""
    rng = random.Random(1)
    worst = 0.0
    for _ in range(20):
        q = [rng.uniform(-3, 3) for _ in range(7)]
        v = [rng.uniform(-1, 1) for _ in range(7)]
        h = 1e-4  # fourth-order central differences along v
        g = {s: geometry([qi + s * h * vi for qi, vi in zip(q, v)]) for s in (-2, -1, 1, 2)}

        def rate(f):
            return (-f(g[2]) + 8 * f(g[1]) - 8 * f(g[-1]) + f(g[-2])) / (12 * h)
        T = 0.0
        for k in range(7):
            vx = rate(lambda x: x["S"][k][0])
            vy = rate(lambda x: x["S"][k][1])
            w = rate(lambda x: x["alpha"][k])
            T += 0.5 * (m[k] * (vx * vx + vy * vy) + J[k] * w * w)
        M = hw_mass_matrix(q)
        T_hw = 0.5 * sum(v[i] * M[i][j] * v[j] for i in range(7) for j in range(7))
        worst = max(worst, abs(T - T_hw) / T_hw)
    g0 = geometry(ANGLES0)
    print(f"kinetic energy vs Hairer-Wanner's mass matrix, 20 random states: "
          f"max relative difference {worst:.1e}")
    print(f"loop closure at t = 0: max |P - P'| = {g0['closure']:.1e}")
    return worst < 1e-10 and g0["closure"] < 1e-15


def f17(x):
    """x with 17 significant digits (read back as the same double)."""
    return "0" if x == 0 else f"{x:.17g}"


def vec(p):
    return f"[{f17(p[0])}, {f17(p[1])}, 0]"


def orientation(a):
    c, s = math.cos(a), math.sin(a)
    return f"[[{f17(c)}, {f17(s)}, 0], [{f17(-s)}, {f17(c)}, 0], [0, 0, 1]]"


def model_yaml(dt, t_end):
    g = geometry(ANGLES0)
    names = [f"b{k}" for k in range(1, 8)]
    S, al = g["S"], g["alpha"]
    # Drawing shapes (no effect on the dynamics), body coordinates.
    shapes = [
        f"{{type: cylinder, radius: {rr}, height: 0.001, offset: [{-ra}, 0, 0]}}",   # crank disc about O
        f"{{type: box, size: [{d}, 0.001, 0.001], offset: [{f17(da - d / 2)}, 0, 0]}}",  # rod Q–P
        "{type: sphere, radius: 0.002}",
        f"{{type: box, size: [0.001, {e}, 0.001], offset: [0, {f17(e - ea - e / 2)}, 0]}}",  # rod E–P
        "{type: sphere, radius: 0.002}",
        f"{{type: box, size: [{zf}, 0.001, 0.001], offset: [{f17(fa - zf / 2)}, 0, 0]}}",  # rod G–P
        "{type: sphere, radius: 0.002}",
    ]
    what = ["crank, turns about O, driven by the torque",
            "connecting rod, hinged to body 1 at Q, ends at P",
            "rotates about B; P and the spring point D on it",
            "rod from E (on body 5) to P",
            "rotates about A; hinge E with body 4",
            "rod from G (on body 7) to P",
            "rotates about A; hinge G with body 6"]
    out = []
    w = out.append
    w("# Andrews' squeezing mechanism: the seven-body planar benchmark of Hairer & Wanner, Solving")
    w("# ODEs II, §VII.7 (and the test set for IVP solvers, \"andrews\"): seven rigid bodies in the")
    w("# plane z = 0, ten revolute joints about z, a spring from body 3 to the fixed point C, the")
    w("# driving torque mom = 0.033 on body 1, no gravity, at rest at t = 0. Written by")
    w("# make_model.py from the published data and initial angles (every number below to 17")
    w("# digits); angles.py reads the seven angles back from the probes (README.md).")
    w("# Body k's frame is the global frame turned about z by its absolute angle at t = 0;")
    w("# inertia [J, J, J] with J the published moment about z (only J3 acts in planar motion).")
    w("name: andrews_squeezer")
    w("solver:")
    w(f"  dt: {dt}")
    w(f"  t_end: {t_end}")
    w("output:")
    w("  vtk_every: 0          # no VTK files; e.g. 10 to watch the mechanism in ParaView")
    w("bodies:")
    for k in range(7):
        w(f"  - name: {names[k]}              # body {k + 1}: {what[k]}")
        w(f"    mass: {m[k]}")
        w(f"    inertia: [{J[k]}, {J[k]}, {J[k]}]")
        w(f"    position: {vec(S[k])}")
        w(f"    orientation: {orientation(al[k])}")
        w(f"    shape: {shapes[k]}")
    w("joints:")
    joints = [("O", "ground", "b1", "O"), ("Q", "b1", "b2", "Q"), ("B", "ground", "b3", "B"),
              ("A5", "ground", "b5", "A"), ("A7", "ground", "b7", "A"), ("E", "b5", "b4", "E"),
              ("G", "b7", "b6", "G"), ("P23", "b3", "b2", "P"), ("P34", "b3", "b4", "P"),
              ("P36", "b3", "b6", "P")]
    for name, a, b, p in joints:
        w(f"  - {{name: {name}, type: revolute, body_a: {a}, body_b: {b}, point: {vec(g[p])}, "
          f"axis: [0, 0, 1]}}")
    w("loads:")
    w(f"  - {{name: drive, body: b1, moment: [0, 0, {mom}]}}")
    w("springs:")
    w(f"  - {{name: spring, a: {{body: b3, point: {vec(g['D'])}}}, "
      f"b: {{body: ground, point: {vec(g['C'])}}}, stiffness: {c0}, free_length: {l0}}}")
    w("probes:                 # bK_o: centre of mass of body K, bK_x: 0.01 along its d1")
    for k in range(7):
        w(f"  - {{name: {names[k]}_o, body: {names[k]}, point_local: [0, 0, 0]}}")
        w(f"  - {{name: {names[k]}_x, body: {names[k]}, point_local: [{PROBE_ARM}, 0, 0]}}")
    w("  - {name: P, body: b2, point: " + vec(g["P"]) + "}")
    return "\n".join(out) + "\n"


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-o", "--output", default=os.path.join(here, "model.yaml"))
    ap.add_argument("--dt", default="1e-5")
    ap.add_argument("--t-end", default="0.03")
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    if a.check and not check():
        raise SystemExit("check failed")
    os.makedirs(os.path.dirname(os.path.abspath(a.output)), exist_ok=True)
    with open(a.output, "w") as f:
        f.write(model_yaml(a.dt, a.t_end))
    print(f"wrote {a.output}")


if __name__ == "__main__":
    main()
