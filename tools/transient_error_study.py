#!/usr/bin/python3
"""Error in time of a transient Kirchhoff–Love plate against a refined solution (IGA-thesis
§6.4.1.5, Fig. 6.15): the L² error of the displacement field over the plate, at every step, for
several NURBS degrees at one element size, with one or more time integrators.

usage: transient_error_study.py MODEL [--degrees 2,3,4,5] [--elements 4]
                                [--reference 5,128] [--integrators bdf1,generalized_alpha,...]
                                [--gauss 16,4,3] [--t-end T] [--isoflex build/isoflex]
                                [--outdir DIR] [--table FILE.md]

MODEL's first surface must be a `builtin: {type: rectangle, size: [lx, ly]}` (degree 1 × 1, one
element; `corner` optional) carrying its first kl_shells entry. For every integrator and degree p
the surface is refined to degree p in both directions with --elements equal elements along u (one
across v), the same for the reference (degree, elements along u), and every variant is run with
`isoflex run` (solver.integrator set, --t-end overriding the end time). The probes are replaced
by a Gauss grid on the rectangle (--gauss NU,GU,GV: NU equal intervals along u with GU
Gauss–Legendre points each, GV points across v), and the error at time t is

    e(t) = ( ∫_Ω |u_h(X, t) − u_ref(X, t)|² dA )^½

with the same rule for every variant (the material points are the same in all of them: the
rectangle's parametrization is affine at every refinement). Each variant is compared with the
reference of its own integrator, so e(t) is the error of the spatial discretization at the same
Δt. Writes l2_error.png (e against t, one panel per integrator: Fig. 6.15) and l2_error.csv
(integrator, p, t, l2_error) to --outdir (default: the model's folder/figures), and a Markdown table (--table: max e, e at the end, unknowns, Newton
iterations, wall time per run). Exit status 2 on a bad model or option, 3 if a run fails.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

import numpy as np
import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from isoflex_csv import fail, numbers, rows  # noqa: E402

INTEGRATORS = ("energy_momentum", "generalized_alpha", "bdf1", "bdf2")


def int_list(text, option):
    try:
        values = [int(v) for v in text.split(",")]
    except ValueError:
        fail(f"{option}: expected integers separated by commas, got {text!r}")
    if any(v < 1 for v in values):
        fail(f"{option}: every value must be ≥ 1, got {text!r}")
    return values


def rectangle(model, path):
    """(corner, lx, ly, surface, shell) of the model's first surface, a builtin rectangle."""
    surfaces = model.get("surfaces") or []
    shells = model.get("kl_shells") or []
    if not surfaces or not shells:
        fail(f"{path}: needs a surface and a kl_shells entry")
    s = surfaces[0]
    b = s.get("builtin") or {}
    if b.get("type") != "rectangle" or "size" not in b:
        fail(f"{path}: surfaces[0] must be a builtin rectangle with size [lx, ly]")
    if shells[0].get("surface") != s.get("name"):
        fail(f"{path}: kl_shells[0] must be on surfaces[0]")
    corner = np.array(b.get("corner", [0.0, 0.0, 0.0]), dtype=float)
    return corner, float(b["size"][0]), float(b["size"][1]), s, shells[0]


def gauss_grid(corner, lx, ly, nu, gu, gv):
    """Points (x, y, z) and area weights of the composite Gauss rule on the rectangle."""
    xu, wu = np.polynomial.legendre.leggauss(gu)
    xv, wv = np.polynomial.legendre.leggauss(gv)
    pts, w = [], []
    h = lx / nu
    for k in range(nu):
        for a, wa in zip(xu, wu):
            x = h * (k + 0.5 * (a + 1.0))
            for b, wb in zip(xv, wv):
                y = 0.5 * ly * (b + 1.0)
                pts.append(corner + np.array([x, y, 0.0]))
                w.append(0.25 * h * ly * wa * wb)
    return pts, np.array(w)


def run_variant(a, model, surface, shell_name, integrator, degree, elements, points, tmp):
    """Runs one variant; returns (times, displacements [steps × points × 3], summary)."""
    surface["refine"] = {"elevate": [degree - 1, degree - 1], "knots_per_span": [elements - 1, 0]}
    model.setdefault("solver", {})["integrator"] = integrator
    model["probes"] = [{"name": f"g{i}", "shell": shell_name, "point": [float(c) for c in p]}
                       for i, p in enumerate(points)]
    model.setdefault("output", {})["vtk_every"] = 0
    tag = f"{integrator}_p{degree}_n{elements}"
    path = os.path.join(tmp, tag + ".yaml")
    with open(path, "w") as f:
        yaml.safe_dump(model, f, sort_keys=False)
    out = os.path.join(tmp, "out_" + tag)
    cmd = [a.isoflex, "run", path, "-o", out]
    if a.t_end:
        cmd += ["--t-end", str(a.t_end)]
    print(f"  {tag}", flush=True)
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        print(run.stdout + run.stderr, file=sys.stderr)
        sys.exit(3 if run.returncode == 3 else 2)
    probes = os.path.join(out, "probes.csv")
    index = {f"g{i}": i for i in range(len(points))}
    steps = {}
    for n, r in rows(probes, ["t", "probe", "ux", "uy", "uz"]):
        v = numbers(probes, n, r, ["t", "ux", "uy", "uz"])
        i = index.get(r["probe"])
        if i is None:
            continue
        u = steps.setdefault(round(v["t"], 9), np.full((len(points), 3), np.nan))
        u[i] = (v["ux"], v["uy"], v["uz"])
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    times = sorted(steps)
    return times, np.array([steps[t] for t in times]), summary


def l2_errors(times, u, ref_times, u_ref, weights):
    """e(t) at the times both runs have."""
    ref = {t: k for k, t in enumerate(ref_times)}
    ts, es = [], []
    for k, t in enumerate(times):
        j = ref.get(t)
        if j is None:
            continue
        d = u[k] - u_ref[j]
        ts.append(t)
        es.append(math.sqrt(float(np.sum(weights * np.sum(d * d, axis=1)))))
    return ts, es


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("model")
    p.add_argument("--degrees", default="2,3,4,5")
    p.add_argument("--elements", type=int, default=4)
    p.add_argument("--reference", default="5,128", help="DEGREE,ELEMENTS of the reference")
    p.add_argument("--integrators", default="bdf1,generalized_alpha,energy_momentum")
    p.add_argument("--gauss", default="16,4,3", help="NU,GU,GV of the Gauss grid")
    p.add_argument("--t-end", type=float)
    p.add_argument("--isoflex", default="build/isoflex")
    p.add_argument("--outdir")
    p.add_argument("--table")
    a = p.parse_args()
    degrees = int_list(a.degrees, "--degrees")
    reference = int_list(a.reference, "--reference")
    if len(reference) != 2:
        fail(f"--reference: expected DEGREE,ELEMENTS, got {a.reference!r}")
    ref_p, ref_n = reference
    gauss = int_list(a.gauss, "--gauss")
    if len(gauss) != 3:
        fail(f"--gauss: expected NU,GU,GV, got {a.gauss!r}")
    integrators = a.integrators.split(",")
    for i in integrators:
        if i not in INTEGRATORS:
            fail(f"--integrators: unknown integrator {i!r} (one of {', '.join(INTEGRATORS)})")
    if a.elements < 1 or any(d > 10 for d in degrees + [ref_p]):
        fail("--elements must be ≥ 1 and the degrees ≤ 10")
    if not os.path.isfile(a.model):
        fail(f"no such file: {a.model}")
    if not os.path.isfile(a.isoflex):
        fail(f"no isoflex binary at {a.isoflex} (--isoflex)")
    with open(a.model) as f:
        try:
            model = yaml.safe_load(f)
        except yaml.YAMLError as e:
            fail(f"{a.model}: {e}")
    if not isinstance(model, dict):
        fail(f"{a.model}: not a model file")
    corner, lx, ly, surface, shell = rectangle(model, a.model)
    points, weights = gauss_grid(corner, lx, ly, *gauss)
    outdir = a.outdir or os.path.join(os.path.dirname(os.path.abspath(a.model)), "figures")
    os.makedirs(outdir, exist_ok=True)

    curves, lines = {}, []
    lines.append("| integrator | p | elements | unknowns | max e(t) | e(t_end) | max e / max ‖u_ref‖ "
                 "| Newton it. | wall (s) |")
    lines.append("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as tmp:
        for integ in integrators:
            rt, ru, rs = run_variant(a, model, surface, shell["name"], integ, ref_p, ref_n, points,
                                     tmp)
            norms = [math.sqrt(float(np.sum(weights * np.sum(u * u, axis=1)))) for u in ru]
            lines.append(f"| {integ} | {ref_p} (reference) | {ref_n} | {rs['n_unknowns']} | – | – "
                         f"| ‖u_ref‖ ≤ {max(norms):.4g} | {rs['newton_iterations_total']} | "
                         f"{rs['wall_time_s']:.1f} |")
            curves[integ] = []
            for d in degrees:
                t, u, s = run_variant(a, model, surface, shell["name"], integ, d, a.elements,
                                      points, tmp)
                ts, es = l2_errors(t, u, rt, ru, weights)
                if not ts:
                    fail(f"{integ}, p = {d}: no time in common with the reference")
                curves[integ].append((d, ts, es))
                lines.append(f"| {integ} | {d} | {a.elements} | {s['n_unknowns']} | "
                             f"{max(es):.3e} | {es[-1]:.3e} | {max(es) / max(norms):.2e} | "
                             f"{s['newton_iterations_total']} | "
                             f"{s['wall_time_s']:.1f} |")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(integrators), figsize=(4.2 * len(integrators), 4),
                             sharey=True, squeeze=False)
    for ax, integ in zip(axes[0], integrators):
        for d, ts, es in curves[integ]:
            ax.semilogy(ts[1:], es[1:], lw=0.9, label=f"p = {d}")  # e(0) = 0
        ax.set_title(integ)
        ax.set_xlabel("t")
        ax.grid(alpha=0.3, which="both")
    axes[0][0].set_ylabel("L² error of the displacement")
    axes[0][-1].legend()
    fig.suptitle(f"L² error against p = {ref_p}, {ref_n} elements (IGA-thesis Fig. 6.15); "
                 f"h = {lx / a.elements:g}")
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "l2_error.png"), dpi=120)
    with open(os.path.join(outdir, "l2_error.csv"), "w") as f:
        f.write("integrator,p,t,l2_error\n")
        for integ in integrators:
            for d, ts, es in curves[integ]:
                f.writelines(f"{integ},{d},{t!r},{e!r}\n" for t, e in zip(ts, es))
    text = "\n".join(lines) + "\n"
    print(text)
    if a.table:
        with open(a.table, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
