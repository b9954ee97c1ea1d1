#!/usr/bin/python3
"""Plot the paths of the probes in an isoflex probes.csv.

usage: plot_probes.py OUTDIR_OR_PROBES_CSV [--probe NAME ...] [-o OUTDIR]

For each selected probe (default: all) writes probe_<name>.png (the path in 3D with its start and
end marked, like the orbit of DNSM-III Fig. 5, and its projections onto the xy, yz and xz planes)
and probe_<name>_components.png (x, y, z over time) to OUTDIR (default: the directory of
probes.csv). Needs only python3 and matplotlib. Exit status 2 for a missing file or column or an
unknown probe.
"""
import argparse
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from isoflex_csv import fail, numbers, rows  # noqa: E402

REQUIRED = ["t", "probe", "x", "y", "z"]
AXES = ("x", "y", "z")


def read_probes(path):
    """{probe name: {"t": [...], "x": [...], "y": [...], "z": [...]}}, in the order of the file."""
    probes = {}
    for line_no, row in rows(path, REQUIRED):
        values = numbers(path, line_no, row, ("t",) + AXES)
        series = probes.setdefault(row["probe"], {n: [] for n in ("t",) + AXES})
        for name, v in values.items():
            series[name].append(v)
    if not probes:
        fail(f"{path} has no data rows")
    return probes


def file_stem(name):
    """The probe name made safe for a file name."""
    return re.sub(r"[^A-Za-z0-9._-]", "_", name)


def cube_limits(s):
    """Equal limits on all three axes around the path (a cube in data units)."""
    lo = [min(s[a]) for a in AXES]
    hi = [max(s[a]) for a in AXES]
    size = max(max(abs(v) for v in lo + hi), 1.0)
    half = max(h - l for l, h in zip(lo, hi)) / 2.0 * 1.05
    if half <= 1e-9 * size:  # a probe at rest: a box of 10 % of its distance from the origin
        half = 0.05 * size
    return [((l + h) / 2.0 - half, (l + h) / 2.0 + half) for l, h in zip(lo, hi)]


def mark_ends(ax, *coords):
    # the start as a ring around the end's square, so that both show when they coincide
    ax.plot(*[[c[0]] for c in coords], "o", color="C2", ms=10, mfc="none", mew=2, label="start")
    ax.plot(*[[c[-1]] for c in coords], "s", color="C3", ms=6, label="end")


def plot_path(name, s, out):
    fig = plt.figure(figsize=(10, 9))
    ax = fig.add_subplot(2, 2, 1, projection="3d")
    ax.plot(s["x"], s["y"], s["z"], color="C0", lw=1.0, label="path")
    mark_ends(ax, s["x"], s["y"], s["z"])
    for (lo, hi), setter in zip(cube_limits(s), (ax.set_xlim, ax.set_ylim, ax.set_zlim)):
        setter(lo, hi)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    ax.set_title("3D path")
    ax.legend(loc="upper left", fontsize="small")
    for position, (a, b) in zip((2, 3, 4), (("x", "y"), ("y", "z"), ("x", "z"))):
        ax = fig.add_subplot(2, 2, position)
        ax.plot(s[a], s[b], color="C0", lw=1.0)
        mark_ends(ax, s[a], s[b])
        ax.set_aspect("equal", adjustable="datalim")
        if max(s[a]) == min(s[a]) and max(s[b]) == min(s[b]):
            ax.text(0.5, 0.9, "the path projects onto one point", transform=ax.transAxes,
                    ha="center")
        ax.set_xlabel(a)
        ax.set_ylabel(b)
        ax.set_title(f"{a}{b} projection")
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"Probe '{name}': path, t = {s['t'][0]:g} … {s['t'][-1]:g}")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def plot_components(name, s, out):
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 7.5))
    for ax, a, color in zip(axes, AXES, ("C0", "C1", "C2")):
        ax.plot(s["t"], s[a], color=color)
        ax.set_ylabel(a)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("t")
    fig.suptitle(f"Probe '{name}': position")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description="Plot the probe paths of an isoflex run.")
    parser.add_argument("source", metavar="OUTDIR_OR_PROBES_CSV",
                        help="output directory of isoflex run, or its probes.csv")
    parser.add_argument("--probe", action="append", metavar="NAME",
                        help="plot this probe (repeatable; default: all)")
    parser.add_argument("-o", "--outdir", help="directory for the PNG files (default: next to "
                        "probes.csv)")
    args = parser.parse_args(argv)
    path = args.source
    if os.path.isdir(path):
        path = os.path.join(path, "probes.csv")
    probes = read_probes(path)
    selected = list(dict.fromkeys(args.probe)) if args.probe else list(probes)
    unknown = [name for name in selected if name not in probes]
    if unknown:
        fail(f"unknown probe(s) {', '.join(unknown)} in {path}; available: "
             f"{', '.join(probes)}")
    outdir = args.outdir or os.path.dirname(os.path.abspath(path))
    os.makedirs(outdir, exist_ok=True)
    for name in selected:
        stem = os.path.join(outdir, f"probe_{file_stem(name)}")
        plot_path(name, probes[name], stem + ".png")
        plot_components(name, probes[name], stem + "_components.png")
        print(stem + ".png")
        print(stem + "_components.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
