#!/usr/bin/python3
"""Conservation study of examples/springs_free_flight: the three energy–momentum formulations and
a damped variant.

usage: conservation.py [--isoflex ./build/isoflex] [--model MODEL] [--outdir DIR]
                       [--damping C] [--table FILE.md]

Run from the repository root. Runs the model with `isoflex run --formulation F` for
F = reparametrized, constrained, nullspace (results in DIR/F), and a copy of it with
`damping: C` on every spring (DIR/damped_model.yaml, default C = 3; reparametrized, results in
DIR/damped; the copy is checked with `isoflex check`). Prints a Markdown table (and writes it to
--table): per run the unknowns, the Newton iterations and wall time of the run (summary.json,
the numbers `isoflex run` prints), the largest relative drifts over history.csv

    energy   max |E(t) − E(0)| / |E(0)|            (damped: E + D, D = dissipated_energy)
    p        max |p(t) − p(0)| / |p(0)|            (px, py, pz)
    L        max |L(t) − L(0)| / |L(0)|            (Lx, Ly, Lz, about the origin)

and the largest distance over time between the probe `plate_corner` of the run and of the
reparametrized run (probes.csv; for the constrained and nullspace runs). Default DIR: out/springs_free_flight_study. Needs only python3
(examples/springs_free_flight/plot.py draws the figures from DIR). Exit status 2 for a bad option
or missing output, 3 if a run fails.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from isoflex_csv import fail, numbers, rows  # noqa: E402

FORMULATIONS = ("reparametrized", "constrained", "nullspace")
PROBE = "plate_corner"


def isoflex(binary, args):
    """Runs `binary args`; its stdout, or exit 3 (the run's output on stderr) if it fails."""
    try:
        r = subprocess.run([binary] + args, capture_output=True, text=True)
    except OSError as e:
        fail(f"cannot run {binary}: {e}")
    if r.returncode != 0:
        print(r.stdout + r.stderr, file=sys.stderr)
        print(f"{os.path.basename(sys.argv[0])}: error: {binary} {' '.join(args)} failed with "
              f"status {r.returncode}", file=sys.stderr)
        sys.exit(3)
    return r.stdout


def damped_copy(binary, model, path, c):
    """Writes `model` with `damping: c` after every spring's `stiffness:` line to `path` and checks
    with `isoflex check` that every spring now has that damping."""
    with open(model) as f:
        lines = f.read().splitlines(keepends=True)
    out, in_springs, inserted = [], False, 0
    for line in lines:
        top = re.match(r"^[A-Za-z_]\w*\s*:", line)
        if top:
            in_springs = line.startswith("springs:")
        out.append(line)
        m = re.match(r"^(\s*)stiffness\s*:", line)
        if in_springs and m:
            out.append(f"{m.group(1)}damping: {c:g}\n")
            inserted += 1
    if inserted == 0:
        fail(f"{model}: no `stiffness:` line (block style) under `springs:` to add damping to")
    with open(path, "w") as f:
        f.writelines(out)
    listed = [s for s in isoflex(binary, ["check", path]).splitlines() if s.startswith("spring ")]
    if len(listed) != inserted or any(f"damping {c:g}," not in s for s in listed):
        fail(f"{path}: `isoflex check` does not show damping {c:g} on every spring:\n"
             + "\n".join(listed))


def history(path):
    cols = ["t", "total_energy", "px", "py", "pz", "Lx", "Ly", "Lz", "newton_iterations"]
    h = {name: [] for name in cols + ["dissipated_energy"]}
    for n, r in rows(path, cols):
        v = numbers(path, n, r, cols + (["dissipated_energy"] if "dissipated_energy" in r else []))
        for name in h:
            h[name].append(v.get(name, 0.0))
    if not h["t"]:
        fail(f"{path} has no data rows")
    return h


def probe(path, name):
    x = []
    for n, r in rows(path, ["t", "probe", "x", "y", "z"]):
        if r["probe"] == name:
            v = numbers(path, n, r, ["x", "y", "z"])
            x.append((v["x"], v["y"], v["z"]))
    if not x:
        fail(f"{path}: no probe named {name}")
    return x


def drifts(h):
    def rel(vectors):
        v0 = vectors[0]
        s0 = math.sqrt(sum(a * a for a in v0))
        return max(math.sqrt(sum((a - b) ** 2 for a, b in zip(v, v0))) for v in vectors) / s0

    e = [et + d for et, d in zip(h["total_energy"], h["dissipated_energy"])]
    return {
        "energy": max(abs(x - e[0]) for x in e) / abs(e[0]),
        "p": rel(list(zip(h["px"], h["py"], h["pz"]))),
        "L": rel(list(zip(h["Lx"], h["Ly"], h["Lz"]))),
    }


def measure(outdir):
    hist = history(os.path.join(outdir, "history.csv"))
    summary_path = os.path.join(outdir, "summary.json")
    if not os.path.isfile(summary_path):
        fail(f"no such file: {summary_path}")
    with open(summary_path) as f:
        s = json.load(f)
    iters = [int(k) for k in hist["newton_iterations"][1:]]
    return {
        "summary": s, "history": hist, "drift": drifts(hist),
        "corner": probe(os.path.join(outdir, "probes.csv"), PROBE),
        "iters_max": max(iters), "iters_median": sorted(iters)[len(iters) // 2],
    }


def main(argv=None):
    p = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    p.add_argument("--isoflex", default="./build/isoflex", help="the isoflex binary "
                   "(default ./build/isoflex)")
    p.add_argument("--model", default="examples/springs_free_flight/model.yaml")
    p.add_argument("--outdir", default="out/springs_free_flight_study",
                   help="results of the runs (default out/springs_free_flight_study)")
    p.add_argument("--damping", type=float, default=3.0,
                   help="damping c of every spring in the damped run (default 3)")
    p.add_argument("--table", help="also write the table to this file")
    a = p.parse_args(argv)
    if not os.path.isfile(a.model):
        fail(f"no such file: {a.model}")
    if not (a.damping > 0 and math.isfinite(a.damping)):
        fail(f"--damping must be a positive number, not {a.damping}")
    os.makedirs(a.outdir, exist_ok=True)

    runs = []
    for f in FORMULATIONS:
        out = os.path.join(a.outdir, f)
        print(isoflex(a.isoflex, ["run", a.model, "-o", out, "--formulation", f]).strip(),
              file=sys.stderr)
        runs.append((f, measure(out)))
    damped_model = os.path.join(a.outdir, "damped_model.yaml")
    damped_copy(a.isoflex, a.model, damped_model, a.damping)
    out = os.path.join(a.outdir, "damped")
    print(isoflex(a.isoflex, ["run", damped_model, "-o", out]).strip(), file=sys.stderr)
    runs.append((f"damped (c = {a.damping:g}), reparametrized", measure(out)))

    ref = runs[0][1]["corner"]
    lines = [
        "| run | unknowns | Newton iterations (median, max per step) | wall time (s) | "
        "energy drift | p drift | L drift | plate_corner vs reparametrized |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, r in runs:
        s, d = r["summary"], r["drift"]
        compare = name in FORMULATIONS[1:]  # the damped run is another model
        if compare and len(r["corner"]) != len(ref):
            fail(f"{name}: {len(r['corner'])} probe rows, the reparametrized run has {len(ref)}")
        dx = max(math.dist(x, y) for x, y in zip(r["corner"], ref)) if compare else None
        lines.append(
            f"| {name} | {s['n_unknowns']} | {s['newton_iterations_total']} "
            f"({r['iters_median']}, {r['iters_max']}) | {s['wall_time_s']:.3f} | "
            f"{d['energy']:.1e} | {d['p']:.1e} | {d['L']:.1e} | "
            + ("–" if dx is None else f"{dx:.1e}") + " |")
    pairs = [(runs[i], runs[j]) for i in range(3) for j in range(i + 1, 3)]
    (n1, _), (n2, _), worst = max(
        ((x, y, max(math.dist(u, v) for u, v in zip(x[1]["corner"], y[1]["corner"])))
         for x, y in pairs), key=lambda z: z[2])
    h0 = runs[0][1]["history"]
    e0 = h0["total_energy"][0]
    dh = runs[-1][1]["history"]
    lines += [
        "",
        f"{len(h0['t']) - 1} steps to t = {h0['t'][-1]:g}; "
        f"E(0) = {e0:.11g}. The largest distance of {PROBE} between two formulations: "
        f"{worst:.1e} ({n1} vs {n2}). Damped run: energy drift is that of E + D; "
        f"D(t = {dh['t'][-1]:g}) = {dh['dissipated_energy'][-1]:.6g} "
        f"({dh['dissipated_energy'][-1] / e0:.1%} of E(0)), E = {dh['total_energy'][-1]:.6g}.",
    ]
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if a.table:
        with open(a.table, "w") as f:
            f.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
