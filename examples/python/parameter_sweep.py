#!/usr/bin/env python3
"""Parameter sweep of the spatial slider-crank (DNSM-III §5.2): the amplitude A of the drive
force f(t) = A sin(πt) e₁ (t ≤ 2), one simulation per amplitude, no model file edited and no
result file written; plots the orbits of the connection point (probe `connection`, the crank's
middle node) in the crank's plane of motion (x, z).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/parameter_sweep.py
    ... --amplitudes 500 1000 1500 --t-end 4 -o examples/python/figures/parameter_sweep.png
"""
import argparse
import os
import sys

import numpy as np

import isoflex

HERE = os.path.dirname(os.path.abspath(__file__))
MODEL = os.path.join(HERE, "..", "slider_crank_flexible", "model.yaml")


def sweep(amplitudes, t_end):
    """Per amplitude: the connection point's orbit (N, 3) and the run's energy figures."""
    runs = {}
    for a in amplitudes:
        model = isoflex.Model(MODEL)
        model.set("solver.t_end", t_end)
        model.set("loads[drive].force", [f"{a}*sin(_pi*t)*(t<=2)", "0", "0"])
        sim = isoflex.Simulation(model)
        r = sim.run()
        runs[a] = {
            "orbit": r["probes"]["connection"]["position"],
            "t": r["t"],
            "energy": r["total_energy"],
            "work": r["external_work"],
            "iterations": int(r["newton_iterations"].sum()),
        }
    return runs


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--amplitudes", type=float, nargs="+", default=[250, 500, 1000, 1500])
    p.add_argument("--t-end", type=float, default=10.0)
    p.add_argument("-o", "--output", default=os.path.join(HERE, "figures", "parameter_sweep.png"))
    args = p.parse_args()

    runs = sweep(args.amplitudes, args.t_end)
    print(f"{'amplitude':>10} {'max |x|':>10} {'max |z|':>10} {'E - W - E0 (rel.)':>18} "
          f"{'Newton it.':>10}")
    for a, run in runs.items():
        x = run["orbit"]
        balance = run["energy"] - run["work"] - run["energy"][0]
        scale = max(np.abs(run["work"]).max(), np.abs(run["energy"]).max(), 1e-300)
        print(f"{a:10g} {np.abs(x[:, 0]).max():10.4f} {np.abs(x[:, 2]).max():10.4f} "
              f"{np.abs(balance).max() / scale:18.2e} {run['iterations']:10d}")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 5))
    for a, run in runs.items():
        ax.plot(run["orbit"][:, 0], run["orbit"][:, 2], lw=1, label=f"A = {a:g}")
    ax.set_xlabel("x of the connection point")
    ax.set_ylabel("z of the connection point")
    ax.set_title(f"Slider-crank: connection-point orbits, t ≤ {args.t_end:g}")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend()
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    fig.savefig(args.output, dpi=120, bbox_inches="tight")
    print(f"figure: {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
