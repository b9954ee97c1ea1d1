#!/usr/bin/python3
"""Convergence study of a Kirchhoff–Love shell model: degree p and knot refinement.

usage: kl_convergence.py MODEL --reference VALUE [--probe ref] [--component x|y|z|norm]
                         [--sign 1|-1] [--degrees 2,3,4,5] [--knots 0,1,3,7,15] [--t T]
                         [--isoflex build/isoflex] [--table FILE.md] [--csv FILE.csv]
                         [--plot FILE.png] [--title TEXT]

For every degree p and every k in --knots the model's Kirchhoff–Love surface is k-refined to
degree p in both directions (`refine: {elevate: [p − p_u, p − p_v], knots_per_span: [k, k]}`, the
surface's own degrees p_u, p_v read from `isoflex check` without refinement) and run with
`isoflex run --static`; the probe's displacement component (times --sign) at the end of the run,
or at load parameter --t from probes.csv, is compared with the reference. Writes a markdown table
(p, spans, control points, DOFs, unknowns, value, relative error, wall time), a CSV and a log-log
plot of |error| against DOFs per degree (like IGA-thesis Figs. 6.9–6.14). Exit status 2 on a bad
model or option, 3 if a run fails.
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


def fail(msg, code=2):
    print(f"kl_convergence: {msg}", file=sys.stderr)
    sys.exit(code)


def kl_surface(model):
    shells = model.get("kl_shells") or []
    if len(shells) != 1:
        fail("the model must have exactly one kl_shell")
    name = shells[0]["surface"]
    for s in model.get("surfaces") or []:
        if s.get("name") == name:
            return s
    fail(f"no surface {name!r}")


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def base_degrees(isoflex, model, workdir):
    m = dict(model)
    surf = kl_surface(m)
    surf.pop("refine", None)
    # A degree-1 surface is rejected by the kl_shell; check the surface alone.
    m.pop("kl_shells", None)
    m.pop("kl_supports", None)
    m.pop("kl_loads", None)
    m.pop("probes", None)
    m["bodies"] = [{"name": "dummy", "mass": 1, "inertia": [1, 1, 1], "position": [0, 0, 0]}]
    path = os.path.join(workdir, "base.yaml")
    with open(path, "w") as f:
        yaml.safe_dump(m, f)
    code, out = run([isoflex, "check", path])
    if code != 0:
        fail(f"isoflex check failed:\n{out}")
    g = re.search(r"surface +" + re.escape(surf["name"]) + r": .*?degrees (\d+) x (\d+)", out)
    if not g:
        fail(f"no degrees in:\n{out}")
    return int(g.group(1)), int(g.group(2))


def probe_value(outdir, probe, component, t):
    comps = {"x": 0, "y": 1, "z": 2}
    if t is None:
        with open(os.path.join(outdir, "summary.json")) as f:
            s = json.load(f)
        if probe not in s["probes"]:
            fail(f"no probe {probe!r} in summary.json")
        u = s["probes"][probe]["displacement"]
    else:
        u = None
        with open(os.path.join(outdir, "probes.csv")) as f:
            for row in csv.DictReader(f):
                if row["probe"] == probe and abs(float(row["t"]) - t) < 1e-9:
                    u = [float(row["ux"]), float(row["uy"]), float(row["uz"])]
        if u is None:
            fail(f"no row of probe {probe!r} at t = {t} in probes.csv")
    if component == "norm":
        return math.sqrt(sum(c * c for c in u))
    return u[comps[component]]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("model")
    ap.add_argument("--reference", type=float, required=True)
    ap.add_argument("--probe", default="ref")
    ap.add_argument("--component", default="z", choices=["x", "y", "z", "norm"])
    ap.add_argument("--sign", type=float, default=1.0)
    ap.add_argument("--degrees", default="2,3,4,5")
    ap.add_argument("--knots", default="0,1,3,7,15")
    ap.add_argument("--t", type=float, default=None)
    ap.add_argument("--isoflex", default="build/isoflex")
    ap.add_argument("--table")
    ap.add_argument("--csv")
    ap.add_argument("--plot")
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    # The output files' folders are made before the sweep, so that a path that cannot be written
    # fails at once and not after the runs (and nothing lands elsewhere).
    for path in (a.table, a.csv, a.plot):
        if path and os.path.dirname(path):
            try:
                os.makedirs(os.path.dirname(path), exist_ok=True)
            except OSError as e:
                fail(f"cannot create the folder of {path}: {e}")
    try:
        degrees = [int(x) for x in a.degrees.split(",")]
        knots = [int(x) for x in a.knots.split(",")]
    except ValueError:
        fail("--degrees and --knots are comma-separated integers")
    if not os.path.isfile(a.isoflex):
        fail(f"no isoflex executable at {a.isoflex}")
    try:
        with open(a.model) as f:
            model = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as e:
        fail(f"cannot read {a.model}: {e}")
    model_dir = os.path.dirname(os.path.abspath(a.model))
    # CAD paths are relative to the model file.
    for s in model.get("surfaces") or []:
        if "cad" in s and not os.path.isabs(s["cad"]["file"]):
            s["cad"]["file"] = os.path.join(model_dir, s["cad"]["file"])
    model.setdefault("output", {})["vtk_every"] = 0

    rows = []
    with tempfile.TemporaryDirectory() as work:
        pu, pv = base_degrees(a.isoflex, yaml.safe_load(yaml.safe_dump(model)), work)
        for p in degrees:
            if p < max(pu, pv) or p < 2:
                continue
            for k in knots:
                kl_surface(model)["refine"] = {"elevate": [p - pu, p - pv],
                                               "knots_per_span": [k, k]}
                path = os.path.join(work, "m.yaml")
                with open(path, "w") as f:
                    yaml.safe_dump(model, f)
                code, out = run([a.isoflex, "check", path])
                if code != 0:
                    fail(f"check failed for p = {p}, k = {k}:\n{out}")
                cps = int(re.search(r"control points +(\d+) \(3 coordinates", out).group(1))
                dofs = int(re.search(r"dofs +(\d+)", out).group(1))
                unknowns = int(re.search(r"unknowns +(\d+)", out).group(1))
                elements = int(re.search(r"on surface \S+: (\d+) elements", out).group(1))
                outdir = os.path.join(work, "out")
                code, out = run([a.isoflex, "run", "--static", path, "-o", outdir])
                if code != 0:
                    fail(f"run failed for p = {p}, k = {k}:\n{out}", 3)
                with open(os.path.join(outdir, "summary.json")) as f:
                    wall = json.load(f)["wall_time_s"]
                v = a.sign * probe_value(outdir, a.probe, a.component, a.t)
                err = (v - a.reference) / abs(a.reference)
                rows.append(dict(p=p, spans=int(round(math.sqrt(elements))), elements=elements,
                                 control_points=cps, dofs=dofs, unknowns=unknowns, value=v,
                                 error=err, wall_s=wall))
                print(f"p={p} k={k} elements={elements} dofs={dofs} value={v:.10g} "
                      f"error={100 * err:+.4g}% wall={wall:.3f}s", flush=True)

    if a.table:
        with open(a.table, "w") as f:
            f.write(f"| p | elements | control points | DOFs | unknowns | value | error vs "
                    f"{a.reference:g} | wall s |\n|---|---|---|---|---|---|---|---|\n")
            for r in rows:
                f.write(f"| {r['p']} | {r['elements']} | {r['control_points']} | {r['dofs']} | "
                        f"{r['unknowns']} | {r['value']:.6g} | {100 * r['error']:+.3g} % | "
                        f"{r['wall_s']:.3f} |\n")
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            w.writeheader()
            w.writerows(rows)
    if a.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4.5))
        for p in sorted({r["p"] for r in rows}):
            rs = [r for r in rows if r["p"] == p and r["error"] != 0]
            ax.loglog([r["dofs"] for r in rs], [abs(r["error"]) for r in rs], "o-",
                      label=f"p = {p}")
        ax.axhline(5e-3, color="grey", ls="--", lw=0.8, label="0.5 %")
        ax.set_xlabel("DOFs (3 per control point)")
        ax.set_ylabel(f"|relative error| vs {a.reference:g}")
        ax.set_title(a.title or os.path.basename(a.model))
        ax.grid(True, which="both", lw=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)


if __name__ == "__main__":
    main()
