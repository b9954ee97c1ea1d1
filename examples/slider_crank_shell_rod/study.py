#!/usr/bin/env python3
"""The slider-crank with a shell, a beam and a rigid connecting rod (examples/slider_crank_shell_rod).

Runs the four models (model.yaml: Kirchhoff–Love strip; damped.yaml: the same with Kelvin–Voigt
damping; beam_rod.yaml; rigid_rod.yaml), prints the table of the README (Newton iterations, wall
time, energy balance, the rod's bending oscillation, the slider against the rigid rod's), and
draws figures/slider.png (slider displacement and velocity over 5 s, IGA-thesis Fig. 6.34),
figures/rod_deflection.png and figures/energy.png. Run from the repository root:

    /usr/bin/python3 examples/slider_crank_shell_rod/study.py --isoflex ./build/isoflex

Options: --outdir (default out/slider_crank_shell_rod_study), --figures (default the example's
figures/), --no-run (read the runs already in --outdir), --formulation (passed to isoflex).
Needs python3 and matplotlib.
"""
import argparse
import json
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
import isoflex_csv  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
RUNS = [("shell", "model.yaml", "Kirchhoff–Love strip"),
        ("shell_damped", "damped.yaml", "KL strip, Kelvin–Voigt η = 1e-4 s"),
        ("beam", "beam_rod.yaml", "director beam"),
        ("rigid", "rigid_rod.yaml", "rigid rod")]


def probes(outdir):
    """{probe: {t: (x, y, vx)}} from probes.csv."""
    out = {}
    path = os.path.join(outdir, "probes.csv")
    for line, row in isoflex_csv.rows(path, ["t", "probe", "x", "y", "vx"]):
        v = isoflex_csv.numbers(path, line, row, ["t", "x", "y", "vx"])
        out.setdefault(row["probe"], {})[round(v["t"], 9)] = (v["x"], v["y"], v["vx"])
    return out


def history(outdir):
    path = os.path.join(outdir, "history.csv")
    cols = ["t", "total_energy", "external_work"]
    rows = []
    for line, row in isoflex_csv.rows(path, cols):
        v = isoflex_csv.numbers(path, line, row, cols)
        d = float(row["dissipated_energy"]) if "dissipated_energy" in row else 0.0
        rows.append((v["t"], v["total_energy"], v["external_work"], d))
    return rows


def deflection(p):
    """The rod's middle point off the chord from the crank pin to the slider, per time."""
    out = []
    for t in sorted(p["slider"]):
        a, b, m = p["crank_pin"][t], p["slider"][t], p["rod_middle"][t]
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        nx, ny = -(b[1] - a[1]) / length, (b[0] - a[0]) / length
        out.append((t, (m[0] - 0.5 * (a[0] + b[0])) * nx + (m[1] - 0.5 * (a[1] + b[1])) * ny))
    return out


def oscillation(defl, t0, t1):
    """The amplitude of the rod's first bending vibration in the deflection over [t0, t1): the
    largest DFT amplitude between 60 and 200 Hz (the strip's first pinned–pinned bending
    frequency is about 104 Hz; the crank's motion lives below 30 Hz)."""
    pts = [(t, v) for t, v in defl if t0 <= t < t1]
    n = len(pts)
    mean = sum(v for _, v in pts) / n
    best = 0.0
    for f in range(60, 201):
        re = sum((v - mean) * math.cos(2 * math.pi * f * t) for t, v in pts)
        im = sum((v - mean) * math.sin(2 * math.pi * f * t) for t, v in pts)
        best = max(best, 2.0 * math.hypot(re, im) / n)
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--isoflex", default="./build/isoflex")
    ap.add_argument("--outdir", default="out/slider_crank_shell_rod_study")
    ap.add_argument("--figures", default=os.path.join(HERE, "figures"))
    ap.add_argument("--formulation", default=None)
    ap.add_argument("--no-run", action="store_true")
    a = ap.parse_args()
    for key, model, _ in RUNS:
        if a.no_run:
            break
        cmd = [a.isoflex, "run", os.path.join(HERE, model), "-o", os.path.join(a.outdir, key)]
        if a.formulation:
            cmd += ["--formulation", a.formulation]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            isoflex_csv.fail(f"{' '.join(cmd)} failed:\n{r.stdout}{r.stderr}")
    data = {}
    for key, _, label in RUNS:
        d = os.path.join(a.outdir, key)
        with open(os.path.join(d, "summary.json")) as f:
            s = json.load(f)
        data[key] = dict(p=probes(d), h=history(d), s=s, label=label)
    rigid = data["rigid"]["p"]["slider"]
    print("| rod | unknowns | Newton it. | wall s | max abs(E + D − W − E₀) / W(5) | "
          "bending oscillation 0.01–0.5 s / 4–5 s | max abs(x − x_rigid) | max abs(v − v_rigid) |")
    print("|---|---|---|---|---|---|---|---|")
    for key, _, label in RUNS:
        r = data[key]
        h = r["h"]
        e0 = h[0][1]
        balance = max(abs(e + d - w - e0) for _, e, w, d in h) / h[-1][2]
        sl = r["p"]["slider"]
        dx = max(abs(sl[t][0] - rigid[t][0]) for t in sl)
        dv = max(abs(sl[t][2] - rigid[t][2]) for t in sl)
        osc = "–"
        if key != "rigid":
            defl = deflection(r["p"])
            osc = f"{oscillation(defl, 0.01, 0.5):.2e} / {oscillation(defl, 4.0, 5.0):.2e}"
        print(f"| {label} | {r['s']['n_unknowns']} | {r['s']['newton_iterations_total']} | "
              f"{r['s']['wall_time_s']:.2f} | {balance:.1e} | {osc} | {dx:.2e} | {dv:.2e} |")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(a.figures, exist_ok=True)
    style = {"shell": ("C0", 1.0), "shell_damped": ("C1", 1.0), "beam": ("C2", 0.8),
             "rigid": ("k", 0.8)}
    fig, ax = plt.subplots(3, 1, figsize=(9, 9))
    for key, _, label in RUNS:
        sl = data[key]["p"]["slider"]
        ts = sorted(sl)
        c, lw = style[key]
        ax[0].plot(ts, [sl[t][0] for t in ts], color=c, lw=lw, label=label)
        ax[1].plot(ts, [sl[t][2] for t in ts], color=c, lw=lw, label=label)
        if key != "rigid":
            near = [t for t in ts if t <= 1.5]
            ax[2].plot(near, [1e3 * (sl[t][2] - rigid[t][2]) for t in near], color=c, lw=0.6,
                       label=label)
    ax[0].set_ylabel("slider x [m]")
    ax[1].set_ylabel("slider velocity [m/s]")
    ax[2].set_ylabel("v − v(rigid rod) [mm/s]")
    ax[2].set_xlabel("t [s] (the drive is switched on at 0 and off at 0.8)")
    ax[0].legend(fontsize=8, loc="lower left")
    ax[0].set_title("Slider-crank, connecting rod as KL shell / beam / rigid body (IGA-thesis Fig. 6.34)")
    fig.tight_layout()
    fig.savefig(os.path.join(a.figures, "slider.png"), dpi=90)

    fig, ax = plt.subplots(3, 1, figsize=(9, 9))
    for key in ("beam", "shell", "shell_damped"):
        defl = deflection(data[key]["p"])
        c, lw = style[key]
        ax[0].plot([t for t, _ in defl], [1e6 * v for _, v in defl], color=c, lw=0.5,
                   label=data[key]["label"])
        for axis, (t0, t1) in ((ax[1], (0.0, 0.4)), (ax[2], (4.0, 4.4))):
            part = [(t, v) for t, v in defl if t0 <= t <= t1]
            axis.plot([t for t, _ in part], [1e6 * v for _, v in part], color=c, lw=lw,
                      label=data[key]["label"])
    for axis in ax:
        axis.set_ylabel("rod middle off the chord [µm]")
    ax[2].set_xlabel("t [s]")
    ax[0].legend(fontsize=8)
    ax[0].set_title("Bending of the connecting rod (its middle point off the line between its pins)")
    fig.tight_layout()
    fig.savefig(os.path.join(a.figures, "rod_deflection.png"), dpi=90)

    fig, ax = plt.subplots(figsize=(9, 4))
    for key in ("shell", "shell_damped"):
        h = data[key]["h"]
        e0 = h[0][1]
        c, _ = style[key]
        ax.semilogy([t for t, *_ in h[1:]], [max(abs(e + d - w - e0), 1e-18) for _, e, w, d in h[1:]],
                    color=c, lw=0.6, label=data[key]["label"])
    ax.set_ylabel("abs(E + D − W − E₀) [J]")
    ax.set_xlabel("t [s]")
    ax.set_title("Energy balance: kinetic + strain + dissipated − work of the drive")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(a.figures, "energy.png"), dpi=90)


if __name__ == "__main__":
    main()
