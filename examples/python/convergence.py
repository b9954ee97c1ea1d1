#!/usr/bin/env python3
"""p/h convergence of the Kirchhoff–Love Scordelis–Lo roof (IGA-thesis §6.4.1.2): the vertical
displacement of the midpoint of the free edge against the converged Kirchhoff–Love value 0.3006
(shared/data/references.md), for degrees p = 2 … 4 and N × N elements, each a static solve in
memory (no result file is written).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/convergence.py
    ... --degrees 2 3 4 --elements 2 4 8 16 -o examples/python/figures/convergence.png
"""
import argparse
import os
import sys

import isoflex

HERE = os.path.dirname(os.path.abspath(__file__))
MODEL = os.path.join(HERE, "..", "scordelis_lo", "kl_shell.yaml")
REFERENCE = 0.3006


def solve(p, n):
    """−u_y at the probe and the number of unknowns, on the quarter model with degree p and
    n × n elements (the built-in surface: degree 2 along the arc, 1 along the axis, one element)."""
    model = isoflex.Model(MODEL)
    model.set("surfaces[roof].refine", {"elevate": [p - 2, p - 1],
                                        "knots_per_span": [n - 1, n - 1]})
    sim = isoflex.Simulation(model)
    sim.solve()
    return -sim.probes["ref"]["displacement"][1], sim.unknowns


def main():
    a = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    a.add_argument("--degrees", type=int, nargs="+", default=[2, 3, 4])
    a.add_argument("--elements", type=int, nargs="+", default=[2, 4, 8, 16, 32])
    a.add_argument("-o", "--output", default=os.path.join(HERE, "figures", "convergence.png"))
    args = a.parse_args()

    table = {}
    print(f"{'p':>2} {'N':>4} {'unknowns':>9} {'-u_y':>10} {'error vs 0.3006':>16}")
    for p in args.degrees:
        for n in args.elements:
            u, unknowns = solve(p, n)
            table.setdefault(p, []).append((unknowns, u))
            print(f"{p:2d} {n:4d} {unknowns:9d} {u:10.6f} {u / REFERENCE - 1:+16.3%}")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for p, rows in table.items():
        ax.loglog([r[0] for r in rows], [abs(r[1] / REFERENCE - 1) for r in rows], "o-",
                  label=f"p = {p}")
    ax.set_xlabel("unknowns")
    ax.set_ylabel("|u_y / 0.3006 − 1|")
    ax.set_title("Scordelis–Lo roof, Kirchhoff–Love: p/h convergence")
    ax.grid(True, which="both", lw=0.3)
    ax.legend()
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    fig.savefig(args.output, dpi=120, bbox_inches="tight")
    print(f"figure: {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
