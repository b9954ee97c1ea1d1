#!/usr/bin/python3
"""Plot the stress resultants of selected beam elements from an isoflex resultants.csv.

usage: plot_resultants.py OUTDIR_OR_RESULTANTS_CSV --element BEAM:INDEX [--element ...] [-o OUTDIR]

Writes resultants.png (the forces n1, n2, n3 and moments m1, m2, m3 of the selected elements over
time, in director components, as in DNSM-III Fig. 6) and resultants_norm.png (|n| and |m| over
time) to OUTDIR (default: the directory of resultants.csv). Elements are numbered from 0 along
the beam. Needs only python3 and matplotlib. Exit status 2 for a missing file or column or a bad
or unknown --element.
"""
import argparse
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from isoflex_csv import fail, numbers, rows  # noqa: E402

COMPONENTS = ["n1", "n2", "n3", "m1", "m2", "m3"]
REQUIRED = ["t", "beam", "element"] + COMPONENTS
SUBSCRIPT = {"1": "₁", "2": "₂", "3": "₃"}


def parse_element(text):
    """(beam, index) from 'BEAM:INDEX'."""
    beam, sep, index = text.rpartition(":")
    if not sep or not beam or not index.isdigit():
        fail(f"bad --element {text!r}: expected BEAM:INDEX, e.g. crank:9")
    return beam, int(index)


def read_resultants(path, wanted):
    """The series of the wanted (beam, index) elements, {key: {"t": [...], "n1": [...], ...}},
    and the element indices of every beam in the file, {beam: set of indices}."""
    series = {key: {name: [] for name in ["t"] + COMPONENTS} for key in wanted}
    beams = {}
    for line_no, row in rows(path, REQUIRED):
        values = numbers(path, line_no, row, ["t", "element"] + COMPONENTS)
        key = (row["beam"], int(values.pop("element")))
        beams.setdefault(key[0], set()).add(key[1])
        if key in series:
            for name, v in values.items():
                series[key][name].append(v)
    if not beams:
        fail(f"{path} has no data rows")
    return series, beams


def check_elements(wanted, beams, path):
    for beam, index in wanted:
        if beam not in beams:
            fail(f"unknown beam {beam!r} in --element {beam}:{index}; beams in {path}: "
                 f"{', '.join(sorted(beams))}")
        if index not in beams[beam]:
            fail(f"beam {beam!r} has no element {index}; its elements are "
                 f"{min(beams[beam])} to {max(beams[beam])}")


def label(name):
    return name[0] + SUBSCRIPT[name[1]]


def plot_components(series, out):
    fig, axes = plt.subplots(2, 3, sharex=True, figsize=(13, 7))
    for ax, name in zip(axes.flat, COMPONENTS):
        for (beam, index), s in series.items():
            ax.plot(s["t"], s[name], lw=1.0, label=f"{beam}:{index}")
        ax.set_ylabel(label(name))
        ax.grid(True, alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("t")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper right", ncol=min(len(labels), 6), title="element")
    fig.suptitle("Stress resultants (director components): forces n, moments m", x=0.02,
                 ha="left")
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    fig.savefig(out, dpi=120)
    plt.close(fig)


def plot_norms(series, out):
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6.5))
    for (beam, index), s in series.items():
        ax1.plot(s["t"], [math.hypot(*v) for v in zip(s["n1"], s["n2"], s["n3"])], lw=1.0,
                 label=f"{beam}:{index}")
        ax2.plot(s["t"], [math.hypot(*v) for v in zip(s["m1"], s["m2"], s["m3"])], lw=1.0,
                 label=f"{beam}:{index}")
    ax1.set_ylabel("|n| (force)")
    ax2.set_ylabel("|m| (moment)")
    ax2.set_xlabel("t")
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
    handles, labels = ax1.get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper right", ncol=min(len(labels), 4), title="element")
    fig.suptitle("Norms of the stress resultants", x=0.02, ha="left")
    fig.tight_layout(rect=(0, 0, 1, 0.92))
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(
        description="Plot the stress resultants of beam elements of an isoflex run.")
    parser.add_argument("source", metavar="OUTDIR_OR_RESULTANTS_CSV",
                        help="output directory of isoflex run, or its resultants.csv")
    parser.add_argument("--element", action="append", required=True, metavar="BEAM:INDEX",
                        help="plot this element (repeatable), e.g. crank:9; elements are "
                        "numbered from 0")
    parser.add_argument("-o", "--outdir", help="directory for the PNG files (default: next to "
                        "resultants.csv)")
    args = parser.parse_args(argv)
    wanted = list(dict.fromkeys(parse_element(text) for text in args.element))
    path = args.source
    if os.path.isdir(path):
        path = os.path.join(path, "resultants.csv")
    series, beams = read_resultants(path, wanted)
    check_elements(wanted, beams, path)
    outdir = args.outdir or os.path.dirname(os.path.abspath(path))
    os.makedirs(outdir, exist_ok=True)
    written = []
    for name, plot in (("resultants.png", plot_components), ("resultants_norm.png", plot_norms)):
        written.append(os.path.join(outdir, name))
        plot(series, written[-1])
    for out in written:
        print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
