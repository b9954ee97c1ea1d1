#!/usr/bin/python3
"""Figures of examples/springs_free_flight from the runs of conservation.py.

usage: plot.py [--undamped DIR] [--damped DIR] [--c C] [-o FIGDIR]

Reads history.csv and forces.csv of the undamped run (default
out/springs_free_flight_study/reparametrized) and of the damped run (default
out/springs_free_flight_study/damped, with a dissipated_energy column) and writes to FIGDIR
(default examples/springs_free_flight/figures):

  energy.png  kinetic, potential and total energy of the undamped run; the damped run's total
              energy E, dissipated energy D and E + D; the relative errors (E − E₀)/E₀
              (undamped) and (E + D − E₀)/E₀ (damped)
  forces.png  the force N = k (ζ − L) + c ζ̇ of each spring against time, undamped and damped

Run from the repository root. Needs only python3 and matplotlib. Exit status 2 for a missing file
or column.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from isoflex_csv import fail, numbers, rows  # noqa: E402

STUDY = "out/springs_free_flight_study"


def history(path, names):
    h = {name: [] for name in names}
    for n, r in rows(path, names):
        for name, v in numbers(path, n, r, names).items():
            h[name].append(v)
    if not h["t"]:
        fail(f"{path} has no data rows")
    return h


def forces(path):
    """{spring: (t, N)} in the order of the file."""
    out = {}
    for n, r in rows(path, ["t", "spring", "force"]):
        v = numbers(path, n, r, ["t", "force"])
        t, f = out.setdefault(r["spring"], ([], []))
        t.append(v["t"])
        f.append(v["force"])
    if not out:
        fail(f"{path} has no data rows")
    return out


def plot_energy(u, d, c, path):
    fig, (ax1, ax2, ax3) = plt.subplots(3, 1, sharex=True, figsize=(8, 8.5),
                                        gridspec_kw={"height_ratios": [3, 3, 2]})
    ax1.plot(u["t"], u["kinetic_energy"], label="kinetic")
    ax1.plot(u["t"], u["potential_energy"], label="potential (springs + plate strain)")
    ax1.plot(u["t"], u["total_energy"], color="k", label="total E")
    ax1.set_ylabel("energy (J)")
    ax1.set_title("undamped")
    ax1.set_ylim(0.0, 1.3 * max(u["total_energy"]))
    ax1.legend(loc="upper center", ncol=3)

    ed = [e + x for e, x in zip(d["total_energy"], d["dissipated_energy"])]
    ax2.plot(d["t"], d["total_energy"], color="C2", label="total E")
    ax2.plot(d["t"], d["dissipated_energy"], color="C3", label="dissipated D")
    ax2.plot(d["t"], ed, color="k", label="E + D")
    ax2.set_ylabel("energy (J)")
    ax2.set_title(f"damped: c = {c:g} on every spring")
    ax2.set_ylim(0.0, 1.3 * max(ed))
    ax2.legend(loc="upper center", ncol=3)

    e0 = u["total_energy"][0]
    ax3.plot(u["t"], [(e - e0) / e0 for e in u["total_energy"]], color="C0",
             label="undamped: (E − E₀) / E₀")
    ed0 = ed[0]
    ax3.plot(d["t"], [(e - ed0) / ed0 for e in ed], color="C3",
             label="damped: (E + D − E₀) / E₀")
    ax3.set_ylabel("relative error")
    ax3.set_xlabel("t (s)")
    ax3.legend(loc="best", fontsize="small")
    for ax in (ax1, ax2, ax3):
        ax.grid(True, alpha=0.3)
    fig.suptitle("Springs in free flight: energy")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_forces(fu, fd, c, path):
    fig, axes = plt.subplots(2, 1, sharex=True, sharey=True, figsize=(8, 6.5))
    for ax, f, title in ((axes[0], fu, "undamped"), (axes[1], fd, f"damped: c = {c:g}")):
        for i, (name, (t, n)) in enumerate(f.items()):
            ax.plot(t, n, color=f"C{i}", label=name)
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_ylabel("force N (N), > 0 tension")
        ax.set_title(title)
        ax.legend(loc="upper center", ncol=3)
        ax.grid(True, alpha=0.3)
    lo = min(min(n) for f in (fu, fd) for _, n in f.values())
    hi = max(max(n) for f in (fu, fd) for _, n in f.values())
    axes[0].set_ylim(lo - 0.05 * (hi - lo), hi + 0.3 * (hi - lo))
    axes[1].set_xlabel("t (s)")
    fig.suptitle("Spring forces (forces.csv)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--undamped", default=f"{STUDY}/reparametrized",
                   help=f"output directory of the undamped run (default {STUDY}/reparametrized)")
    p.add_argument("--damped", default=f"{STUDY}/damped",
                   help=f"output directory of the damped run (default {STUDY}/damped)")
    p.add_argument("-o", "--outdir", default="examples/springs_free_flight/figures",
                   help="directory for the PNG files (default examples/springs_free_flight/figures)")
    p.add_argument("--c", type=float, default=3.0,
                   help="the damped run's damping, for the titles (default 3, as conservation.py)")
    a = p.parse_args(argv)
    energy = ["t", "kinetic_energy", "potential_energy", "total_energy"]
    u = history(os.path.join(a.undamped, "history.csv"), energy)
    d = history(os.path.join(a.damped, "history.csv"), energy + ["dissipated_energy"])
    fu = forces(os.path.join(a.undamped, "forces.csv"))
    fd = forces(os.path.join(a.damped, "forces.csv"))
    os.makedirs(a.outdir, exist_ok=True)
    for name, plot, args in (("energy.png", plot_energy, (u, d, a.c)),
                             ("forces.png", plot_forces, (fu, fd, a.c))):
        out = os.path.join(a.outdir, name)
        plot(*args, out)
        print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
