"""The suction panel of issue 19, rebuilt from its description without gmsh: a structured
triangulation of a 4.0 m × 2.4 m ETFE film (250 µm, E = 800 MPa, ν = 0.45, prestress 2 MPa both
ways) laid flat on three 60 mm steel tube arches (rise 0.25 m over the 2.4 m span, along y at
x = 1, 2 and 3 m; μ = 0.25), its short edges (x = 0 and x = 4 m) clamped in the rails ``railW`` and
``railE``, its long edges free or held by edge cables.

Load path (:func:`load_table`, for ``membrane_contact.Film.run``): both rails lowered 0.30 m in
10 stages (the film drapes over the arches), a wind suction ``suction.pressure`` (pushing the film
up, ``towards: "+z"``) raised to 400 Pa in 4 stages (the film lifts off its arches), then removed
in 4 stages.

``nx × ny`` nodes: the issue's gmsh mesh had 1 226 nodes and 2 322 triangles; the default 49 × 25
has 1 225 and 2 304 (every arch on a mesh column, 25 contact nodes each: 75, as the importer's).

Run: ``python examples/suction_panel.py [--small] [--cables] [--linear] [--out DIR]``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

LENGTH, WIDTH = 4.0, 2.4
RISE, TUBE_RADIUS = 0.25, 0.03
ARCHES = (1.0, 2.0, 3.0)
LOWERING, SUCTION = 0.30, 400.0


def model(nx: int = 49, ny: int = 25, cables: bool = False, wrinkling: str | None = "tension-field",
          name: str | None = None) -> dict:
    """The model file (a dict). ``nx - 1`` must be a multiple of 4 (arches on mesh columns);
    ``wrinkling=None`` leaves the entry out (the solver's default, the tension-field film)."""
    if (nx - 1) % 4 or nx < 5 or ny < 3:
        raise ValueError(f"nx = {nx} needs nx - 1 a multiple of 4 and ny = {ny} at least 3")
    dx, dy = LENGTH / (nx - 1), WIDTH / (ny - 1)
    top = RISE + TUBE_RADIUS  # the flat film touches the crowns
    nid = lambda i, j: j * nx + i  # noqa: E731
    nodes = [[i * dx, j * dy, top] for j in range(ny) for i in range(nx)]
    triangles = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            a, b, c, d = nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1)
            # alternate the diagonal so that the mesh has no preferred direction
            if (i + j) % 2 == 0:
                triangles += [[a, b, c], [a, c, d]]
            else:
                triangles += [[a, b, d], [b, c, d]]
    material = {"youngs_modulus": 800e6, "poisson_ratio": 0.45, "thickness": 250e-6,
                "prestress": [2e6, 2e6, 0.0]}
    if wrinkling is not None:
        material["wrinkling"] = wrinkling
    kn = 1000 * 800e6 * 250e-6
    supports = []
    for k, x in enumerate(ARCHES):
        column = round(x / dx)
        supports.append({
            "name": f"arch{k + 1}",
            "centreline": {"parabola": {"apex": [x, WIDTH / 2, RISE], "up": [0, 0, 1], "along": [0, 1, 0],
                                        "half_span": WIDTH / 2, "rise": RISE}},
            "tube_radius": TUBE_RADIUS, "nodes": [nid(column, j) for j in range(ny)],
            "normal_stiffness": kn, "tangential_stiffness": 0.1 * kn, "friction": 0.25,
        })
    groups = [{"name": "railW", "nodes": [nid(0, j) for j in range(ny)], "target": [0.0, 0.0, -LOWERING]},
              {"name": "railE", "nodes": [nid(nx - 1, j) for j in range(ny)], "target": [0.0, 0.0, -LOWERING]}]
    m = {
        "name": name or f"SuctionPanel{'Cables' if cables else ''}{'Linear' if wrinkling == 'none' else ''}{nx}x{ny}",
        "description": "issue 19's suction panel: film over three tube arches, rails lowered, suction",
        "nodes": nodes, "triangles": triangles, "material": material,
        "groups": groups, "curved_supports": supports,
        "loads": {"pressures": [{"name": "suction", "elements": "all", "pressure": 0.0, "towards": "+z"}]},
        "outputs": {"points": [{"name": "mid", "node": nid((nx - 1) // 2 + (nx - 1) // 8, ny // 2)}],
                    "element_sets": [{"name": "panel", "elements": "all"}]},
    }
    if cables:
        m["cables"] = [{"name": f"edge{side}", "nodes": [nid(i, j) for i in range(nx)], "area": 1.1e-4,
                        "youngs_modulus": 1.6e11, "prestress_force": 2000.0}
                       for side, j in (("S", 0), ("N", ny - 1))]
    return m


def load_table(erection: int = 10, suction: int = 4, removal: int = 4) -> dict:
    """The staged load path as ``Film.run`` columns: rails down, suction up, suction off."""
    rows = [(0.0, 0.0)]
    rows += [(-LOWERING * k / erection, 0.0) for k in range(1, erection + 1)]
    rows += [(-LOWERING, SUCTION * k / suction) for k in range(1, suction + 1)]
    rows += [(-LOWERING, SUCTION * (1 - k / removal)) for k in range(1, removal + 1)]
    return {"time": [float(t) for t in range(len(rows))],
            "railW.dz": [r[0] for r in rows], "railE.dz": [r[0] for r in rows],
            "suction.pressure": [r[1] for r in rows]}


def path_csv(table: dict) -> str:
    """The table as a CLI ``--path`` CSV (first column time)."""
    names = list(table)
    lines = [",".join(names)]
    lines += [",".join(repr(table[n][k]) for n in names) for k in range(len(table["time"]))]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--small", action="store_true", help="17 × 9 nodes instead of 49 × 25")
    p.add_argument("--cables", action="store_true", help="edge cables on the long edges")
    p.add_argument("--linear", action="store_true", help="wrinkling 'none' (the linear film)")
    p.add_argument("--out", default=".", help="directory of the model file and its --path CSV")
    a = p.parse_args(argv)
    nx, ny = (17, 9) if a.small else (49, 25)
    m = model(nx, ny, a.cables, "none" if a.linear else "tension-field")
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{m['name']}.json").write_text(json.dumps(m))
    (out / f"{m['name']}_path.csv").write_text(path_csv(load_table()))
    print(out / f"{m['name']}.json")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
