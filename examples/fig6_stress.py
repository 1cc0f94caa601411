"""Paper Fig. 6: deformed film and element equivalent (von Mises) stress, 300 mm arch, mu = 0.2.

The picture is read from the VTK XML unstructured grids (.vtu, ASCII or raw appended binary)
with the standard library's xml.etree and numpy: the film (points = deformed node positions,
triangles, cell data ``von_mises`` etc.) and the gaps (one line per gap from its film node to its
support on the arch, cell data ``gap_status``).

Where the .vtu files come from (--source): the FMU, through its String parameter
``results.directory`` (it writes <dir>/ParallelArch_film_NNNN.vtu and ..._gaps_NNNN.vtu after
every step; the default when the FMU has it), or the core's CLI (``membrane-contact specimen
--vtk DIR``, the same solver without FMI, the same increments per step); or a film file given with
--vtu (its ``_gaps_`` sibling is read if there). The 1/4 model is mirrored about its two symmetry planes (x = 0 between the arches,
y = 0 through the crowns) to show the whole specimen.

Writes fig6_stress.png and fig6_stress.csv (per triangle of the 1/4 model: centroid, von Mises
and principal stresses in MPa) into --out.

    .venv/bin/python examples/fig6_stress.py [--steps 20] [--out DIR] [--vtu FILE]
"""

from __future__ import annotations

import math
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import archfmu  # noqa: E402

VTK_TRIANGLE, VTK_LINE = 5, 3


VTK_TYPES = {"Float64": "<f8", "Float32": "<f4", "Int64": "<i8", "Int32": "<i4", "UInt64": "<u8",
             "UInt32": "<u4", "UInt8": "u1"}


def read_vtu(path) -> dict:
    """Arrays of a .vtu (ASCII, or raw appended data with UInt64 block headers as the FMU and
    the CLI write it): points, connectivity/offsets/types, point and cell data."""
    data = Path(path).read_bytes()
    # Raw appended data is not XML: parse what precedes it, read the blocks by their offsets.
    head, marker, tail = data.partition(b"<AppendedData")
    appended = tail[tail.index(b"_") + 1:] if marker else b""
    root = ET.fromstring(head + b"</VTKFile>" if marker else data)
    piece = root.find("UnstructuredGrid/Piece")
    if piece is None:
        raise ValueError(f"{path}: not a VTK UnstructuredGrid file")
    header = np.dtype(VTK_TYPES[root.get("header_type", "UInt32")])

    def array(da):
        n = int(da.get("NumberOfComponents", "1"))
        if da.get("format", "ascii") == "ascii":
            a = np.array(da.text.split(), dtype=float)
        elif da.get("format") == "appended" and marker:
            at = int(da.get("offset"))
            size = int(np.frombuffer(appended, header, 1, at)[0])
            a = np.frombuffer(appended[at + header.itemsize:at + header.itemsize + size],
                              VTK_TYPES[da.get("type")]).astype(float)
        else:
            raise ValueError(f"{path}: {da.get('format')} DataArrays are not read")
        return a.reshape(-1, n) if n > 1 else a

    cells = {da.get("Name"): array(da).astype(int) for da in piece.find("Cells")}
    return {
        "points": array(piece.find("Points/DataArray")),
        "connectivity": cells["connectivity"],
        "offsets": cells["offsets"],
        "types": cells["types"],
        "point_data": {da.get("Name"): array(da) for da in piece.find("PointData") or []},
        "cell_data": {da.get("Name"): array(da) for da in piece.find("CellData") or []},
        "n_points": int(piece.get("NumberOfPoints")),
        "n_cells": int(piece.get("NumberOfCells")),
    }


def cells_of(vtu, vtk_type):
    """(cell indices, node lists) of every cell of ``vtk_type``."""
    starts = np.concatenate([[0], vtu["offsets"][:-1]])
    idx = [i for i, t in enumerate(vtu["types"]) if t == vtk_type]
    return idx, [vtu["connectivity"][starts[i]:vtu["offsets"][i]] for i in idx]


def mirrored(points):
    """The four copies of the 1/4 model (x >= 0, y >= 0) about x = 0 and y = 0."""
    return [points * np.array([sx, sy, 1.0]) for sx in (1, -1) for sy in (1, -1)]


def arch_circle(supports):
    """Least-squares circle (yc, zc, R) through the gap support points of one arch (y, z)."""
    y, z = supports[:, 1], supports[:, 2]
    A = np.column_stack([2 * y, 2 * z, np.ones_like(y)])
    yc, zc, c = np.linalg.lstsq(A, y ** 2 + z ** 2, rcond=None)[0]
    return yc, zc, math.sqrt(c + yc ** 2 + zc ** 2)


def fmu_writes_vtk(fmu_path) -> bool:
    """Does the FMU have the results-directory String parameter?"""
    try:
        from fmpy import read_model_description
        md = read_model_description(str(fmu_path))
    except Exception:
        return False
    return any(v.name == archfmu.RESULTS_DIRECTORY and v.type == "String"
               and v.causality == "parameter" for v in md.modelVariables)


def gap_lines(gaps):
    """(film node positions, support positions, statuses) of the gap lines of ``gaps`` (the
    gaps .vtu, or an older file holding film and gaps)."""
    line_idx, lines = cells_of(gaps, VTK_LINE)
    pts = gaps["points"]
    status = gaps["cell_data"].get("gap_status")
    status = status[line_idx] if status is not None else np.ones(len(lines))
    ends = np.array(lines, dtype=int).reshape(-1, 2)
    return pts[ends[:, 0]], pts[ends[:, 1]], status


def plot(vtu, gaps, title, path):
    plt = archfmu.use_agg()
    from matplotlib import colors
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    pts = vtu["points"]
    tri_idx, tris = cells_of(vtu, VTK_TRIANGLE)
    tris = np.array(tris)
    vm = vtu["cell_data"]["von_mises"][tri_idx] / 1e6
    gap_nodes, supports, gap_status = gap_lines(gaps if gaps is not None else vtu)
    norm = colors.Normalize(vmin=vm.min(), vmax=vm.max())
    cmap = plt.get_cmap("jet")

    fig = plt.figure(figsize=(12.5, 5.6))
    grid = fig.add_gridspec(1, 2, width_ratios=[1.35, 1])
    ax = fig.add_subplot(grid[0, 0], projection="3d")
    for copy in mirrored(pts):
        poly = Poly3DCollection(copy[tris], facecolors=cmap(norm(vm)), edgecolors="k",
                                linewidths=0.15)
        ax.add_collection3d(poly)
    # Arches: circle through the gap supports, mirrored to the full span.
    if len(supports) >= 3:
        yc, zc, r = arch_circle(supports)
        half = math.sqrt(max(r ** 2 - zc ** 2, 0.0))  # foot at z = 0
        ys = np.linspace(-half, half, 60)
        zs = zc + np.sqrt(np.maximum(r ** 2 - (ys - yc) ** 2, 0.0))
        x_arch = supports[0, 0]
        segs = [np.column_stack([np.full_like(ys, sx * x_arch), ys, zs]) for sx in (1, -1)]
        ax.add_collection3d(Line3DCollection(segs, colors="0.25", linewidths=2.5))
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    ext = max(abs(lo[0]), abs(hi[0]), abs(lo[1]), abs(hi[1]))
    ax.set_xlim(-ext, ext)
    ax.set_ylim(-ext, ext)
    ax.set_zlim(0, max(hi[2], 1e-3))
    z_scale = 0.35 * 2 * ext / max(hi[2], 1e-3)
    ax.set_box_aspect((1, 1, 0.35))
    ax.view_init(elev=24, azim=-58)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(f"whole specimen (1/4 model mirrored), arches in grey, z × {z_scale:.1f}",
                 fontsize=9)

    bx = fig.add_subplot(grid[0, 1])
    tpc = bx.tripcolor(pts[:, 0], pts[:, 1], tris, facecolors=vm, cmap=cmap, norm=norm,
                       edgecolors="k", linewidth=0.15)
    if len(gap_nodes):
        for k, (p, s) in enumerate(zip(gap_nodes, gap_status)):
            closed = s > 0
            bx.plot(p[0], p[1], "o", ms=6, mec="k", mfc="w" if not closed else "k")
            bx.annotate(f"G{k + 1}", (p[0], p[1]), textcoords="offset points",
                        xytext=(5, -3), fontsize=7)
        bx.plot([], [], "ko", label="gap in contact")
        bx.plot([], [], "o", mec="k", mfc="w", label="gap open")
        bx.legend(fontsize=7, loc="upper right", framealpha=0.9)
    bx.set_aspect("equal")
    bx.set_xlabel("x (m)  (x = 0: between the arches)")
    bx.set_ylabel("y (m)  (y = 0: crowns)")
    bx.set_title("1/4 model, top view of the deformed film", fontsize=9)
    fig.colorbar(tpc, ax=bx, shrink=0.85, label="von Mises stress (MPa), both views")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.02, 1, 0.96))
    archfmu.save_png(fig, path)
    plt.close(fig)


def element_rows(vtu):
    tri_idx, tris = cells_of(vtu, VTK_TRIANGLE)
    cd, pts = vtu["cell_data"], vtu["points"]
    rows = []
    for e, (i, nodes) in enumerate(zip(tri_idx, tris)):
        c = pts[nodes].mean(axis=0)
        rows.append([e, float(c[0]), float(c[1]), float(c[2]), float(cd["von_mises"][i] / 1e6),
                     float(cd["principal_1"][i] / 1e6), float(cd["principal_2"][i] / 1e6)])
    return rows


def main(argv=None):
    p = archfmu.example_parser(__doc__.splitlines()[0], steps=20)
    p.add_argument("--height", type=float, default=300.0, help="arch height in mm (default 300)")
    p.add_argument("--mu", type=float, default=0.2, help="friction coefficient (default 0.2)")
    p.add_argument("--vtu", help="plot this film .vtu (and its _gaps_ sibling) instead of "
                                 "running the analysis")
    p.add_argument("--source", choices=["auto", "fmu", "cli"], default="auto",
                   help="who writes the .vtu: the FMU (its results.directory parameter), the "
                        "CLI (--vtk), or auto: the FMU if it has the parameter (default)")
    a = p.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    height = a.height / 1e3
    source = a.source
    if source == "auto":
        source = "fmu" if fmu_writes_vtk(a.fmu) else "cli"
    with tempfile.TemporaryDirectory() as tmp:
        if a.vtu:
            vtu_path, source = Path(a.vtu), "file"
        else:
            vtk_dir = Path(tmp) / "vtk"
            archfmu.ramp(height, a.mu, a.steps, backend=source, fmu_path=a.fmu, vtk_dir=vtk_dir)
            # <id>_film_NNNN.vtu: the last step
            vtu_path = sorted(vtk_dir.glob("*_film_*.vtu"))[-1]
        vtu = read_vtu(vtu_path)
        gaps_path = vtu_path.with_name(vtu_path.name.replace("_film_", "_gaps_"))
        gaps = read_vtu(gaps_path) if gaps_path != vtu_path and gaps_path.is_file() else None
    source = {"fmu": f"FMU {archfmu.RESULTS_DIRECTORY}", "cli": "CLI --vtk"}.get(source, source)
    rows = element_rows(vtu)
    csv_path = archfmu.write_csv(out / "fig6_stress.csv",
                                 ["element", "x_m", "y_m", "z_m", "von_mises_MPa",
                                  "principal_1_MPa", "principal_2_MPa"], rows)
    vm = np.array([r[4] for r in rows])
    title = (f"Fig. 6: equivalent stress on the membrane elements, {a.height:.0f} mm arch, "
             f"μ = {a.mu:g}, frame dz = {-a.height / 2:.0f} mm ({a.steps} steps; .vtu from "
             f"{source})")
    png = out / "fig6_stress.png"
    plot(vtu, gaps, title, png)
    print(f"{len(rows)} triangles, von Mises {vm.min():.2f} ... {vm.max():.2f} MPa "
          f"(.vtu from {source})")
    print(f"wrote {png} and {csv_path}")
    return {"vtu_source": source, "von_mises_MPa": vm}


if __name__ == "__main__":
    main()
