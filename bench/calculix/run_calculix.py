#!/usr/bin/python3
"""CalculiX (ccx, S8R shells) side of the linear shell obstacle-course comparison.

Generates the input decks for the Scordelis-Lo roof and the pinched hemisphere (18 deg hole,
MacNeal-Harder; optionally the closed hemisphere), runs `ccx` on each one after the other
(single thread), reads the displacement of the reference node from the .dat file (*NODE PRINT),
the number of equations from ccx's standard output, and measures wall and CPU time of the ccx
process. Writes results.md and results.json into --out (never into the repository).

Standard library only. Usage:
    /usr/bin/python3 bench/calculix/run_calculix.py --out /tmp/ccx [--sizes 4,8,16,32,64]
        [--cases roof,hemi,hemi_closed] [--max-seconds 120] [--ccx ccx]
"""

import argparse
import datetime
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time

# --------------------------------------------------------------------------------------------
# structured S8R meshes
# --------------------------------------------------------------------------------------------


class Mesh:
    """Nodes (merged by coordinates) and 8-node serendipity quadrilaterals."""

    def __init__(self):
        self.coords = []          # index i -> (x, y, z); node id = i + 1
        self.key = {}
        self.elements = []        # 8 node ids: corners counter-clockwise, then midsides 12 23 34 41
        self.normal = {}          # node id -> exact unit normal of the mid-surface

    def node(self, p, n=None):
        k = tuple(int(round(c * 1e8)) for c in p)
        nid = self.key.get(k)
        if nid is None:
            self.coords.append(tuple(p))
            nid = len(self.coords)
            self.key[k] = nid
            if n is not None:
                self.normal[nid] = n
        return nid

    def add_patch(self, nu, nv, point):
        """point(u, v), u, v in [0, 1] -> (xyz, normal); nu x nv elements."""
        grid = {}
        for i in range(2 * nu + 1):
            for j in range(2 * nv + 1):
                if i % 2 == 1 and j % 2 == 1:
                    continue      # serendipity: no centre node
                p, n = point(i / (2.0 * nu), j / (2.0 * nv))
                grid[i, j] = self.node(p, n)
        for a in range(nu):
            for b in range(nv):
                i, j = 2 * a, 2 * b
                self.elements.append((grid[i, j], grid[i + 2, j], grid[i + 2, j + 2], grid[i, j + 2],
                                      grid[i + 1, j], grid[i + 2, j + 1], grid[i + 1, j + 2],
                                      grid[i, j + 1]))
        return grid

    def nodes_where(self, pred):
        return [i + 1 for i, p in enumerate(self.coords) if pred(p)]

    def nearest(self, q):
        best = min(range(len(self.coords)),
                   key=lambda i: sum((a - b) ** 2 for a, b in zip(self.coords[i], q)))
        return best + 1


def unit(v):
    s = math.sqrt(sum(c * c for c in v))
    return tuple(c / s for c in v)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def rotation_dof(plane_normal, shell_normal):
    """Rotational DOF (4, 5, 6) for a symmetry plane: the constrained rotation axis is the
    tangent direction lying in the symmetry plane, a = s x n. ccx projects an applied rotation
    axis onto the shell tangent plane (mean-rotation MPC), so any global axis other than s with a
    non-zero component along a gives exactly that constraint; take the best aligned one."""
    a = unit(cross(plane_normal, shell_normal))
    k = max(range(3), key=lambda i: abs(a[i]) if abs(plane_normal[i]) < 0.5 else -1.0)
    return 4 + k


# --------------------------------------------------------------------------------------------
# benchmark definitions
# --------------------------------------------------------------------------------------------

def roof(n):
    """Scordelis-Lo roof, quarter model. Axis x: x = 0 mid-length symmetry plane, x = 25
    diaphragm; theta from the crown (y = 0 symmetry plane) to the free edge at 40 deg;
    y = R sin(theta), z = R cos(theta)."""
    R, L, t, E, nu, q = 25.0, 50.0, 0.25, 4.32e8, 0.0, 90.0
    phi = math.radians(40.0)
    m = Mesh()

    def point(u, v):
        th = v * phi
        n_ = (0.0, math.sin(th), math.cos(th))
        return (u * L / 2, R * n_[1], R * n_[2]), n_

    m.add_patch(n, n, point)
    tol = 1e-9
    bcs = []
    for nid in m.nodes_where(lambda p: abs(p[0] - L / 2) < tol):       # rigid diaphragm
        bcs += [(nid, 2), (nid, 3)]
    for nid in m.nodes_where(lambda p: abs(p[0]) < tol):               # mid-length symmetry
        bcs += [(nid, 1), (nid, rotation_dof((1, 0, 0), m.normal[nid]))]
    for nid in m.nodes_where(lambda p: abs(p[1]) < tol):               # crown symmetry
        bcs += [(nid, 2), (nid, rotation_dof((0, 1, 0), m.normal[nid]))]
    ref_xyz = (0.0, R * math.sin(phi), R * math.cos(phi))
    ref = m.nearest(ref_xyz)
    loads = ["*DLOAD", "EALL, GRAV, 1., 0., 0., -1."]
    return dict(mesh=m, t=t, E=E, nu=nu, density=q / t, bcs=bcs, cloads=[], dload=loads,
                ref=ref, ref_xyz=ref_xyz, ref_dir=3, sign=-1.0, extra_ref=None,
                label="%dx%d" % (n, n), refs=[("0.3024", 0.3024)])


def hemi(n):
    """Pinched hemisphere with an 18 deg hole (MacNeal-Harder), quarter model 0 <= lambda <= 90
    deg, latitude 0 (free equator) .. 72 deg (free hole edge). Loads of the full model: 2
    outward on +-x, 2 inward on +-y; each load point lies in a symmetry plane, so the quarter
    carries half: +1 (x) at (R, 0, 0), -1 (y) at (0, R, 0). One node (hole edge, lambda = 0)
    has u_z = 0 against the vertical rigid translation (loads are self-equilibrated)."""
    R, t, E, nu = 10.0, 0.04, 6.825e7, 0.3
    top = math.radians(72.0)
    m = Mesh()

    def point(u, v):
        lam, lat = u * math.pi / 2, v * top
        n_ = (math.cos(lat) * math.cos(lam), math.cos(lat) * math.sin(lam), math.sin(lat))
        return tuple(R * c for c in n_), n_

    m.add_patch(n, n, point)
    tol = 1e-9
    bcs = []
    for nid in m.nodes_where(lambda p: abs(p[1]) < tol):      # plane y = 0
        bcs += [(nid, 2), (nid, rotation_dof((0, 1, 0), m.normal[nid]))]
    for nid in m.nodes_where(lambda p: abs(p[0]) < tol):      # plane x = 0
        bcs += [(nid, 1), (nid, rotation_dof((1, 0, 0), m.normal[nid]))]
    fix = m.nearest((R * math.cos(top), 0.0, R * math.sin(top)))
    bcs.append((fix, 3))
    a, b = m.nearest((R, 0, 0)), m.nearest((0, R, 0))
    return dict(mesh=m, t=t, E=E, nu=nu, density=None, bcs=bcs,
                cloads=[(a, 1, 1.0), (b, 2, -1.0)], dload=[], ref=a, ref_xyz=(R, 0.0, 0.0),
                ref_dir=1, sign=1.0, extra_ref=(b, (0.0, R, 0.0), 2, -1.0),
                label="%dx%d" % (n, n), refs=[("0.094", 0.094), ("0.0924", 0.0924)])


def hemi_closed(n):
    """Closed hemisphere (no hole), quarter model: the spherical triangle equator/(x=0)/(y=0)
    split into 3 structured quadrilateral patches of (n/2)x(n/2) elements each (corners at the
    load points, the edge midpoints, the centroid and the pole). Pole: u_x = u_y = 0 (both
    symmetry planes) and u_z = 0 (the 'fixed top'; the loads are self-equilibrated, so this only
    removes the rigid vertical translation)."""
    R, t, E, nu = 10.0, 0.04, 6.825e7, 0.3
    k = max(1, n // 2)
    A, B, P = (1.0, 0, 0), (0, 1.0, 0), (0, 0, 1.0)
    mAB, mBP, mPA = unit((1, 1, 0)), unit((0, 1, 1)), unit((1, 0, 1))
    C = unit((1, 1, 1))
    m = Mesh()

    def patch(c1, c2, c3, c4):
        def point(u, v):
            w = [(1 - u) * (1 - v), u * (1 - v), u * v, (1 - u) * v]
            q = unit(tuple(sum(wi * c[d] for wi, c in zip(w, (c1, c2, c3, c4))) for d in range(3)))
            return tuple(R * c for c in q), q
        return point

    m.add_patch(k, k, patch(A, mAB, C, mPA))
    m.add_patch(k, k, patch(mAB, B, mBP, C))
    m.add_patch(k, k, patch(C, mBP, P, mPA))
    tol = 1e-9
    bcs = []
    for nid in m.nodes_where(lambda p: abs(p[1]) < tol):
        bcs += [(nid, 2), (nid, rotation_dof((0, 1, 0), m.normal[nid]))]
    for nid in m.nodes_where(lambda p: abs(p[0]) < tol):
        bcs += [(nid, 1), (nid, rotation_dof((1, 0, 0), m.normal[nid]))]
    pole = m.nearest((0, 0, R))
    bcs.append((pole, 3))
    a, b = m.nearest((R, 0, 0)), m.nearest((0, R, 0))
    return dict(mesh=m, t=t, E=E, nu=nu, density=None, bcs=bcs,
                cloads=[(a, 1, 1.0), (b, 2, -1.0)], dload=[], ref=a, ref_xyz=(R, 0.0, 0.0),
                ref_dir=1, sign=1.0, extra_ref=(b, (0.0, R, 0.0), 2, -1.0),
                label="3x(%dx%d)" % (k, k), refs=[("0.094", 0.094), ("0.0924", 0.0924)])


CASES = {"roof": ("Scordelis-Lo roof", roof),
         "hemi": ("pinched hemisphere, 18 deg hole", hemi),
         "hemi_closed": ("pinched hemisphere, closed", hemi_closed)}

# --------------------------------------------------------------------------------------------
# deck, run, parse
# --------------------------------------------------------------------------------------------


def write_deck(path, c):
    m = c["mesh"]
    out = ["** generated by bench/calculix/run_calculix.py", "*HEADING", path, "*NODE, NSET=NALL"]
    out += ["%d, %.15g, %.15g, %.15g" % (i + 1, *p) for i, p in enumerate(m.coords)]
    out.append("*ELEMENT, TYPE=S8R, ELSET=EALL")
    out += ["%d, %s" % (e + 1, ", ".join(str(v) for v in nodes)) for e, nodes in enumerate(m.elements)]
    refs = [c["ref"]] + ([c["extra_ref"][0]] if c["extra_ref"] else [])
    out += ["*NSET, NSET=NREF", ", ".join(str(r) for r in refs)]
    out += ["*MATERIAL, NAME=MAT", "*ELASTIC", "%.15g, %.15g" % (c["E"], c["nu"])]
    if c["density"]:
        out += ["*DENSITY", "%.15g" % c["density"]]
    out += ["*SHELL SECTION, ELSET=EALL, MATERIAL=MAT", "%.15g" % c["t"]]
    out += ["*BOUNDARY"] + ["%d, %d, %d, 0." % (nid, d, d) for nid, d in c["bcs"]]
    out += ["*STEP", "*STATIC"]
    if c["cloads"]:
        out += ["*CLOAD"] + ["%d, %d, %.15g" % cl for cl in c["cloads"]]
    out += c["dload"]
    out += ["*NODE PRINT, NSET=NREF", "U", "*END STEP", ""]
    with open(path, "w") as f:
        f.write("\n".join(out))


def parse_dat(path):
    disp = {}
    with open(path) as f:
        text = f.read()
    block = text.split("displacements")[-1]
    for line in block.splitlines()[1:]:
        parts = line.split()
        if len(parts) == 4 and parts[0].isdigit():
            disp[int(parts[0])] = tuple(float(v) for v in parts[1:])
    return disp


def run_ccx(ccx, workdir, job):
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1",
               CCX_NPROC_EQUATION_SOLVER="1", CCX_NPROC_RESULTS="1", CCX_NPROC_STIFFNESS="1")
    with open(os.path.join(workdir, job + ".log"), "w") as log:
        t0 = time.perf_counter()
        p = subprocess.Popen([ccx, "-i", job], cwd=workdir, stdout=log, stderr=subprocess.STDOUT,
                             env=env)
        _, status, ru = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
    p.returncode = os.waitstatus_to_exitcode(status)
    with open(os.path.join(workdir, job + ".log")) as f:
        logtext = f.read()
    neq = None
    mo = re.search(r"number of equations\s*\n\s*(\d+)", logtext)
    if mo:
        neq = int(mo.group(1))
    knots = 0
    twelve = os.path.join(workdir, job + ".12d")
    if os.path.exists(twelve):
        with open(twelve) as f:
            knots = f.read().count("KNOT")
    return dict(rc=p.returncode, wall=wall, cpu=ru.ru_utime + ru.ru_stime, user=ru.ru_utime,
                sys=ru.ru_stime, neq=neq,
                knots=knots)


def uptime():
    try:
        return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    except OSError:
        with open("/proc/loadavg") as f:
            return "loadavg " + f.read().strip()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--out", required=True, help="directory for decks, ccx output and results")
    ap.add_argument("--sizes", default="4,8,16,32,64,128", help="elements per side of the quarter model")
    ap.add_argument("--cases", default="roof,hemi,hemi_closed")
    ap.add_argument("--ccx", default="ccx")
    ap.add_argument("--max-seconds", type=float, default=120.0,
                    help="skip larger sizes of a case once a run took longer than this")
    args = ap.parse_args()

    ccx = shutil.which(args.ccx) or args.ccx
    os.makedirs(args.out, exist_ok=True)
    sizes = [int(s) for s in args.sizes.split(",") if s]
    version = subprocess.run([ccx, "-v"], capture_output=True, text=True).stdout.strip()
    load_before = uptime()
    started = datetime.datetime.now().astimezone()
    rows = []
    for case in args.cases.split(","):
        title, build = CASES[case]
        for n in sizes:
            c = build(n)
            m = c["mesh"]
            job = "%s_%d" % (case, n)
            write_deck(os.path.join(args.out, job + ".inp"), c)
            r = run_ccx(ccx, args.out, job)
            row = dict(case=case, title=title, n=n, mesh=c["label"], elements=len(m.elements),
                       nodes=len(m.coords), dofs=6 * len(m.coords), neq=r["neq"], wall=r["wall"],
                       cpu=r["cpu"], rc=r["rc"], knots=r["knots"],
                       ref_node=c["ref"], ref_xyz=m.coords[c["ref"] - 1], target_xyz=c["ref_xyz"],
                       refs=c["refs"])
            if r["rc"] == 0:
                disp = parse_dat(os.path.join(args.out, job + ".dat"))
                u = disp[c["ref"]]
                row["u_vec"] = u
                row["value"] = c["sign"] * u[c["ref_dir"] - 1]
                row["component"] = "%s u_%s" % ("-" if c["sign"] < 0 else "+", "xyz"[c["ref_dir"] - 1])
                if c["extra_ref"]:
                    nid, xyz, d, s = c["extra_ref"]
                    row["value2"] = s * disp[nid][d - 1]
                    row["ref2_xyz"] = m.coords[nid - 1]
                    row["u2_vec"] = disp[nid]
            rows.append(row)
            print("%-12s %-10s nodes %6d dofs %7d neq %7s  value %s  wall %.2f s cpu %.2f s%s" % (
                case, c["label"], row["nodes"], row["dofs"], row["neq"],
                ("%.6f" % row["value"]) if "value" in row else "FAILED rc=%d" % r["rc"],
                r["wall"], r["cpu"], "  KNOTS %d" % r["knots"] if r["knots"] else ""), flush=True)
            if r["rc"] != 0 or r["wall"] > args.max_seconds:
                break
    load_after = uptime()
    meta = dict(command=" ".join([sys.executable] + sys.argv), version=version,
                date=started.isoformat(timespec="seconds"), load_before=load_before,
                load_after=load_after, host_cpus=os.cpu_count())
    with open(os.path.join(args.out, "results.json"), "w") as f:
        json.dump(dict(meta=meta, rows=rows), f, indent=1)
    md = format_md(meta, rows)
    with open(os.path.join(args.out, "results.md"), "w") as f:
        f.write(md)
    print(md)


def format_md(meta, rows):
    L = ["CalculiX %s, S8R, command `%s`, %s" % (meta["version"].replace("This is ", ""),
                                                 meta["command"], meta["date"]),
         "", "load before: `%s`  " % meta["load_before"], "load after: `%s`" % meta["load_after"], "",
         "| benchmark | mesh | elements | nodes | DOFs (6/node) | equations (ccx) | displacement | "
         "error vs ref | wall s | CPU s |",
         "| --- | --- | ---: | ---: | ---: | ---: | ---: | --- | ---: | ---: |"]
    for r in rows:
        if "value" not in r:
            L.append("| %s | %s | %d | %d | %d | %s | failed (rc %d) | | %.2f | %.2f |" % (
                r["title"], r["mesh"], r["elements"], r["nodes"], r["dofs"], r["neq"], r["rc"],
                r["wall"], r["cpu"]))
            continue
        errs = ", ".join("%+.2f %% (%s)" % (100 * (r["value"] / v - 1), s) for s, v in r["refs"])
        val = "%.5f" % r["value"]
        if "value2" in r:
            val += " / %.5f" % r["value2"]
        L.append("| %s | %s | %d | %d | %d | %s | %s | %s | %.2f | %.2f |" % (
            r["title"], r["mesh"], r["elements"], r["nodes"], r["dofs"], r["neq"], val, errs,
            r["wall"], r["cpu"]))
    L.append("")
    L.append("Reference nodes (node id: coordinates):")
    for r in rows:
        s = "- %s %s: node %d at (%s)" % (r["case"], r["mesh"], r["ref_node"],
                                          ", ".join("%.6g" % v for v in r["ref_xyz"]))
        if "u_vec" in r:
            s += ", u = (%s)" % ", ".join("%.6g" % v for v in r["u_vec"])
        if "ref2_xyz" in r:
            s += "; second load node at (%s), u = (%s)" % (
                ", ".join("%.6g" % v for v in r["ref2_xyz"]), ", ".join("%.6g" % v for v in r["u2_vec"]))
        L.append(s)
    return "\n".join(L) + "\n"


if __name__ == "__main__":
    main()
