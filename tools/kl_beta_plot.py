#!/usr/bin/python3
"""Plot a multipatch penalty study (like IGA-thesis Figs. 6.17, 6.21, 6.23, 6.26).

usage: kl_beta_plot.py CSV --out FILE.png [--component x|y|z|angle] [--reference VALUE]
                       [--reference-label TEXT] [--single-condition VALUE] [--title TEXT]

CSV is the output of bench/kl_multipatch_bench (coupling, beta, ux, uy, uz, newton_iterations,
unknowns, condition_number[, angle_error]). Left: the probe's displacement component (or with
`angle` the relative angle error |θ − θ₀|/θ₀, log scale) against β₁ for the bending strips, with
the reference value as a line; right: the condition number of the Newton matrix against β₁, with
the single patch's as a line. Rows of other couplings (no β₁: c0, strip_constraints, angle) are
drawn as horizontal lines in both; failed runs (empty columns) and infinite condition numbers are
left out and listed on stderr. Exit status 2 on a bad file or option.
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def fail(msg):
    print(f"kl_beta_plot: {msg}", file=sys.stderr)
    sys.exit(2)


def number(text):
    try:
        v = float(text)
    except ValueError:
        return None
    return v if math.isfinite(v) else None


def finite_points(rows, column, missing):
    """(β₁, value) of the rows with a finite value in `column`; the others reported on stderr."""
    out = []
    for r in rows:
        v = number(r[column])
        if v is None:
            print(f"kl_beta_plot: beta {float(r['beta']):g}: {missing}", file=sys.stderr)
        else:
            out.append((float(r["beta"]), v))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv")
    ap.add_argument("--out", required=True)
    ap.add_argument("--component", choices=["x", "y", "z", "angle"], default="x")
    ap.add_argument("--reference", type=float)
    ap.add_argument("--reference-label", default="reference")
    ap.add_argument("--single-condition", type=float)
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    try:
        with open(a.csv, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        fail(f"{a.csv}: {e.strerror}")
    need = {"coupling", "beta", "ux", "uy", "uz", "condition_number"}
    if not rows or not need <= set(rows[0]):
        fail(f"{a.csv}: expected the columns {', '.join(sorted(need))}")
    key = "angle_error" if a.component == "angle" else "u" + a.component
    if key not in rows[0]:
        fail(f"{a.csv}: no column {key} (run the bench with --angle-at)")
    strips = [r for r in rows if r["coupling"] == "bending_strip"]
    others = [r for r in rows if r["coupling"] != "bending_strip"]
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    pts = finite_points(strips, key, "no result (the run failed)")
    plot = left.loglog if a.component == "angle" else left.semilogx
    plot([b for b, _ in pts], [u for _, u in pts], "o-", label="bending strip (SBSM)")
    if a.reference is not None:
        left.axhline(a.reference, color="k", ls="--", lw=1, label=a.reference_label)
    for r in others:
        u = number(r[key])
        if u is not None:
            left.axhline(u, ls=":", color=f"C{1 + others.index(r)}", label=r["coupling"])
    left.set_xlabel("β₁ = E_s / E")
    left.set_ylabel("|θ − θ₀| / θ₀ at the joint" if a.component == "angle"
                    else f"{a.component}-displacement of the probe")
    left.grid(True, which="both", alpha=0.3)
    left.legend()
    cond = finite_points(strips, "condition_number", "no finite condition number")
    right.loglog([b for b, _ in cond], [c for _, c in cond], "o-", label="bending strip (SBSM)")
    if a.single_condition is not None:
        right.axhline(a.single_condition, color="k", ls="--", lw=1, label="single patch")
    for r in others:
        c = number(r["condition_number"])
        if c is not None:
            right.axhline(c, ls=":", color=f"C{1 + others.index(r)}", label=r["coupling"])
    right.set_xlabel("β₁ = E_s / E")
    right.set_ylabel("condition number of the Newton matrix")
    right.grid(True, which="both", alpha=0.3)
    right.legend()
    if a.title:
        fig.suptitle(a.title)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    fig.savefig(a.out, dpi=120)


if __name__ == "__main__":
    main()
