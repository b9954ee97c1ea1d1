#!/usr/bin/env python3
"""Step-size and formulation study of examples/andrews_squeezer: the seven angles at t = 0.03
against the published reference for a series of time steps, in the three energy–momentum
formulations.

usage: study.py [--isoflex ./build/isoflex] [--model MODEL] [--outdir DIR]
                [--dts 1e-4,5e-5,...] [--formulations reparametrized,constrained,nullspace]
                [--plot FIGDIR]

Run from the repository root. For every dt and formulation: `isoflex run MODEL --dt DT
--formulation F -o DIR/F_DT`, then the angles at t = 0.03 (angles.py). Prints Markdown tables:
the error of each angle per dt (reparametrized) with the observed order between successive dts,
and per run the Newton iterations, the wall time (summary.json), max |Φ|, the energy balance
max |E − E(0) − external_work| and the largest difference of an angle at t = 0.03 from the
reparametrized run at the same dt. --plot writes FIGDIR/convergence.png (|error| of each angle
against dt, first formulation, log-log). Default DIR: out/andrews_squeezer_study. Exit status 2 for a
bad option or missing output, 3 if a run fails.
"""
import argparse
import json
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import angles  # noqa: E402
from isoflex_csv import fail  # noqa: E402  (angles.py put tools/ on the path)


def run(binary, model, dt, formulation, out):
    args = [binary, "run", model, "--dt", dt, "--formulation", formulation, "-o", out]
    try:
        r = subprocess.run(args, capture_output=True, text=True)
    except OSError as e:
        fail(f"cannot run {binary}: {e}")
    if r.returncode != 0:
        print(r.stdout + r.stderr, file=sys.stderr)
        print(f"study.py: error: {' '.join(args)} failed with status {r.returncode}",
              file=sys.stderr)
        sys.exit(3)
    with open(os.path.join(out, "summary.json")) as f:
        s = json.load(f)
    t, alpha = angles.absolute_angles(out)
    q = angles.hw_angles(alpha)
    i = int(abs(t - angles.T_REF).argmin())
    if abs(t[i] - angles.T_REF) > 1e-9:
        fail(f"{out}: no row at t = 0.03")
    bal = angles.energy_balance(out, t, q[:, 0])
    return {"q": q[i], "err": q[i] - angles.REFERENCE, "newton": s["newton_iterations_total"],
            "wall": s["wall_time_s"], "phi": s["max_constraint_violation"],
            "steps": s["steps"], "unknowns": s["n_unknowns"],
            "balance": float(abs(bal[:, 1] - bal[:, 3]).max()),
            "torque_gap": float(bal[-1, 1] - bal[-1, 2])}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--isoflex", default="./build/isoflex")
    ap.add_argument("--model", default=os.path.join(HERE, "model.yaml"))
    ap.add_argument("--outdir", default="out/andrews_squeezer_study")
    ap.add_argument("--dts", default="1e-4,5e-5,2.5e-5,1.25e-5,1e-5,5e-6,2.5e-6")
    ap.add_argument("--formulations", default="reparametrized,constrained,nullspace")
    ap.add_argument("--plot", metavar="FIGDIR")
    a = ap.parse_args()
    dts = a.dts.split(",")
    forms = a.formulations.split(",")
    res = {}
    for f in forms:
        for dt in dts:
            res[f, dt] = run(a.isoflex, a.model, dt, f, os.path.join(a.outdir, f"{f}_{dt}"))
    f0 = forms[0]
    sym = angles.SYMBOLS
    print(f"Errors at t = 0.03 ({f0}; isoflex − reference):\n")
    print("| Δt | steps | " + " | ".join(sym) + " |")
    print("|---|---:|" + "---:|" * 7)
    for dt in dts:
        r = res[f0, dt]
        print(f"| {dt} | {r['steps']} | " + " | ".join(f"{e:.2e}" for e in r["err"]) + " |")
    print("\nObserved order log(|e(Δt₁)| / |e(Δt₂)|) / log(Δt₁ / Δt₂) between successive steps:\n")
    print("| Δt₁ → Δt₂ | " + " | ".join(sym) + " |")
    print("|---|" + "---:|" * 7)
    for d1, d2 in zip(dts, dts[1:]):
        e1, e2 = res[f0, d1]["err"], res[f0, d2]["err"]
        p = [math.log(abs(x) / abs(y)) / math.log(float(d1) / float(d2)) for x, y in zip(e1, e2)]
        print(f"| {d1} → {d2} | " + " | ".join(f"{x:.3f}" for x in p) + " |")
    print("\nRuns (wall time: summary.json; balance: max over the run of |E − E(0) − W|, "
          "W = external_work; torque gap: E − E(0) − mom·(β − β(0)) at t = 0.03; "
          f"vs {f0}: max over the seven angles of the difference at t = 0.03):\n")
    print("| formulation | Δt | unknowns | Newton iterations | wall time (s) | max \\|Φ\\| | "
          "balance | torque gap | max \\|error\\| | vs " + f0 + " |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for f in forms:
        for dt in dts:
            r = res[f, dt]
            diff = max(abs(x - y) for x, y in zip(r["q"], res[f0, dt]["q"]))
            print(f"| {f} | {dt} | {r['unknowns']} | {r['newton']} | {r['wall']:.3f} | "
                  f"{r['phi']:.1e} | {r['balance']:.1e} | {r['torque_gap']:.2e} | "
                  f"{max(abs(e) for e in r['err']):.2e} | "
                  + ("–" if f == f0 else f"{diff:.1e}") + " |")
    if a.plot:
        plot(a.plot, dts, [res[f0, dt]["err"] for dt in dts])


def plot(figdir, dts, errors):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(figdir, exist_ok=True)
    h = [float(x) for x in dts]
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for k, s in enumerate(angles.SYMBOLS):
        ax.loglog(h, [abs(e[k]) for e in errors], "o-", ms=4, label=s)
    e0 = abs(errors[0][0])
    ax.loglog(h, [e0 * (x / h[0]) ** 2 for x in h], "k--", lw=1, label="Δt²")
    ax.set_xlabel("Δt [s]")
    ax.set_ylabel("|angle − reference| at t = 0.03 [rad]")
    ax.set_title("Andrews' squeezer: error at t = 0.03")
    ax.grid(alpha=0.3, which="both")
    ax.legend(ncol=2, fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(figdir, "convergence.png"), dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
