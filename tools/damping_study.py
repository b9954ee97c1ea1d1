#!/usr/bin/python3
"""Damping study of a model with Kelvin–Voigt material damping: a probe's oscillation for several
damping factors η, free (IGA-thesis §6.4.3.1, Figs. 6.29, 6.30) or under a harmonic load
(§6.4.3.2, Fig. 6.32).

usage: damping_study.py MODEL --etas 0,0.005,0.01,0.02 [--probe tip] [--component z]
                        [--shell NAME] [--t-end T] [--isoflex build/isoflex]
                        [--forcing OMEGA [--periods N] [--sdof OMEGA1,X0]]
                        [--outdir DIR] [--table FILE.md]

For every η the model's kl_shells entry (the first, or --shell) gets `material.eta: η` and is
run with `isoflex run` (--t-end overrides the model's end time).

Free oscillation (default): the amplitudes z_k are the largest values of the probe's displacement
component in each oscillation (between upward zero crossings), and the damping ratio per
oscillation is ζ_k / √(1 − ζ_k²) = δ_k / 2π, δ_k = ln(z_k / z_{k+1}) (the thesis' definition).
Writes amplitude.png (the component against t; Fig. 6.29), damping_ratio.png (ζ_k against k;
Fig. 6.30) and a table (per η: the period, z_1, ζ_1, ζ at the last oscillation, η ω / 2, the
dissipated energy over the initial energy).

--forcing OMEGA (the load's angular frequency): the steady state is fitted over the last N
periods (default 4) as u(t) = X sin(Ω t − φ) + c (least squares), X the amplitude and φ the phase
lag behind the load. --sdof OMEGA1,X0 adds the linear single-degree-of-freedom values of a
Kelvin–Voigt oscillator with natural frequency OMEGA1 and static response X0,
X = X0 / √((1 − r²)² + (η Ω)²), tan φ = η Ω / (1 − r²), r = Ω / OMEGA1. Writes
steady_state.png (X and φ against η; Fig. 6.32), response.png (the component against t) and the
table. Figures go to --outdir (default: the model's folder/figures).
Exit status 2 on a bad model or option, 3 if a run fails.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from isoflex_csv import fail, numbers, rows  # noqa: E402


def turning_points(t, z):
    """(t_k, z_k): the largest z of every oscillation, between two upward zero crossings of z (a
    ripple of higher modes near a turning point is not a second oscillation); the start (at rest,
    t = 0) and an oscillation cut off by the end of the run are left out."""
    ups = [i for i in range(1, len(z)) if z[i - 1] < 0 <= z[i]]
    peaks = []
    for a, b in zip(ups, ups[1:]):
        k = max(range(a, b), key=lambda i: z[i])
        peaks.append((t[k], z[k]))
    return peaks


def damping_ratios(peaks):
    out = []
    for (_, a), (_, b) in zip(peaks, peaks[1:]):
        if a <= 0 or b <= 0:
            break
        d = math.log(a / b) / (2 * math.pi)
        out.append(d / math.sqrt(1 + d * d))
    return out


def fit_steady_state(t, z, omega, periods):
    """(X, φ): least-squares fit of z = X sin(Ω t − φ) + c over the last `periods` periods."""
    t0 = t[-1] - periods * 2 * math.pi / omega
    pts = [(ti, zi) for ti, zi in zip(t, z) if ti >= t0]
    if len(pts) < 8 or t0 < 0:
        fail(f"the run is shorter than {periods} periods of the load")
    # normal equations of [sin, cos, 1]
    rowsv = [(math.sin(omega * ti), math.cos(omega * ti), 1.0, zi) for ti, zi in pts]
    A = [[sum(r[i] * r[j] for r in rowsv) for j in range(3)] for i in range(3)]
    b = [sum(r[i] * r[3] for r in rowsv) for i in range(3)]
    for k in range(3):  # Gaussian elimination (3 × 3, well conditioned)
        for i in range(k + 1, 3):
            f = A[i][k] / A[k][k]
            for j in range(k, 3):
                A[i][j] -= f * A[k][j]
            b[i] -= f * b[k]
    x = [0.0] * 3
    for i in (2, 1, 0):
        x[i] = (b[i] - sum(A[i][j] * x[j] for j in range(i + 1, 3))) / A[i][i]
    a_sin, a_cos = x[0], x[1]  # X sin(Ωt − φ) = X cos φ sin Ωt − X sin φ cos Ωt
    return math.hypot(a_sin, a_cos), math.atan2(-a_cos, a_sin)


def run_variants(a, model, shell, etas):
    """Runs the model for every η; per η the probe's times, displacement component and summary."""
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for eta in etas:
            shell["material"]["eta"] = eta
            path = os.path.join(tmp, f"eta_{eta:g}.yaml")
            with open(path, "w") as f:
                yaml.safe_dump(model, f, sort_keys=False)
            out = os.path.join(tmp, f"out_{eta:g}")
            cmd = [a.isoflex, "run", path, "-o", out]
            if a.t_end:
                cmd += ["--t-end", str(a.t_end)]
            run = subprocess.run(cmd, capture_output=True, text=True)
            if run.returncode != 0:
                print(run.stdout + run.stderr, file=sys.stderr)
                sys.exit(3 if run.returncode == 3 else 2)
            probes = os.path.join(out, "probes.csv")
            col = "u" + a.component
            t, z = [], []
            for n, r in rows(probes, ["t", "probe", col]):
                if r["probe"] == a.probe:
                    v = numbers(probes, n, r, ["t", col])
                    t.append(v["t"])
                    z.append(v[col])
            if not t:
                fail(f"{a.model}: no probe named {a.probe}")
            with open(os.path.join(out, "summary.json")) as f:
                summary = json.load(f)
            results.append({"eta": eta, "t": t, "z": z, "summary": summary})
    return results


def plot_lines(path, curves, xlabel, ylabel, title, style="-"):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for x, y, label in curves:
        ax.plot(x, y, style, lw=0.9, ms=3, label=label)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def free_decay(a, results, outdir):
    for r in results:
        r["peaks"] = turning_points(r["t"], r["z"])
        r["zeta"] = damping_ratios(r["peaks"])
        p = r["peaks"]
        r["period"] = (p[-1][0] - p[0][0]) / (len(p) - 1) if len(p) > 1 else float("nan")
    ylabel = f"{a.probe} displacement u{a.component} (m)"
    plot_lines(os.path.join(outdir, "amplitude.png"),
               [(r["t"], r["z"], f"η = {r['eta']:g} s") for r in results], "t (s)", ylabel,
               "Tip amplitude against time (IGA-thesis Fig. 6.29)")
    plot_lines(os.path.join(outdir, "damping_ratio.png"),
               [(range(1, len(r["zeta"]) + 1), r["zeta"], f"η = {r['eta']:g} s")
                for r in results if r["zeta"]], "oscillation k", "damping ratio ζ_k",
               "Damping ratio per oscillation (IGA-thesis Fig. 6.30)", "o-")
    lines = ["| η (s) | period (s) | z₁ (m) | ζ₁ | ζ last | η ω / 2 | dissipated / E₀ |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in results:
        omega = 2 * math.pi / r["period"] if r["period"] == r["period"] else float("nan")
        z1 = r["peaks"][0][1] if r["peaks"] else float("nan")
        first = f"{r['zeta'][0]:.4f}" if r["zeta"] else "–"
        last = f"{r['zeta'][-1]:.4f} (k = {len(r['zeta'])})" if r["zeta"] else "–"
        s = r["summary"]
        lines.append(f"| {r['eta']:g} | {r['period']:.4f} | {z1:.4f} | {first} | {last} | "
                     f"{r['eta'] * omega / 2:.4f} | "
                     f"{s.get('dissipated_energy', 0.0) / s['energy_initial']:.4f} |")
    return lines


def steady_state(a, results, outdir):
    sdof = None
    if a.sdof:
        try:
            omega1, x0 = (float(v) for v in a.sdof.split(","))
        except ValueError:
            fail(f"--sdof: expected OMEGA1,X0, got {a.sdof}")
        sdof = (omega1, x0)
    w = a.forcing
    for r in results:
        r["X"], r["phi"] = fit_steady_state(r["t"], r["z"], w, a.periods)
    lines = ["| η (s) | amplitude X (m) | phase lag φ (°) |" +
             (" SDOF X (m) | SDOF φ (°) |" if sdof else ""),
             "| --- | --- | --- |" + (" --- | --- |" if sdof else "")]
    model_curves = []
    for r in results:
        line = f"| {r['eta']:g} | {r['X']:.5g} | {math.degrees(r['phi']):.2f} |"
        if sdof:
            rr = w / sdof[0]
            X = sdof[1] / math.hypot(1 - rr * rr, r["eta"] * w)
            phi = math.atan2(r["eta"] * w, 1 - rr * rr)
            r["sdof"] = (X, phi)
            line += f" {X:.5g} | {math.degrees(phi):.2f} |"
        lines.append(line)
    etas = [r["eta"] for r in results]
    curves = [(etas, [r["X"] for r in results], "isoflex (steady state)")]
    phases = [(etas, [math.degrees(r["phi"]) for r in results], "isoflex (steady state)")]
    if sdof:
        curves.append((etas, [r["sdof"][0] for r in results], "linear SDOF, first mode"))
        phases.append((etas, [math.degrees(r["sdof"][1]) for r in results],
                       "linear SDOF, first mode"))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for (x, y, label), style in zip(curves, ["o-", "s--"]):
        ax1.plot(x, y, style, ms=4, label=label)
    for (x, y, label), style in zip(phases, ["o-", "s--"]):
        ax2.plot(x, y, style, ms=4, label=label)
    ax1.set_xlabel("η (s)")
    ax1.set_ylabel(f"steady-state amplitude of u{a.component} (m)")
    ax2.set_xlabel("η (s)")
    ax2.set_ylabel("phase lag behind the load (°)")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend()
    fig.suptitle(f"Harmonic load, Ω = {w:g} rad/s (IGA-thesis Fig. 6.32)")
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "steady_state.png"), dpi=120)
    plot_lines(os.path.join(outdir, "response.png"),
               [(r["t"], r["z"], f"η = {r['eta']:g} s") for r in results], "t (s)",
               f"{a.probe} displacement u{a.component} (m)", "Response to the harmonic load")
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("model")
    ap.add_argument("--etas", required=True, help="comma-separated damping factors (s)")
    ap.add_argument("--probe", default="tip")
    ap.add_argument("--component", default="z", choices=["x", "y", "z"])
    ap.add_argument("--shell", help="name of the kl_shells entry (default: the first)")
    ap.add_argument("--t-end", type=float)
    ap.add_argument("--isoflex", default=os.path.join(os.getcwd(), "build", "isoflex"))
    ap.add_argument("--forcing", type=float, help="angular frequency of a harmonic load")
    ap.add_argument("--periods", type=int, default=4)
    ap.add_argument("--sdof", help="OMEGA1,X0 of the linear single-degree-of-freedom comparison")
    ap.add_argument("--outdir")
    ap.add_argument("--table")
    a = ap.parse_args()

    try:
        etas = [float(x) for x in a.etas.split(",")]
    except ValueError:
        fail(f"--etas: not a list of numbers: {a.etas}")
    if any(e < 0 for e in etas):
        fail("--etas: damping factors must be >= 0")
    if a.forcing is not None and not a.forcing > 0:
        fail("--forcing: the angular frequency must be > 0")
    if not os.path.isfile(a.model):
        fail(f"no such file: {a.model}")
    with open(a.model) as f:
        model = yaml.safe_load(f)
    shells = model.get("kl_shells") or []
    shell = next((s for s in shells if a.shell is None or s.get("name") == a.shell), None)
    if shell is None:
        fail(f"{a.model}: no kl_shells entry" + (f" named {a.shell}" if a.shell else ""))
    outdir = a.outdir or os.path.join(os.path.dirname(os.path.abspath(a.model)), "figures")
    os.makedirs(outdir, exist_ok=True)

    results = run_variants(a, model, shell, etas)
    lines = steady_state(a, results, outdir) if a.forcing else free_decay(a, results, outdir)
    table = "\n".join(lines) + "\n"
    print(table, end="")
    if a.table:
        with open(a.table, "w") as f:
            f.write(table)


if __name__ == "__main__":
    main()
