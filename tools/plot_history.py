#!/usr/bin/python3
"""Plot an isoflex history.csv: energy, momentum and constraint/Newton diagnostics.

usage: plot_history.py HISTORY_CSV [-o OUTDIR] [--reference-time T]

Writes energy.png, momentum.png and constraints.png to OUTDIR (default: the directory of
HISTORY_CSV). With --reference-time T the energy drift is taken relative to E(T) and shown for
t >= T (for runs whose loads act until T). Needs only python3 and matplotlib. Exit status 2 for a
missing file or columns or a reference time after the last step.
"""
import argparse
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

from isoflex_csv import fail, numbers, rows  # noqa: E402

REQUIRED = [
    "t", "kinetic_energy", "potential_energy", "total_energy", "px", "py", "pz", "Lx", "Ly", "Lz",
    "constraint_violation", "newton_iterations",
]


def read_columns(path):
    """The columns of a CSV file as lists of floats, keyed by header name."""
    columns = None
    for line_no, row in rows(path, REQUIRED):
        if columns is None:
            columns = {name: [] for name in row}
        for name, v in numbers(path, line_no, row, row.keys()).items():
            columns[name].append(v)
    if not columns:
        fail(f"{path} has no data rows")
    return columns


def reference_index(t, t_ref):
    """The first row at or after t_ref (allowing for round-off in the accumulated time)."""
    tolerance = 1e-9 * max(1.0, abs(t_ref))
    for i, ti in enumerate(t):
        if ti >= t_ref - tolerance:
            return i
    fail(f"--reference-time {t_ref:g} is after the last time {t[-1]:g}")


def plot_energy(c, out, t_ref=None):
    t = c["t"]
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6.5))
    ax1.plot(t, c["kinetic_energy"], label="kinetic")
    ax1.plot(t, c["potential_energy"],
             label="potential" if t_ref is None else "potential (strain + gravity)")
    ax1.plot(t, c["total_energy"], label="total", color="k")
    ax1.set_ylabel("energy")
    ax1.legend(loc="best")
    ax1.grid(True, alpha=0.3)
    if t_ref is None:
        e0 = c["total_energy"][0]
        scale = abs(e0)
        if scale > 0.0:
            drift = [(e - e0) / scale for e in c["total_energy"]]
            ax2.set_ylabel("(E − E₀) / |E₀|")
        else:
            drift = [e - e0 for e in c["total_energy"]]
            ax2.set_ylabel("E − E₀  (E₀ = 0)")
        ax2.plot(t, drift, color="k")
    else:
        i = reference_index(t, t_ref)
        e_ref = c["total_energy"][i]
        scale = abs(e_ref)
        if scale > 0.0:
            drift = [(e - e_ref) / scale for e in c["total_energy"][i:]]
            ax2.set_ylabel("(E − E(T)) / |E(T)|")
        else:
            drift = [e - e_ref for e in c["total_energy"][i:]]
            ax2.set_ylabel("E − E(T)  (E(T) = 0)")
        ax2.plot(t[i:], drift, color="k", label="t ≥ T")
        for ax in (ax1, ax2):
            ax.axvline(t[i], color="0.5", ls=":", lw=1.0)
        ax2.plot([], [], color="0.5", ls=":", lw=1.0, label=f"T = {t[i]:g}")
        ax2.legend(loc="best")
    ax2.set_xlabel("t")
    ax2.grid(True, alpha=0.3)
    fig.suptitle("Energy")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def plot_momentum(c, out):
    t = c["t"]
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6.5))
    for name in ("px", "py", "pz"):
        ax1.plot(t, c[name], label=name)
    ax1.set_ylabel("linear momentum")
    ax1.legend(loc="best")
    ax1.grid(True, alpha=0.3)
    for name in ("Lx", "Ly", "Lz"):
        ax2.plot(t, c[name], label=name)
    ax2.set_ylabel("angular momentum (origin)")
    ax2.set_xlabel("t")
    ax2.legend(loc="best")
    ax2.grid(True, alpha=0.3)
    fig.suptitle("Momentum")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def plot_constraints(c, out):
    t = c["t"]
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6.5))
    viol = c["constraint_violation"]
    positive = [v for v in viol if v > 0.0 and math.isfinite(v)]
    if positive:
        # zeros (e.g. the initial state) cannot be drawn on a log axis: leave gaps
        ax1.semilogy(t, [v if v > 0.0 else math.nan for v in viol], color="C3")
    else:
        ax1.plot(t, viol, color="C3")
        ax1.text(0.5, 0.5, "all zero", transform=ax1.transAxes, ha="center")
    ax1.set_ylabel("max |Φ|")
    ax1.grid(True, which="both", alpha=0.3)
    ax2.step(t, c["newton_iterations"], where="mid", color="C0")
    ax2.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax2.set_ylabel("Newton iterations")
    ax2.set_xlabel("t")
    ax2.grid(True, alpha=0.3)
    fig.suptitle("Constraints and Newton iterations")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description="Plot an isoflex history.csv.")
    parser.add_argument("history", metavar="HISTORY_CSV", help="history.csv written by isoflex")
    parser.add_argument("-o", "--outdir", help="directory for the PNG files (default: next to "
                        "HISTORY_CSV)")
    parser.add_argument("--reference-time", type=float, metavar="T",
                        help="show the energy drift (E − E(T))/|E(T)| for t >= T, e.g. the time "
                        "at which the loads stop")
    args = parser.parse_args(argv)
    if args.reference_time is not None and not math.isfinite(args.reference_time):
        fail(f"--reference-time must be a finite number, not {args.reference_time}")
    columns = read_columns(args.history)
    if args.reference_time is not None:
        reference_index(columns["t"], args.reference_time)  # fails before anything is written
    outdir = args.outdir or os.path.dirname(os.path.abspath(args.history))
    os.makedirs(outdir, exist_ok=True)
    written = []
    for name, plot in (("energy.png", plot_energy), ("momentum.png", plot_momentum),
                       ("constraints.png", plot_constraints)):
        path = os.path.join(outdir, name)
        if plot is plot_energy:
            plot(columns, path, args.reference_time)
        else:
            plot(columns, path)
        written.append(path)
    for path in written:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
