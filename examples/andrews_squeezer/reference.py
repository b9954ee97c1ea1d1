#!/usr/bin/env python3
"""An independent check of the published reference solution: Hairer & Wanner's equations of
Andrews' squeezing mechanism (the 7 angles, their mass matrix, forces and 6 constraints,
§VII.7) integrated to t = 0.03 in index-1 form with scipy's DOP853 at tight tolerances,
against the reference values that angles.py and the test use.

    /usr/bin/python3 examples/andrews_squeezer/reference.py [--rtol 1e-12]

M(q) q̈ = f(q, q̇) − Gᵀλ, G q̈ = −(d/dt G) q̇: the accelerations and multipliers from one linear
solve per evaluation; the constraint drift is printed. Needs numpy and scipy.
"""
import argparse
import math
import os
import sys

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import angles  # noqa: E402
import make_model as mm  # noqa: E402  (data, initial angles, Hairer–Wanner's mass matrix)
from make_model import (c0, d, e, l0, mom, rr, sc, sd, ss, u, xa, xb, xc, ya, yb, yc,  # noqa: E402
                        zf, zt, ea, da, fa)

I7 = np.eye(7)
B_, T_, G_, P_, D_, O_, E_ = I7  # unit vectors of β, Θ, γ, Φ, δ, Ω, ε
# Each constraint row (P reached along two chains, x and y) as a constant plus a sum of
# c·cos(a·q) or c·sin(a·q): its value, gradient and second time derivative follow from these.
ROWS = [(-xb, [(rr, "c", B_), (-d, "c", B_ + T_), (-ss, "s", G_)]),
        (-yb, [(rr, "s", B_), (-d, "s", B_ + T_), (ss, "c", G_)]),
        (-xa, [(rr, "c", B_), (-d, "c", B_ + T_), (-e, "s", P_ + D_), (-zt, "c", D_)]),
        (-ya, [(rr, "s", B_), (-d, "s", B_ + T_), (e, "c", P_ + D_), (-zt, "s", D_)]),
        (-xa, [(rr, "c", B_), (-d, "c", B_ + T_), (-zf, "c", O_ + E_), (-u, "s", E_)]),
        (-ya, [(rr, "s", B_), (-d, "s", B_ + T_), (-zf, "s", O_ + E_), (u, "c", E_)])]


def constraints(q, v=None):
    """g(q), G(q) = ∂g/∂q and, with v, the quadratic term (d/dt G) v."""
    g, G, gvv = np.zeros(6), np.zeros((6, 7)), np.zeros(6)
    for i, (const, terms) in enumerate(ROWS):
        g[i] = const
        for c, kind, a in terms:
            x = a @ q
            f, df = (math.cos(x), -math.sin(x)) if kind == "c" else (math.sin(x), math.cos(x))
            g[i] += c * f
            G[i] += c * df * a
            if v is not None:
                gvv[i] -= c * f * (a @ v) ** 2
    return g, G, gvv


def forces(q, v):
    """Hairer–Wanner's f: the torque, the spring on γ and the velocity terms of M."""
    be, th, ga, ph, de, om, ep = q
    bep, thp, gap, php, dep, omp, epp = v
    m2, m4, m6 = mm.m[1], mm.m[3], mm.m[5]
    xd = xb + sd * math.cos(ga) + sc * math.sin(ga)       # the spring's point D
    yd = yb + sd * math.sin(ga) - sc * math.cos(ga)
    L = math.hypot(xd - xc, yd - yc)
    F = -c0 * (L - l0) / L
    return np.array([
        mom - m2 * da * rr * thp * (thp + 2 * bep) * math.sin(th),
        m2 * da * rr * bep**2 * math.sin(th),
        F * (xd - xc) * (sc * math.cos(ga) - sd * math.sin(ga))
        + F * (yd - yc) * (sd * math.cos(ga) + sc * math.sin(ga)),
        m4 * zt * (e - ea) * dep**2 * math.cos(ph),
        -m4 * zt * (e - ea) * php * (php + 2 * dep) * math.cos(ph),
        -m6 * u * (zf - fa) * epp**2 * math.cos(om),
        m6 * u * (zf - fa) * omp * (omp + 2 * epp) * math.cos(om)])


def rhs(t, y):
    q, v = y[:7], y[7:]
    _, G, gvv = constraints(q, v)
    K = np.block([[np.array(mm.hw_mass_matrix(q)), G.T], [G, np.zeros((6, 6))]])
    a = np.linalg.solve(K, np.concatenate([forces(q, v), -gvv]))[:7]
    return np.concatenate([v, a])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rtol", type=float, default=1e-12, help="rtol = atol of DOP853")
    a = ap.parse_args()
    q0 = np.array(mm.ANGLES0)
    r = solve_ivp(rhs, (0.0, angles.T_REF), np.concatenate([q0, np.zeros(7)]), method="DOP853",
                  rtol=a.rtol, atol=a.rtol)
    q = r.y[:7, -1]
    print(f"DOP853, rtol = atol = {a.rtol:g}: {r.t.size - 1} steps; |g(q0)| = "
          f"{np.abs(constraints(q0)[0]).max():.1e}, |g(q(0.03))| = "
          f"{np.abs(constraints(q)[0]).max():.1e}")
    print(f"{'angle':6} {'this integration':>22} {'reference':>22} {'difference':>10}")
    for k in range(7):
        print(f"{angles.SYMBOLS[k]:6} {q[k]:22.16g} {angles.REFERENCE[k]:22.16g} "
              f"{q[k] - angles.REFERENCE[k]:10.2e}")


if __name__ == "__main__":
    main()
