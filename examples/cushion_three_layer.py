"""A rectangular three-layer ETFE cushion, 3 m x 6 m, through inflation, snow, wind and sun (issue 43).

Three layers (250/100/250 µm, ETFE with the data-sheet plasticity ``etfe-23C``, tension-field
film, E = 1 GPa, ν = 0.43, 0.5 MPa prestress) share their boundary nodes, clamped in the
extrusions along the four edges. Two chambers: ``upper`` (top and middle layer) and ``lower``
(middle and bottom). The model file is written here and run by ``membrane-contact model`` along
a staged path (``--path``), one row per step:

1. **inflate**: both chambers held by the inflation unit, 0 to 300 Pa;
2. **snow** (plan load on the top layer, 0 to ``--snow`` Pa): the lower chamber's valve closed
   (its air enclosed: Boyle), the upper chamber held at 300 Pa by the unit (the air that the top
   pushes out leaves through it). The top layer inverts and lands on the middle layer
   (node-to-surface layer contact, μ = 0.3), and the two carry the snow on the lower air;
3. the snow melts (back to 0);
4. **wind**: the upper valve closed too (both chambers enclosed), suction on the top layer
   (follower pressure, 0 to ``--wind`` Pa), then back to 0;
5. **sun**: both chambers' air heated by 30 K.

Prints a table of each stage's end: chamber pressures and volumes, contact area (the touching
top nodes' tributary area), contact force and largest contact pressure, the largest von Mises
stress and plastic strain per layer, and the reactions along the extrusions (kN/m, the CLI's
``--line-reactions``: max and mean over the nodes between the corners of the long and the short
edges). Checks, says so and exits non-zero otherwise: each enclosed chamber keeps
``(p + p_a) V / T`` (the gas law, isothermal but for the sun's 30 K) to 1e-6 from the state its
valve closed at, the held chamber its 300 Pa, every valve as the path set it, the top touches the
middle layer under the snow, and the reactions' vertical total equals the snow's plan load and
the suction's projected load (18 m² each) to 1e-6 of the load (the air's pressure has no
resultant on a closed cushion). Writes the figure ``cushion_three_layer.png`` into ``--out``:
the deflected section through the middle of the cushion (x across the 3 m span, at y = 3 m) at
the end of each stage, and the reaction per unit length along one long edge.

The golden number (``tests/python/test_examples.py`` checks it): the lower chamber's pressure
under the full snow, printed as ``lower chamber under the snow: ... Pa``.

    .venv/bin/python examples/cushion_three_layer.py [--out DIR] [--nx 10 --ny 20] [--snow 1500]
        [--wind 1000] [--steps 4] [--keep DIR]

Needs the release build (``cargo build --release``) or ``$MEMBRANE_CONTACT_CLI`` and
matplotlib; about 6 s on one core (docs/mechanics.md, "The rectangular three-layer cushion", has
the figures).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CLI = Path(os.environ.get("MEMBRANE_CONTACT_CLI") or ROOT / "target" / "release" / "membrane-contact")

WIDTH, LENGTH = 3.0, 6.0
THICKNESS = {"top": 250e-6, "middle": 100e-6, "bottom": 250e-6}
INFLATION, HEATING = 300.0, 30.0
ATMOSPHERE = 101325.0


def cushion(nx: int = 10, ny: int = 20):
    """The model (a dict) of an ``nx`` x ``ny`` grid per layer over 3 m x 6 m, the boundary nodes
    shared and held by the support sets ``west``, ``east`` (the long edges, corners included),
    ``south`` and ``north``; and each layer's nodes along the section y = 3 m."""
    ids = {}
    nodes = []

    def node(layer, i, j):
        on_edge = i in (0, nx) or j in (0, ny)
        key = ("edge", i, j) if on_edge else (layer, i, j)
        if key not in ids:
            ids[key] = len(nodes)
            nodes.append([WIDTH * i / nx, LENGTH * j / ny, 0.0])
        return ids[key]

    for i in range(nx + 1):
        for j in range(ny + 1):
            if i in (0, nx) or j in (0, ny):
                node("edge", i, j)
    triangles, layers = [], {}
    for layer in ("top", "middle", "bottom"):
        first = len(triangles)
        for j in range(ny):
            for i in range(nx):
                a, b, c, d = node(layer, i, j), node(layer, i + 1, j), node(layer, i + 1, j + 1), node(layer, i, j + 1)
                # Diagonals alternate so the mesh is symmetric about both mid-lines.
                pair = [[a, b, c], [a, c, d]] if (i < nx // 2) == (j < ny // 2) else [[a, b, d], [b, c, d]]
                if layer == "bottom":  # normal -z: out of the lower chamber
                    pair = [[t[0], t[2], t[1]] for t in pair]
                triangles += pair
        layers[layer] = list(range(first, len(triangles)))
    edges = {"west": [], "east": [], "south": [], "north": []}
    for (kind, i, j), n in ids.items():
        if kind != "edge":
            continue
        side = "west" if i == 0 else "east" if i == nx else "south" if j == 0 else "north"
        edges[side].append(n)
    supports = [{"node": n, "fixed": ["x", "y", "z"], "name": side} for side, ns in edges.items() for n in sorted(ns)]
    # The section through the middle (y = 3 m), each layer's nodes across the span.
    section = {layer: [node(layer, i, ny // 2) for i in range(nx + 1)] for layer in ("top", "middle", "bottom")}
    chamber = dict(pressure=INFLATION, sealed=False, kappa=1.0, atmosphere=ATMOSPHERE, temperature=293.15)
    return {
        "name": "CushionThreeLayer",
        "description": "Rectangular three-layer ETFE cushion 3 m x 6 m, 250/100/250 um, two chambers "
                       "(examples/cushion_three_layer.py)",
        "nodes": nodes,
        "triangles": triangles,
        "material": {"youngs_modulus": 1e9, "poisson_ratio": 0.43, "thickness": 250e-6,
                     "prestress": [0.5e6, 0.5e6, 0.0], "wrinkling": "tension-field",
                     "plasticity": {"hardening": "etfe-23C"}},
        "layers": [{"name": n, "elements": layers[n], "thickness": THICKNESS[n]} for n in ("top", "middle", "bottom")],
        "supports": supports,
        "loads": {"pressures": [
            {"name": "snow", "elements": layers["top"], "pressure": 0.0, "kind": "plan", "towards": "-z"},
            {"name": "wind", "elements": layers["top"], "pressure": 0.0, "towards": "+z"}]},
        "chambers": [
            dict(name="upper", elements=layers["top"] + layers["middle"], **chamber),
            dict(name="lower", elements=layers["bottom"] + layers["middle"], **chamber)],
        "layer_contacts": [{"name": "touch", "slave": "top", "master": "middle", "side": "front",
                            "normal_stiffness": 1e6, "tangential_stiffness": 2e5, "friction": 0.3,
                            "search_distance": 0.5}],
    }, section


#: The path's columns.
COLUMNS = ["time", "upper.supplyPressure", "lower.supplyPressure", "upper.sealed", "lower.sealed",
           "snow.pressure", "wind.pressure", "upper.heating", "lower.heating"]


def stages(snow: float, wind: float, steps: int = 4):
    """The path's rows, and each stage's (name, last row index)."""
    rows, ends = [], []

    def ramp(name, n, **change):
        start = dict(rows[-1]) if rows else {c: 0.0 for c in COLUMNS}
        for k in range(1, n + 1):
            row = dict(start)
            for c, v in change.items():
                row[c] = start[c] + (v - start[c]) * k / n if isinstance(v, float) else v
            rows.append(row)
        ends.append((name, len(rows) - 1))

    ramp("inflated", steps, **{"upper.supplyPressure": INFLATION, "lower.supplyPressure": INFLATION})
    ramp("snow", 2 * steps, **{"lower.sealed": 1, "snow.pressure": float(snow)})
    ramp("snow melted", steps, **{"snow.pressure": 0.0})
    ramp("wind suction", steps, **{"upper.sealed": 1, "wind.pressure": float(wind)})
    ramp("calm", steps, **{"wind.pressure": 0.0})
    ramp("sun", steps, **{"upper.heating": HEATING, "lower.heating": HEATING})
    for k, row in enumerate(rows):
        row["time"] = float(k + 1)
    return rows, ends


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def run(model, rows, out_dir: Path):
    """Runs the CLI on the model and path; returns its stdout and seconds."""
    (out_dir / "cushion.json").write_text(json.dumps(model))
    with open(out_dir / "path.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        for r in rows:
            w.writerow([r["time"]] + [int(r[c]) if c.endswith("sealed") else r[c] for c in COLUMNS[1:]])
    cmd = [str(CLI), "model", str(out_dir / "cushion.json"), "--path", str(out_dir / "path.csv"), "--quiet",
           "--chambers-csv", str(out_dir / "chambers.csv"), "--elements-csv", str(out_dir / "elements.csv"),
           "--layer-contacts-csv", str(out_dir / "contacts.csv"), "--line-reactions", str(out_dir / "lines.csv"),
           "--vtk", str(out_dir / "vtk"), "--vtk-format", "ascii"]
    started = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.perf_counter() - started
    if r.returncode != 0:
        sys.exit(f"membrane-contact failed:\n{r.stdout}\n{r.stderr}")
    return r.stdout, seconds


def per_step(rows, key):
    """CSV rows grouped by step (int) and then by ``key``."""
    out = defaultdict(dict)
    for r in rows:
        out[int(r["step"])][r[key]] = r
    return out


def air(c):
    """``(p + p_a) V / T`` of a chambers CSV row: the air's mass times R."""
    return (float(c["pressure_Pa"]) + ATMOSPHERE) * float(c["volume_m3"]) / float(c["temperature_K"])


def gas_law(chambers, ends, rows):
    """The largest relative change of ``(p + p_a) V / T`` of each enclosed chamber over the steps
    it stays enclosed (from the converged state its valve closed at), the largest departure of
    a held chamber from its supply's 300 Pa, and the steps whose valves are not the path's."""
    drift, held, valves = 0.0, 0.0, 0
    steps = sorted(chambers)
    for name in ("upper", "lower"):
        reference = None
        for k, step in enumerate(steps):
            c = chambers[step][name]
            p = float(c["pressure_Pa"])
            valves += int(c["sealed"]) != rows[step - 1][f"{name}.sealed"]
            if c["sealed"] == "1":
                if reference is None:  # sealed as this step started: the step before's air
                    b = chambers[steps[k - 1]][name]
                    reference = air(b)
                drift = max(drift, abs(air(c) / reference - 1.0))
            else:
                reference = None
                if step > ends[0][1]:
                    held = max(held, abs(p - INFLATION))
    return drift, held, valves


def vertical_balance(lines, rows):
    """The largest difference, over the steps, between the supports' summed vertical reaction and
    the loads' vertical total (snow per plan area, suction on the top's projection: 18 m² each),
    relative to the larger of the load and 1 N."""
    worst = 0.0
    for step, by_node in lines.items():
        rz = sum(float(r["Rz_N"]) for r in by_node.values())
        row = rows[step - 1]
        load = (row["snow.pressure"] - row["wind.pressure"]) * WIDTH * LENGTH
        worst = max(worst, abs(rz - load) / max(abs(load), 1.0))
    return worst


def edge_reactions(by_node):
    """Per edge kind ("long": west and east, "short": south and north): the largest and the mean
    reaction per unit length (kN/m, magnitude) over the nodes between the corners."""
    out = {}
    for kind, sides in (("long", ("west", "east")), ("short", ("south", "north"))):
        q = [float(r["q_N_per_m"]) / 1e3 for r in by_node.values() if r["line"] in sides and not corner(r)]
        out[kind] = (max(q), sum(q) / len(q))
    return out


def corner(r):
    return float(r["x_m"]) in (0.0, WIDTH) and float(r["y_m"]) in (0.0, LENGTH)


def stage_table(model, ends, chambers, contacts, elements, lines):
    """Each stage's figures at its last step."""
    layer_of = {e: l["name"] for l in model["layers"] for e in l["elements"]}
    table = []
    for name, k in ends:
        step = k + 1
        touching = [r for r in contacts[step].values() if float(r["normal_force_N"]) > 0.0]
        air_at = chambers[step]
        stress, plastic = defaultdict(float), defaultdict(float)
        for r in elements[step].values():
            layer = layer_of[int(r["element"])]
            stress[layer] = max(stress[layer], float(r["von_mises_Pa"]) / 1e6)
            plastic[layer] = max(plastic[layer], float(r.get("equivalent_plastic_strain", 0.0)))
        table.append({
            "stage": name, "step": step,
            "upper": float(air_at["upper"]["pressure_Pa"]), "lower": float(air_at["lower"]["pressure_Pa"]),
            "V upper": float(air_at["upper"]["volume_m3"]), "V lower": float(air_at["lower"]["volume_m3"]),
            "contact nodes": len(touching),
            "contact area": sum(float(r["normal_force_N"]) / float(r["pressure_Pa"]) for r in touching),
            "contact force": sum(float(r["normal_force_N"]) for r in touching) / 1e3,
            "contact pressure": max((float(r["pressure_Pa"]) for r in touching), default=0.0),
            "stress": dict(stress), "plastic": dict(plastic), "edges": edge_reactions(lines[step]),
        })
    return table


def print_table(table):
    rows = [
        ("upper chamber (Pa)", lambda s: f"{s['upper']:.1f}"),
        ("lower chamber (Pa)", lambda s: f"{s['lower']:.1f}"),
        ("volumes upper/lower (m³)", lambda s: f"{s['V upper']:.3f}/{s['V lower']:.3f}"),
        ("contact area (m²)", lambda s: f"{s['contact area']:.2f}"),
        ("contact force (kN)", lambda s: f"{s['contact force']:.2f}"),
        ("max contact pressure (Pa)", lambda s: f"{s['contact pressure']:.0f}"),
    ] + [(f"von Mises {layer} (MPa)", lambda s, layer=layer: f"{s['stress'][layer]:.2f}") for layer in THICKNESS] + [
        (f"plastic strain {layer}", lambda s, layer=layer: f"{s['plastic'][layer]:.2e}") for layer in THICKNESS] + [
        ("long edges max/mean (kN/m)", lambda s: "{:.2f}/{:.2f}".format(*s["edges"]["long"])),
        ("short edges max/mean (kN/m)", lambda s: "{:.2f}/{:.2f}".format(*s["edges"]["short"])),
    ]
    width = 13
    print(f"{'':28}" + "".join(f"{s['stage']:>{width}}" for s in table))
    for label, cell in rows:
        print(f"{label:28}" + "".join(f"{cell(s):>{width}}" for s in table))


def read_points(vtu):
    """The deformed node positions of a .vtu written with --vtk-format ascii."""
    text = Path(vtu).read_text()
    block = text.split("<Points>", 1)[1].split(">", 1)[1].split("</DataArray>", 1)[0]
    values = [float(v) for v in block.split()]
    return [values[i:i + 3] for i in range(0, len(values), 3)]


def plot(path, work, model, section, ends, lines):
    """The deflected section at y = 3 m at each stage's end, and the reaction per unit length
    along the west long edge (x = 0)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(2, 1, figsize=(8, 8))
    styles = {"top": "-", "middle": ":", "bottom": "--"}
    for (name, k), colour in zip(ends, plt.rcParams["axes.prop_cycle"].by_key()["color"]):
        points = read_points(work / "vtk" / f"{model['name']}_film_{k + 1:04d}.vtu")
        for layer, nodes in section.items():
            a.plot([points[n][0] for n in nodes], [points[n][2] * 1e3 for n in nodes], styles[layer], color=colour,
                   label=name if layer == "top" else None)
        edge = sorted((float(r["y_m"]), float(r["q_N_per_m"]) / 1e3)
                      for r in lines[k + 1].values() if r["line"] == "west")
        b.plot([y for y, _ in edge], [q for _, q in edge], "o-", color=colour, label=name, ms=3)
    a.set_title("section through the middle (y = 3 m) at the end of each stage", fontsize=10)
    b.set_title("reaction per unit length along the long edge x = 0", fontsize=10)
    a.set_xlabel("x across the span at y = 3 m (m)")
    a.set_ylabel("z (mm): top -, middle :, bottom --")
    a.legend(fontsize=8)
    b.set_xlabel("y along the long edge x = 0 (m)")
    b.set_ylabel("reaction (kN/m)")
    b.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default=".", help="directory of the figure")
    p.add_argument("--nx", type=int, default=10, help="divisions across the 3 m span")
    p.add_argument("--ny", type=int, default=20, help="divisions along the 6 m length")
    p.add_argument("--steps", type=int, default=4, help="steps per stage (the snow takes twice)")
    p.add_argument("--snow", type=float, default=1500.0, help="snow per plan area (Pa)")
    p.add_argument("--wind", type=float, default=1000.0, help="wind suction (Pa)")
    p.add_argument("--keep", default=None, help="directory for the model, path and CLI outputs")
    a = p.parse_args(argv)
    model, section = cushion(a.nx, a.ny)
    rows, ends = stages(a.snow, a.wind, a.steps)
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(a.keep or tmp)
        work.mkdir(parents=True, exist_ok=True)
        _, seconds = run(model, rows, work)
        chambers = per_step(read_rows(work / "chambers.csv"), "chamber")
        contacts = per_step(read_rows(work / "contacts.csv"), "node")
        elements = per_step(read_rows(work / "elements.csv"), "element")
        lines = per_step(read_rows(work / "lines.csv"), "node")
        table = stage_table(model, ends, chambers, contacts, elements, lines)
        print(f"{model['description']}: {len(model['nodes'])} nodes, {len(model['triangles'])} triangles, "
              f"{len(rows)} steps, {seconds:.1f} s")
        print_table(table)
        drift, held, valves = gas_law(chambers, ends, rows)
        balance = vertical_balance(lines, rows)
        print(f"gas law: (p + p_a) V / T of each enclosed chamber kept to {drift:.1e} (checked: 1e-6); "
              f"the held chamber within {held:.1e} Pa of 300 Pa; {valves} valves not as the path set them")
        print(f"vertical reactions = snow and suction loads to {balance:.1e} of the load (checked: 1e-6)")
        out = Path(a.out)
        out.mkdir(parents=True, exist_ok=True)
        plot(out / "cushion_three_layer.png", work, model, section, ends, lines)
    snow = next(s for s in table if s["stage"] == "snow")
    print(f"lower chamber under the snow: {snow['lower']:.1f} Pa")
    if not (drift < 1e-6 and held < 1e-6 and valves == 0 and balance < 1e-6 and snow["contact nodes"] > 0):
        sys.exit("a check failed: gas law, held pressure, valves, vertical balance or the top not on the middle layer")


if __name__ == "__main__":
    main()
