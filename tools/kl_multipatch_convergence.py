#!/usr/bin/python3
"""Energy convergence of the multipatch roll-up (IGA-thesis §6.4.2.1, Figs. 6.18 and 6.19).

usage: kl_multipatch_convergence.py [--isoflex build/isoflex] [--degrees 2,3,4,5]
                                    [--knots 1,3,7,15] [--patches 1,2,4]
                                    [--couplings bending_strip,angle] [--beta 1e3]
                                    [--csv FILE.csv] [--plot FILE.png]

The cantilever plate of examples/kl_two_patch_roll_up (L = 12, b = 1, t = 0.1, E = 1.2e6, ν = 0,
clamped at x = 0) rolled to a full circle by the end moment M = 2π EI/L, cut into N equal patches
along its length, each of degree p along the plate (quadratic across, one element) with k knots
inserted per patch; the patches joined by each coupling. Per run: the strain energy at the end
(summary.json energy_final: the patches' and, for bending_strip, the strips'), the unknowns the
static solver solves for (free coordinates and multipliers, the thesis' DOF counts) and the
coordinates. The reference is the finest single patch run (highest p, most knots); the plot shows
|U − U_ref| / U_ref against the unknowns per degree, one panel per patch count and coupling
(Fig. 6.18: the couplings side by side; Fig. 6.19: the patch counts).
Exit status 2 on a bad option, 3 if a run fails.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile

import yaml

L, B, T, E = 12.0, 1.0, 0.1, 1.2e6
MOMENT = 52.35987755982988  # 2π EI / L per unit width, EI = E t³/12 = 100


def model(patches, p, k, coupling, beta):
    w = L / patches
    m = {
        "name": f"roll_up_{patches}x_p{p}_k{k}_{coupling}",
        "solver": {"analysis": "static", "dt": 0.0625, "t_end": 1, "max_subdivisions": 6},
        "surfaces": [], "kl_shells": [],
        "kl_supports": [{"shell": "s0", "edge": "u0", "clamped": "all"}],
        "kl_loads": [{"shell": f"s{patches - 1}", "edge": "u1",
                      "moment_per_length": f"{MOMENT!r}*t", "axis": [0, -1, 0]}],
        "probes": [{"name": "tip", "shell": f"s{patches - 1}", "point": [L, 0.5 * B, 0]}],
    }
    for i in range(patches):
        m["surfaces"].append({"name": f"s{i}",
                              "builtin": {"type": "rectangle", "size": [w, B], "corner": [i * w, 0, 0]},
                              "refine": {"elevate": [p - 1, 1], "knots_per_span": [k, 0]}})
        m["kl_shells"].append({"name": f"s{i}", "surface": f"s{i}",
                               "material": {"E": E, "nu": 0, "thickness": T}})
    if patches > 1:
        m["kl_interfaces"] = {"coupling": coupling, "beta": beta}
    return m


def run(isoflex, m, tmp):
    path = os.path.join(tmp, m["name"] + ".yaml")
    with open(path, "w") as f:
        yaml.safe_dump(m, f, sort_keys=False)
    out = os.path.join(tmp, m["name"])
    r = subprocess.run([isoflex, "run", "--static", path, "-o", out], capture_output=True, text=True)
    if r.returncode != 0:
        print(f"kl_multipatch_convergence: {m['name']} failed: {r.stderr.strip()}", file=sys.stderr)
        return None
    with open(os.path.join(out, "summary.json")) as f:
        s = json.load(f)
    return s


def numbers(text, what):
    try:
        return [int(x) for x in text.split(",")]
    except ValueError:
        print(f"kl_multipatch_convergence: bad --{what} '{text}'", file=sys.stderr)
        sys.exit(2)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--isoflex", default="build/isoflex")
    ap.add_argument("--degrees", default="2,3,4,5")
    ap.add_argument("--knots", default="1,3,7,15")
    ap.add_argument("--patches", default="1,2,4")
    ap.add_argument("--couplings", default="bending_strip,angle")
    ap.add_argument("--beta", type=float, default=1e3)
    ap.add_argument("--csv")
    ap.add_argument("--plot")
    a = ap.parse_args()
    degrees, knots, patches = (numbers(a.degrees, "degrees"), numbers(a.knots, "knots"),
                               numbers(a.patches, "patches"))
    couplings = a.couplings.split(",")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in patches:
            for c in (couplings if n > 1 else ["none"]):
                for p in degrees:
                    for k in knots:
                        s = run(a.isoflex, model(n, p, k, c, a.beta), tmp)
                        if s is None:
                            sys.exit(3)
                        rows.append({"patches": n, "coupling": c, "p": p, "knots": k,
                                     "coordinates": s["n_coordinates"],
                                     "unknowns": s["n_unknowns"], "energy": s["energy_final"],
                                     "tip_x": s["probes"]["tip"]["displacement"][0]})
                        print(f"{n} patches {c:>13} p={p} k={k:>2}: unknowns {rows[-1]['unknowns']:>4} "
                              f"U = {s['energy_final']:.10f}", file=sys.stderr)
    single = [r for r in rows if r["patches"] == 1]
    ref = max(single, key=lambda r: (r["p"], r["knots"]))["energy"] if single else rows[-1]["energy"]
    for r in rows:
        r["relative_error"] = abs(r["energy"] - ref) / ref
    for path in (a.csv, a.plot):
        if path:
            os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    out = open(a.csv, "w", newline="") if a.csv else sys.stdout
    w = csv.DictWriter(out, fieldnames=list(rows[0].keys()), lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        groups = sorted({(r["patches"], r["coupling"]) for r in rows})
        fig, axes = plt.subplots(1, len(groups), figsize=(4 * len(groups), 3.6), sharey=True)
        for ax, (n, c) in zip(axes if len(groups) > 1 else [axes], groups):
            for p in degrees:
                pts = [r for r in rows if (r["patches"], r["coupling"], r["p"]) == (n, c, p)
                       and r["relative_error"] > 0]
                ax.loglog([r["unknowns"] for r in pts], [r["relative_error"] for r in pts], "o-",
                          label=f"p = {p}")
            ax.set_title(f"{n} patch{'es' if n > 1 else ''}" + (f", {c}" if n > 1 else ""))
            ax.set_xlabel("unknowns")
            ax.grid(True, which="both", alpha=0.3)
        (axes[0] if len(groups) > 1 else axes).set_ylabel("|U − U_ref| / U_ref")
        (axes[0] if len(groups) > 1 else axes).legend()
        fig.suptitle(f"roll-up to 360°: strain energy against unknowns (U_ref = {ref:.8f})")
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)


if __name__ == "__main__":
    main()
