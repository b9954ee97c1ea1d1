#!/usr/bin/python3
"""Plot stress resultants (or any point field) of a Kirchhoff–Love shell run from its VTU file.

usage: plot_kl_resultants.py RUN_DIR_OR_VTU [-o FILE.png] [--field NAME:COMP ...]
                             [--coords A,B] [--line PARAM=VALUE[:LABEL] ...] [--along X] [--title TEXT]
                             [--levels N]

Reads the .vtu that `isoflex run --static` writes for a kl_shell (io/kl_shell_vtk.hpp: VTK XML,
binary or ascii as output.vtk_format says, the deformed mid-surface tessellated per knot span;
point data `parameters` (ξ, η), `displacement`, `n`, `m`, `sigma_top`, `sigma_bottom` (components
11, 22, 12 in the local Cartesian frame whose first axis e1 ∥ a₁ is written as `e1`),
`principal_top/bottom` (1, 2), `von_mises_top/bottom`). Given a run directory, the last vtk/<shell>_NNNNNN.vtu is used (the
patch's own file; vtk/step_NNNNNN.vtu holds bodies, beams and director shells); a run with
several Kirchhoff–Love shells needs the file itself.

For every --field (default n:22 and m:22) one contour plot over the reference mid-surface
(Points − displacement), projected onto --coords A,B, each one of x, y, z (reference coordinates),
xi, eta (parameters) or phi_xy (the polar angle atan2(y, x) in degrees; for cylinders about z);
default xi,eta. With --line PARAM=VALUE[:LABEL] (PARAM xi or eta; the nearest tessellation line is
taken; LABEL for the legend) a second row shows each field along that parameter line, against the
first of --coords that varies along it.

COMP: 11, 22, 12 for n, m, sigma_top, sigma_bottom; x, y, z or norm for displacement; 1, 2 for
principal_top/bottom; nothing for von_mises_top/bottom. Which component is "along" a direction:
e1 is the direction of the 11 components, e2 = a₃ × e1 that of 22. --along X (x, y or z) prints
the mean |e1 · X| over the surface (≈ 1: X is the 11 direction; ≈ 0 on a surface whose e2 is X:
the 22 one) so a script can check it.

Needs python3, numpy and matplotlib (Debian: python3-numpy, python3-matplotlib). Exit status 2 on
a missing file, field or component.
"""
import argparse
import glob
import os
import sys
import xml.etree.ElementTree as ET

import numpy as np

COMPONENTS = {
    "n": {"11": 0, "22": 1, "12": 2},
    "m": {"11": 0, "22": 1, "12": 2},
    "sigma_top": {"11": 0, "22": 1, "12": 2},
    "sigma_bottom": {"11": 0, "22": 1, "12": 2},
    "displacement": {"x": 0, "y": 1, "z": 2},
    "principal_top": {"1": 0, "2": 1},
    "principal_bottom": {"1": 0, "2": 1},
}
LABELS = {"n": "membrane force n", "m": "bending moment m", "sigma_top": "σ top",
          "sigma_bottom": "σ bottom", "displacement": "u", "principal_top": "σ principal top",
          "principal_bottom": "σ principal bottom"}


def fail(msg):
    print(f"plot_kl_resultants: {msg}", file=sys.stderr)
    sys.exit(2)


def vtu_path(arg):
    if os.path.isdir(arg):
        files = sorted(f for f in glob.glob(os.path.join(arg, "vtk", "*_*.vtu"))
                       if not os.path.basename(f).startswith("step_"))
        shells = sorted({os.path.basename(f).rsplit("_", 1)[0] for f in files})
        if not shells:
            fail(f"no Kirchhoff–Love shell file vtk/<shell>_NNNNNN.vtu in {arg}")
        if len(shells) > 1:
            fail(f"{arg} has the shells {', '.join(shells)}: give the .vtu of one, e.g. "
                 f"{files[-1]}")
        return files[-1]
    if not os.path.isfile(arg):
        fail(f"no such file: {arg}")
    return arg


TYPES = {"Float64": "<f8", "Float32": "<f4", "Int64": "<i8", "Int32": "<i4", "UInt8": "u1"}


def read_vtu(path):
    """Point data {name: array (n,) or (n, k)}, points (n, 3), quads (m, 4).

    The arrays are ascii or appended raw binary (VTK XML Formats: <AppendedData encoding="raw">,
    data after its '_', each array's block at its offset: the byte count as header_type (UInt32
    or UInt64), then the little-endian values)."""
    with open(path, "rb") as f:
        content = f.read()
    appended = content.find(b'<AppendedData encoding="raw">')
    raw = b""
    if appended >= 0:  # the raw bytes are not XML: parse the markup without them
        raw = content[content.index(b"_", appended) + 1:]
        content = content[:appended] + b"</VTKFile>"
    try:
        root = ET.fromstring(content)
    except ET.ParseError as e:
        fail(f"cannot parse {path}: {e}")
    if raw and root.get("byte_order", "LittleEndian") != "LittleEndian":
        fail(f"{path}: binary data not LittleEndian")
    header = np.dtype("<u8" if root.get("header_type") == "UInt64" else "<u4")
    piece = root.find(".//Piece")
    if piece is None:
        fail(f"{path}: no <Piece> (not an UnstructuredGrid .vtu)")

    def array(da):
        k = int(da.get("NumberOfComponents", "1"))
        fmt = da.get("format", "ascii")
        if fmt == "ascii":
            v = np.array((da.text or "").split(), dtype=float)
        elif fmt == "appended" and raw and da.get("type") in TYPES:
            at = int(da.get("offset"))
            n = int(np.frombuffer(raw, header, 1, at)[0])
            v = np.frombuffer(raw[at + header.itemsize:at + header.itemsize + n],
                              TYPES[da.get("type")]).astype(float)
        else:
            fail(f"{path}: DataArray {da.get('Name')!r} is {fmt} of type {da.get('type')} "
                 f"(ascii or appended raw expected)")
        return v.reshape(-1, k) if k > 1 else v

    data = {}
    pd = piece.find("PointData")
    if pd is not None:
        for da in pd.iter("DataArray"):
            data[da.get("Name")] = array(da)
    points = array(piece.find("Points").find("DataArray"))
    cells = {da.get("Name"): array(da) for da in piece.find("Cells").iter("DataArray")}
    conn = cells["connectivity"].astype(int)
    offsets = cells["offsets"].astype(int)
    starts = np.concatenate(([0], offsets[:-1]))
    if not np.all(offsets - starts == 4):
        fail(f"{path}: expected quadrilateral cells only")
    quads = np.stack([conn[starts + i] for i in range(4)], axis=1)
    return data, points, quads


def field_values(data, spec):
    name, _, comp = spec.partition(":")
    if name not in data:
        fail(f"no point field {name!r} (fields: {', '.join(sorted(data))})")
    v = data[name]
    if v.ndim == 1:
        if comp:
            fail(f"field {name!r} has one component: write --field {name}")
        return v, name
    if name == "displacement" and comp == "norm":
        return np.linalg.norm(v, axis=1), "|u|"
    table = COMPONENTS.get(name, {str(i + 1): i for i in range(v.shape[1])})
    if comp not in table:
        fail(f"field {name!r}: component {comp!r} not one of {', '.join(table)}")
    return v[:, table[comp]], f"{LABELS.get(name, name)}_{comp}"


def coordinate(name, X, params):
    if name in ("x", "y", "z"):
        return X[:, "xyz".index(name)], name
    if name == "xi":
        return params[:, 0], "ξ"
    if name == "eta":
        return params[:, 1], "η"
    if name == "phi_xy":
        return np.degrees(np.arctan2(X[:, 1], X[:, 0])), "φ = atan2(y, x) [°]"
    fail(f"unknown coordinate {name!r} (x, y, z, xi, eta, phi_xy)")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("run")
    ap.add_argument("-o", "--output", default=None)
    ap.add_argument("--field", action="append", default=None)
    ap.add_argument("--coords", default="xi,eta")
    ap.add_argument("--line", action="append", default=[])
    ap.add_argument("--along", choices=["x", "y", "z"], default=None)
    ap.add_argument("--title", default="")
    ap.add_argument("--levels", type=int, default=21)
    a = ap.parse_args()
    fields = a.field or ["n:22", "m:22"]
    path = vtu_path(a.run)
    data, points, quads = read_vtu(path)
    for need in ("parameters", "displacement"):
        if need not in data:
            fail(f"{path}: no point field {need!r}: not a Kirchhoff–Love shell output")
    X = points - data["displacement"]
    params = data["parameters"]

    if a.along:
        if "e1" not in data:
            fail(f"{path}: no point field 'e1'")
        d = np.zeros(3)
        d["xyz".index(a.along)] = 1.0
        print(f"mean |e1 · {a.along}| = {np.mean(np.abs(data['e1'] @ d)):.6f}")

    cnames = a.coords.split(",")
    if len(cnames) != 2:
        fail("--coords takes two names, e.g. z,phi_xy")
    cu, lu = coordinate(cnames[0], X, params)
    cv, lv = coordinate(cnames[1], X, params)

    lines = []
    for spec in a.line:
        spec, _, text = spec.partition(":")
        pname, _, value = spec.partition("=")
        if pname not in ("xi", "eta"):
            fail(f"bad --line {spec!r}: expected xi=VALUE or eta=VALUE")
        try:
            value = float(value)
        except ValueError:
            fail(f"bad --line {spec!r}: VALUE is a number")
        col = 0 if pname == "xi" else 1
        grid = np.unique(np.round(params[:, col], 12))
        nearest = grid[np.argmin(np.abs(grid - value))]
        sel = np.where(np.abs(params[:, col] - nearest) < 1e-9)[0]
        sel = sel[np.argsort(params[sel, 1 - col])]
        label = f"{'ξ' if col == 0 else 'η'} = {nearest:g}"
        lines.append((f"{label} ({text})" if text else label, sel))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.tri as mtri

    tris = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    tri = mtri.Triangulation(cu, cv, tris)
    rows = 2 if lines else 1
    fig, axes = plt.subplots(rows, len(fields), figsize=(5.2 * len(fields), 4.2 * rows),
                             squeeze=False)
    for j, spec in enumerate(fields):
        values, label = field_values(data, spec)
        ax = axes[0][j]
        cs = ax.tricontourf(tri, values, levels=a.levels, cmap="jet")
        fig.colorbar(cs, ax=ax)
        ax.set_xlabel(lu)
        ax.set_ylabel(lv)
        ax.set_title(f"{label}  [{values.min():.4g}, {values.max():.4g}]", fontsize=10)
        if lines:
            ax2 = axes[1][j]
            for text, sel in lines:
                # Abscissa: the first of --coords that varies along the line.
                c, lc = (cu, lu) if np.ptp(cu[sel]) > np.ptp(cv[sel]) * 1e-6 else (cv, lv)
                ax2.plot(c[sel], values[sel], "-", label=text)
                ax2.set_xlabel(lc)
            ax2.set_ylabel(label)
            ax2.grid(True, lw=0.3)
            ax2.legend(fontsize=8)
    fig.suptitle(a.title or os.path.basename(path))
    fig.tight_layout()
    out = a.output or os.path.splitext(path)[0] + "_resultants.png"
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
