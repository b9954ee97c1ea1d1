#!/usr/bin/env python3
"""Load–displacement paths of the hinged cylindrical roof (README.md) from three runs:

    isoflex run examples/kl_snap_through/model.yaml -o OUT/model
    isoflex run examples/kl_snap_through/arc_length.yaml -o OUT/arc_length
    isoflex run examples/kl_snap_through/thin_arc_length.yaml -o OUT/thin_arc_length
    python3 examples/kl_snap_through/plot_path.py OUT [figure.png]

The load P = 3000 λ (λ the load factor, history.csv column t) against the centre's inward
displacement w (probe `centre` along the radial direction at 0.1 rad, probes.csv). Writes the
figure (default examples/kl_snap_through/figures/load_displacement.png) and prints the limit
points of each path.
"""
import csv
import math
import os
import sys

INWARD = (-math.cos(0.1), -math.sin(0.1), 0.0)
RUNS = [("model", "t = 12.7, displacement control"),
        ("arc_length", "t = 12.7, arc length"),
        ("thin_arc_length", "t = 6.35, arc length")]


def path(run_dir):
    with open(os.path.join(run_dir, "history.csv")) as f:
        loads = [3000.0 * float(r["t"]) for r in csv.DictReader(f)]
    with open(os.path.join(run_dir, "probes.csv")) as f:
        w = [sum(d * float(r[k]) for d, k in zip(INWARD, ("ux", "uy", "uz")))
             for r in csv.DictReader(f) if r["probe"] == "centre"]
    return w, loads


def limit_points(w, p):
    """(w, P) at the sampled extrema of P along the path."""
    return [(w[i], p[i]) for i in range(1, len(p) - 1)
            if (p[i] - p[i - 1]) * (p[i + 1] - p[i]) < 0]


def main():
    out = sys.argv[1]
    here = os.path.dirname(os.path.abspath(__file__))
    figure = sys.argv[2] if len(sys.argv) > 2 else os.path.join(here, "figures",
                                                                "load_displacement.png")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    styles = ["o", "-", "-"]
    for (name, label), style in zip(RUNS, styles):
        w, p = path(os.path.join(out, name))
        ax.plot(w, p, style, ms=3, lw=1.2, label=label)
        lims = ", ".join(f"P = {b:.4g} at w = {a:.4g}" for a, b in limit_points(w, p))
        print(f"{name}: {len(p) - 1} steps, limit points {lims}")
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel("inward displacement of the centre w")
    ax.set_ylabel("point load P")
    ax.set_title("Hinged cylindrical roof (R = 2540, 0.2 rad, L = 508), KL shell p = 3, 8 × 8")
    ax.legend()
    ax.grid(alpha=0.3)
    os.makedirs(os.path.dirname(figure), exist_ok=True)
    fig.tight_layout()
    fig.savefig(figure, dpi=120)
    print(f"wrote {figure}")


if __name__ == "__main__":
    main()
