#!/usr/bin/python3
"""Convergence study of the Kirchhoff–Love plate roll-up (kl_shell.yaml): degree p and elements N
along the plate (one element across the width: with ν = 0 the solution does not vary across it).

usage: kl_study.py [--isoflex build/isoflex] [--degrees 2,3,4,5] [--elements 1,2,4,8,16,32,64]
                   [--from-csv FILE.csv] [--table FILE.md] [--csv FILE.csv] [--plot PREFIX]

For every p and N the surface of kl_shell.yaml is refined to `elevate: [p − 1, p − 1],
knots_per_span: [N − 1, 0]` and run with `isoflex run --static`; the tip probe `ref` is read from
probes.csv at t = 0.25, 0.5, 1 (90°, 180°, 360°). Errors, relative to |u_exact| (8.80, 14.21, 12):
  e    = |u_h − u_exact| against the exact elastica (IGA-thesis (6.14)):
         U = L (sin θ/θ − 1), W = L (1 − cos θ)/θ;
  e_KL = |u_h − u_KL| against the Kirchhoff–Love model's own closed form, the stretched arc of
         kl_arc() (README.md);
and |U_h − U| at 180°, absolute, against both (IGA-thesis Fig. 6.9). Writes a markdown table, a
CSV (with the raw tip displacements; --from-csv reports an earlier CSV without running) and two
PNGs: PREFIX_180.png (|U_h − U| at 180° vs the element size h = L/N per p) and PREFIX_dofs.png
(e and e_KL vs DOFs, one panel per angle). A run that fails (Newton did not converge) is listed as
such, with the angles it reached.
"""
import argparse
import csv
import json
import math
import os
import re
import subprocess
import sys
import tempfile

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
L = 12.0
ANGLES = [(0.25, "90°"), (0.5, "180°"), (1.0, "360°")]


def exact(t):
    th = 2.0 * math.pi * t
    return (L * (math.sin(th) / th - 1.0), 0.0, L * (1.0 - math.cos(th)) / th)


def kl_arc(t, thickness=0.1):
    """The Kirchhoff–Love model's own exact solution: a uniformly stretched arc. With the
    Green–Lagrange membrane strain ε = ½(λ² − 1) and the bending strain measured in the reference
    metric, E^f = λ θ/L, the energy L [½ E t ε² + ½ D (λθ/L)²] − M θ is stationary at
    θ = θ₀/λ², ε = −t² θ²/(12 L²) (README.md); the tip is at λ L (sin θ/θ, 0, (1 − cos θ)/θ)."""
    th0 = 2.0 * math.pi * t
    th, lam = th0, 1.0
    for _ in range(100):
        lam = math.sqrt(1.0 - thickness**2 * th**2 / (6.0 * L**2))
        th = th0 / lam**2
    return (lam * L * math.sin(th) / th - L, 0.0, lam * L * (1.0 - math.cos(th)) / th)


def probe_rows(outdir):
    rows = {}
    with open(os.path.join(outdir, "probes.csv")) as f:
        for r in csv.DictReader(f):
            if r["probe"] == "ref":
                rows[float(r["t"])] = (float(r["ux"]), float(r["uy"]), float(r["uz"]))
    return rows


def at(rows, t):
    for tt, u in rows.items():
        if abs(tt - t) < 1e-9:
            return u
    return None


KEYS = ["p", "N", "h", "dofs", "unknowns", "status", "steps", "iterations", "wall_s",
        "U90°", "W90°", "U180°", "W180°", "U360°", "W360°",
        "e90°", "e180°", "e360°", "k90°", "k180°", "k360°", "dU180", "kU180"]


def study(a):
    degrees = [int(x) for x in a.degrees.split(",")]
    elements = [int(x) for x in a.elements.split(",")]
    with open(os.path.join(HERE, "kl_shell.yaml")) as f:
        model = yaml.safe_load(f)
    model["output"] = {"vtk_every": 0}
    results = []
    with tempfile.TemporaryDirectory() as work:
        path = os.path.join(work, "m.yaml")
        outdir = os.path.join(work, "out")
        for p in degrees:
            for n in elements:
                model["surfaces"][0]["refine"] = {"elevate": [p - 1, p - 1],
                                                  "knots_per_span": [n - 1, 0]}
                with open(path, "w") as f:
                    yaml.safe_dump(model, f)
                chk = subprocess.run([a.isoflex, "check", path], capture_output=True, text=True)
                if chk.returncode != 0:
                    sys.exit(f"check failed for p = {p}, N = {n}:\n{chk.stdout}{chk.stderr}")
                dofs = int(re.search(r"dofs +(\d+)", chk.stdout).group(1))
                unknowns = int(re.search(r"unknowns +(\d+)", chk.stdout).group(1))
                run = subprocess.run([a.isoflex, "run", "--static", path, "-o", outdir],
                                     capture_output=True, text=True)
                with open(os.path.join(outdir, "summary.json")) as f:
                    s = json.load(f)
                rows = probe_rows(outdir)
                r = dict(p=p, N=n, h=L / n, dofs=dofs, unknowns=unknowns,
                         status="ok" if run.returncode == 0 else "failed",
                         iterations=s["newton_iterations_total"], steps=s["steps"],
                         wall_s=s["wall_time_s"])
                for t, name in ANGLES:
                    u = at(rows, t)
                    r[f"U{name}"] = u[0] if u else float("nan")
                    r[f"W{name}"] = u[2] if u else float("nan")
                results.append(r)
                print(f"p={p} N={n} dofs={dofs} {r['status']} steps={r['steps']} "
                      f"it={r['iterations']} wall={r['wall_s']:.2f}s", flush=True)
    return results


def errors(r):
    for t, name in ANGLES:
        u = (r[f"U{name}"], 0.0, r[f"W{name}"])
        ue = exact(t)
        r[f"e{name}"] = math.dist(u, ue) / math.hypot(*ue)
        r[f"k{name}"] = math.dist(u, kl_arc(t)) / math.hypot(*ue)
    r["dU180"] = abs(r["U180°"] - exact(0.5)[0])
    r["kU180"] = abs(r["U180°"] - kl_arc(0.5)[0])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--isoflex", default="build/isoflex")
    ap.add_argument("--degrees", default="2,3,4,5")
    ap.add_argument("--elements", default="1,2,4,8,16,32,64")
    ap.add_argument("--from-csv", help="no runs: report the results of an earlier --csv")
    ap.add_argument("--table")
    ap.add_argument("--csv")
    ap.add_argument("--plot")
    a = ap.parse_args()
    if a.from_csv:
        with open(a.from_csv) as f:
            results = []
            for row in csv.DictReader(f):
                r = {k: row[k] for k in ("status",)}
                for k in ("p", "N", "dofs", "unknowns", "steps", "iterations"):
                    r[k] = int(row[k])
                for k in ("h", "wall_s", "U90°", "W90°", "U180°", "W180°", "U360°", "W360°"):
                    r[k] = float(row[k])
                results.append(r)
    else:
        results = study(a)
    for r in results:
        errors(r)
    report(a, results)


def fmt(v):
    return "—" if not math.isfinite(v) else f"{v:.2e}"


def report(a, results):
    for path in (a.table, a.csv, a.plot):
        if path:
            os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    if a.table:
        with open(a.table, "w") as f:
            f.write("| p | N | DOFs | e 90° | e 180° | e 360° | e_KL 90° | e_KL 180° | e_KL 360° "
                    "| \\|U−U₆.₁₄\\| 180° | \\|U−U_KL\\| 180° | Newton it. | wall s |\n"
                    "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
            for r in results:
                f.write(f"| {r['p']} | {r['N']} | {r['dofs']} | {fmt(r['e90°'])} | "
                        f"{fmt(r['e180°'])} | {fmt(r['e360°'])} | {fmt(r['k90°'])} | "
                        f"{fmt(r['k180°'])} | {fmt(r['k360°'])} | {fmt(r['dU180'])} | "
                        f"{fmt(r['kU180'])} | {r['iterations']} | {r['wall_s']:.2f} |"
                        + ("" if r["status"] == "ok" else f" failed after {r['steps']} steps")
                        + "\n")
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=KEYS, extrasaction="ignore")
            w.writeheader()
            w.writerows(results)
    if a.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        ps = sorted({r["p"] for r in results})
        fig, axs = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
        for ax, key, what in ((axs[0], "dU180", "exact elastica (6.14)"),
                              (axs[1], "kU180", "the KL model's stretched arc")):
            for p in ps:
                rs = [r for r in results if r["p"] == p and math.isfinite(r[key]) and r[key] > 0]
                ax.loglog([r["h"] for r in rs], [r[key] for r in rs], "o-", label=f"p = {p}")
            ax.set_xlabel("element size h = L/N")
            ax.set_title(f"vs {what}")
            ax.grid(True, which="both", lw=0.3)
        axs[0].set_ylabel("|U_h − U| at the tip, 180°")
        axs[0].legend()
        fig.suptitle("KL plate roll-up: tip x-displacement error at 180° (cf. IGA-thesis Fig. 6.9)")
        fig.tight_layout()
        fig.savefig(a.plot + "_180.png", dpi=120)

        fig, axs = plt.subplots(2, 3, figsize=(13, 8), sharey=True, sharex=True)
        for row, pre, what in ((0, "e", "vs (6.14)"), (1, "k", "vs the KL stretched arc")):
            for ax, (t, name) in zip(axs[row], ANGLES):
                for p in ps:
                    rs = [r for r in results
                          if r["p"] == p and math.isfinite(r[f"{pre}{name}"])]
                    ax.loglog([r["dofs"] for r in rs], [r[f"{pre}{name}"] for r in rs], "o-",
                              label=f"p = {p}")
                ax.axhline(5e-3, color="grey", ls="--", lw=0.8, label="0.5 %")
                ax.set_title(f"θ = {name} (t = {t:g}), {what}")
                ax.grid(True, which="both", lw=0.3)
            axs[row][0].set_ylabel("|u_h − u| / |u_exact| at the tip")
        for ax in axs[1]:
            ax.set_xlabel("DOFs (3 per control point)")
        axs[0][0].legend()
        fig.tight_layout()
        fig.savefig(a.plot + "_dofs.png", dpi=120)


if __name__ == "__main__":
    main()
