#!/usr/bin/env python3
"""The seven angles of Andrews' squeezing mechanism at t = 0.03 from an isoflex run, against the
published reference solution (Hairer & Wanner; the test set for IVP solvers, problem "andrews").

    /usr/bin/python3 examples/andrews_squeezer/angles.py OUTDIR [--t 0.03] [--plot FIGDIR] [--json]

Each body K carries two probes (model.yaml): bK_o at its centre of mass and bK_x 0.01 along its
d1, which at t = 0 points along the body's absolute angle. The absolute angle is atan2 of
bK_x − bK_o, unwrapped over the rows of probes.csv (a run must write every step: a body turns by
less than π per step). The angles of Hairer & Wanner: β = α1, Θ = α2 − α1, γ = α3, Φ = α4 − α5,
δ = α5, Ω = α6 − α7, ε = α7.

Also the energy balance from history.csv: the change of kinetic + spring energy against the
work of the torque, mom·(β(t) − β(0)), and against the column external_work when the run has it.
--plot writes FIGDIR/angles.png (the seven angles over time) and FIGDIR/energy.png.
Uses python3 and numpy (matplotlib for --plot) and tools/isoflex_csv.py.
"""
import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
import isoflex_csv  # noqa: E402

NAMES = ["beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon"]
SYMBOLS = ["β", "Θ", "γ", "Φ", "δ", "Ω", "ε"]
# The test set's reference solution at t = 0.03 (andrews, SOLN; Hairer & Wanner).
REFERENCE = [15.81077119629904, -15.75637105984298, 0.04082224013073101, -0.5347301163226948,
             0.5244099658805304, 0.5347301163226948, 1.048080741042263]
T_REF = 0.03
MOM = 0.033


def absolute_angles(outdir):
    """Times and the unwrapped absolute angles α1 … α7 (rows: time, columns: bodies)."""
    path = os.path.join(outdir, "probes.csv")
    pos = {}
    for line_no, row in isoflex_csv.rows(path, ["t", "probe", "x", "y"]):
        v = isoflex_csv.numbers(path, line_no, row, ["t", "x", "y"])
        pos.setdefault(row["probe"], {})[v["t"]] = (v["x"], v["y"])
    missing = [f"b{k}_{s}" for k in range(1, 8) for s in "ox" if f"b{k}_{s}" not in pos]
    if missing:
        isoflex_csv.fail(f"{path} lacks the probe(s) {', '.join(missing)}")
    t = np.array(sorted(set.intersection(*(set(pos[f"b{k}_{s}"]) for k in range(1, 8)
                                           for s in "ox"))))
    alpha = np.empty((t.size, 7))
    for k in range(1, 8):
        o = np.array([pos[f"b{k}_o"][x] for x in t])
        x = np.array([pos[f"b{k}_x"][x] for x in t])
        raw = np.arctan2(x[:, 1] - o[:, 1], x[:, 0] - o[:, 0])
        step = np.abs(np.diff(np.unwrap(raw)))
        if step.size and step.max() > 0.5 * math.pi:
            isoflex_csv.fail(f"body {k} turns by {step.max():.2f} rad between two rows of {path}: "
                             "write every step (output.history) with a smaller dt")
        alpha[:, k - 1] = np.unwrap(raw)
    return t, alpha


def hw_angles(alpha):
    a = alpha.T
    return np.array([a[0], a[1] - a[0], a[2], a[3] - a[4], a[4], a[5] - a[6], a[6]]).T


def energy_balance(outdir, t, beta):
    """Rows of history.csv with E − E0, the torque's work mom·(β − β0) and external_work."""
    path = os.path.join(outdir, "history.csv")
    hist = []
    for line_no, row in isoflex_csv.rows(path, ["t", "total_energy"]):
        v = isoflex_csv.numbers(path, line_no, row, ["t", "total_energy"])
        w = float(row["external_work"]) if "external_work" in row else math.nan
        hist.append((v["t"], v["total_energy"], w))
    h = np.array(hist)
    by_t = {round(x, 12): b for x, b in zip(t, beta)}
    rows = []
    for tt, E, W in h:
        b = by_t.get(round(tt, 12))
        if b is not None:
            rows.append((tt, E - h[0, 1], MOM * (b - beta[0]), W))
    return np.array(rows)


def plot(figdir, t, q, bal):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(figdir, exist_ok=True)
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for k in (0, 1):
        ax[0].plot(t * 1e3, q[:, k], label=SYMBOLS[k])
        ax[0].plot([T_REF * 1e3], [REFERENCE[k]], "k+", ms=10)
    for k in range(2, 7):
        ax[1].plot(t * 1e3, q[:, k], label=SYMBOLS[k])
        ax[1].plot([T_REF * 1e3], [REFERENCE[k]], "k+", ms=10)
    for a in ax:
        a.set_xlabel("t [ms]")
        a.set_ylabel("angle [rad]")
        a.grid(alpha=0.3)
        a.legend(ncol=2, fontsize=9)
    ax[0].set_title("β, Θ (+: reference at t = 0.03)")
    ax[1].set_title("γ, Φ, δ, Ω, ε (+: reference at t = 0.03)")
    fig.tight_layout()
    fig.savefig(os.path.join(figdir, "angles.png"), dpi=120)
    plt.close(fig)
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    ax[0].plot(bal[:, 0] * 1e3, bal[:, 1], label="E(t) − E(0)")
    ax[0].plot(bal[:, 0] * 1e3, bal[:, 2], "--", label="mom·(β(t) − β(0))")
    ax[0].set_ylabel("energy [J]")
    ax[0].legend()
    ax[0].set_title("energy and the work of the torque")
    if np.isfinite(bal[:, 3]).all():
        ax[1].semilogy(bal[1:, 0] * 1e3, np.abs(bal[1:, 1] - bal[1:, 3]) + 1e-300,
                       label="|E − E(0) − external_work|")
    ax[1].semilogy(bal[1:, 0] * 1e3, np.abs(bal[1:, 1] - bal[1:, 2]) + 1e-300,
                   label="|E − E(0) − mom·(β − β(0))|")
    ax[1].set_ylabel("J")
    ax[1].legend()
    ax[1].set_title("energy balance")
    for a in ax:
        a.set_xlabel("t [ms]")
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(figdir, "energy.png"), dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir", help="the output folder of an isoflex run of model.yaml")
    ap.add_argument("--t", type=float, default=T_REF, help="the time to report (default 0.03)")
    ap.add_argument("--plot", metavar="FIGDIR", help="write angles.png and energy.png there")
    ap.add_argument("--json", action="store_true", help="print the result as one JSON object")
    a = ap.parse_args()
    t, alpha = absolute_angles(a.outdir)
    q = hw_angles(alpha)
    i = int(np.argmin(np.abs(t - a.t)))
    if abs(t[i] - a.t) > 1e-9:
        isoflex_csv.fail(f"no row at t = {a.t} in {a.outdir}/probes.csv (the last is t = {t[-1]})")
    bal = energy_balance(a.outdir, t, q[:, 0])
    j = int(np.argmin(np.abs(bal[:, 0] - a.t)))
    compare = abs(a.t - T_REF) < 1e-12
    err = [q[i, k] - REFERENCE[k] for k in range(7)] if compare else [math.nan] * 7
    result = {"t": t[i], "angles": dict(zip(NAMES, q[i].tolist())),
              "errors": dict(zip(NAMES, err)) if compare else None,
              "max_abs_error": max(abs(x) for x in err) if compare else None,
              "energy_change": bal[j, 1], "torque_work": bal[j, 2], "external_work": bal[j, 3]}
    if a.json:
        print(json.dumps(result))
    else:
        print(f"{a.outdir}: t = {t[i]:.10g}")
        print(f"{'angle':6} {'isoflex':>22} {'reference':>22} {'error':>10}")
        for k in range(7):
            ref = f"{REFERENCE[k]:22.16g}" if compare else " " * 22
            print(f"{SYMBOLS[k]:6} {q[i, k]:22.16g} {ref} {err[k]:10.2e}")
        print(f"energy: E(t) - E(0) = {bal[j, 1]:.12g}; torque's work mom*(beta - beta0) = "
              f"{bal[j, 2]:.12g} (difference {bal[j, 1] - bal[j, 2]:.2e})")
        if math.isfinite(bal[j, 3]):
            print(f"        external_work = {bal[j, 3]:.12g} (E - E0 - W = "
                  f"{bal[j, 1] - bal[j, 3]:.2e}; max over the run "
                  f"{np.abs(bal[:, 1] - bal[:, 3]).max():.2e})")
    if a.plot:
        plot(a.plot, t, q, bal)


if __name__ == "__main__":
    main()
