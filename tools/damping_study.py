#!/usr/bin/python3
"""Damping study of a model with Kelvin–Voigt material damping: the free oscillation of a probe
for several damping factors η (IGA-thesis §6.4.3.1, Figs. 6.29 and 6.30).

usage: damping_study.py MODEL --etas 0,0.005,0.01,0.02 [--probe tip] [--component z]
                        [--shell NAME] [--t-end T] [--isoflex build/isoflex]
                        [--outdir DIR] [--table FILE.md]

For every η the model's kl_shells entry (the first, or --shell) gets `material.eta: η` and is
run with `isoflex run` (--t-end overrides the model's end time). From the probe's displacement
component the upper turning points z_k are found, and the damping ratio per oscillation
    ζ_k / √(1 − ζ_k²) = δ_k / 2π,   δ_k = ln(z_k / z_{k+1})
(the thesis' definition). Writes amplitude.png (the component against t, every η; Fig. 6.29),
damping_ratio.png (ζ_k against k; Fig. 6.30) and a markdown table (per η: the period, z_1,
ζ_1, ζ at the last oscillation, the dissipated energy) to --outdir (default: the model's
folder/figures) and --table. Exit status 2 on a bad model or option, 3 if a run fails.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from isoflex_csv import fail, numbers, rows  # noqa: E402


def turning_points(t, z):
    """(t_k, z_k): the largest z of every oscillation, between two upward zero crossings of z (a
    ripple of higher modes near a turning point is not a second oscillation); the start (at rest,
    t = 0) and an oscillation cut off by the end of the run are left out."""
    ups = [i for i in range(1, len(z)) if z[i - 1] < 0 <= z[i]]
    peaks = []
    for a, b in zip(ups, ups[1:]):
        k = max(range(a, b), key=lambda i: z[i])
        peaks.append((t[k], z[k]))
    return peaks


def damping_ratios(peaks):
    out = []
    for (_, a), (_, b) in zip(peaks, peaks[1:]):
        if a <= 0 or b <= 0:
            break
        d = math.log(a / b) / (2 * math.pi)
        out.append(d / math.sqrt(1 + d * d))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("model")
    ap.add_argument("--etas", required=True, help="comma-separated damping factors (s)")
    ap.add_argument("--probe", default="tip")
    ap.add_argument("--component", default="z", choices=["x", "y", "z"])
    ap.add_argument("--shell", help="name of the kl_shells entry (default: the first)")
    ap.add_argument("--t-end", type=float)
    ap.add_argument("--isoflex", default=os.path.join(os.getcwd(), "build", "isoflex"))
    ap.add_argument("--outdir")
    ap.add_argument("--table")
    a = ap.parse_args()

    try:
        etas = [float(x) for x in a.etas.split(",")]
    except ValueError:
        fail(f"--etas: not a list of numbers: {a.etas}")
    if any(e < 0 for e in etas):
        fail("--etas: damping factors must be >= 0")
    if not os.path.isfile(a.model):
        fail(f"no such file: {a.model}")
    with open(a.model) as f:
        model = yaml.safe_load(f)
    shells = model.get("kl_shells") or []
    shell = next((s for s in shells if a.shell is None or s.get("name") == a.shell), None)
    if shell is None:
        fail(f"{a.model}: no kl_shells entry" + (f" named {a.shell}" if a.shell else ""))
    outdir = a.outdir or os.path.join(os.path.dirname(os.path.abspath(a.model)), "figures")
    os.makedirs(outdir, exist_ok=True)

    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for eta in etas:
            shell["material"]["eta"] = eta
            path = os.path.join(tmp, f"eta_{eta:g}.yaml")
            with open(path, "w") as f:
                yaml.safe_dump(model, f, sort_keys=False)
            out = os.path.join(tmp, f"out_{eta:g}")
            cmd = [a.isoflex, "run", path, "-o", out]
            if a.t_end:
                cmd += ["--t-end", str(a.t_end)]
            run = subprocess.run(cmd, capture_output=True, text=True)
            if run.returncode != 0:
                print(run.stdout + run.stderr, file=sys.stderr)
                sys.exit(3 if run.returncode == 3 else 2)
            probes = os.path.join(out, "probes.csv")
            col = "u" + a.component
            t, z = [], []
            for n, r in rows(probes, ["t", "probe", col]):
                if r["probe"] == a.probe:
                    v = numbers(probes, n, r, ["t", col])
                    t.append(v["t"])
                    z.append(v[col])
            if not t:
                fail(f"{a.model}: no probe named {a.probe}")
            with open(os.path.join(out, "summary.json")) as f:
                summary = json.load(f)
            peaks = turning_points(t, z)
            period = ((peaks[-1][0] - peaks[0][0]) / (len(peaks) - 1)) if len(peaks) > 1 else float("nan")
            results.append({"eta": eta, "t": t, "z": z, "peaks": peaks,
                            "zeta": damping_ratios(peaks), "period": period,
                            "dissipated": summary.get("dissipated_energy", 0.0),
                            "energy": summary["energy_initial"]})

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5))
    for r in results:
        ax.plot(r["t"], r["z"], lw=0.9, label=f"η = {r['eta']:g} s")
    ax.set_xlabel("t (s)")
    ax.set_ylabel(f"{a.probe} displacement u{a.component} (m)")
    ax.set_title("Tip amplitude against time (IGA-thesis Fig. 6.29)")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "amplitude.png"), dpi=120)

    fig, ax = plt.subplots(figsize=(8, 4.5))
    for r in results:
        if r["zeta"]:
            ax.plot(range(1, len(r["zeta"]) + 1), r["zeta"], "o-", ms=3, label=f"η = {r['eta']:g} s")
    ax.set_xlabel("oscillation k")
    ax.set_ylabel("damping ratio ζ_k")
    ax.set_title("Damping ratio per oscillation (IGA-thesis Fig. 6.30)")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "damping_ratio.png"), dpi=120)

    lines = ["| η (s) | period (s) | z₁ (m) | ζ₁ | ζ last | η ω / 2 | dissipated / E₀ |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in results:
        omega = 2 * math.pi / r["period"] if r["period"] == r["period"] else float("nan")
        z1 = r["peaks"][0][1] if r["peaks"] else float("nan")
        first = f"{r['zeta'][0]:.4f}" if r["zeta"] else "–"
        last = f"{r['zeta'][-1]:.4f} (k = {len(r['zeta'])})" if r["zeta"] else "–"
        lines.append(f"| {r['eta']:g} | {r['period']:.4f} | {z1:.4f} | {first} | {last} | "
                     f"{r['eta'] * omega / 2:.4f} | {r['dissipated'] / r['energy']:.4f} |")
    table = "\n".join(lines) + "\n"
    print(table, end="")
    if a.table:
        with open(a.table, "w") as f:
            f.write(table)


if __name__ == "__main__":
    main()
