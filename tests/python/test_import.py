"""Mesh import (issue 9 items 1 and 2): gmsh mesh + mapping → model file → CLI and FMU.

SOURCE: hand geometry of ``examples/film_over_two_arches/`` (film_over_two_arches.geo, meshed
by gmsh 4.15.2 from PyPI into the checked-in gmsh 2.2 ASCII and 4.1 binary files); the gap
frames and initial gaps follow the paper's §4.3 as ``src/specimens/parallel_arch.rs`` builds them: z
from the arch's centre of curvature through the contact point, x along the arch, y = z × x,
``g0 = |A − C| − R`` for a film node A in the arch's plane.

TEST GOAL:
* both gmsh formats import to the same model (same numbering, coordinates to 1e-12);
* every gap frame is orthonormal and right-handed to 1e-9 (x along the arch, y its plane
  normal, z outward); the initial gaps are the geometric distances to the arch (circle: closed
  form; parabola and polyline: against densely sampled curves); gaps are numbered from the
  arch's start to its end;
* a distance band around the curve selects the same film nodes as the physical group;
* errors name the bad item (physical group, node with coordinates, mapping key, cell type);
* quads are refused, or split with a warning; a physical line becomes a cable chain;
* the imported model runs in the Rust CLI without warnings: the frame goes down, the film
  drapes over the arches, the crown gaps close and slide outward symmetrically, the far gaps
  stay open, and the frame's reaction balances the gap forces;
* an FMU packed from it steps through fmpy to what the CLI computes, with the exact balance
  ``R_frame + Σ (N z + T_x x + T_y y) = 0`` from the FMU's outputs.

MESH (examples/film_over_two_arches, z = 0.3 everywhere, ~0.2 m triangles)::

    y=2.0  F F F F F F F F F F F F F F F F      F: boundary group "frame" (4 edges)
           F                             F
    y=1.4  F  N1 N2 . . . . . . . . N13  F      N1..N13: gaps over the arch y = 1.4
           F            c                F      c: output point "centre" (1.5, 1.0)
    y=0.6  F  S1 S2 . . . S7. . . . S13  F      S1..S13: gaps over the arch y = 0.6
    y=0    F F F F F F F F F F F F F F F F          (x = 0.3 … 2.7, crown S7/N7 at x = 1.5)
          x=0                           x=3

    arches: circles in the planes y = 0.6 / 1.4, feet (0.3, ·, 0) and (2.7, ·, 0), crown
    (1.5, ·, 0.3): R = 2.55 m, centre (1.5, ·, −2.25)

BOUNDARY CONDITIONS: frame lowered by dz = −0.15 m (half the rise) in 5 steps, dx = dy = 0.

PARAMETERS: E = 1 GPa, ν = 0.43, t = 250 µm, σ0 = 0.5 MPa, k_n = 2.5e8 N/m, k_s = 2.5e7 N/m,
μ = 0.2 (the specimen's values, src/specimens/parallel_arch.rs).
"""

from __future__ import annotations

import csv
import json
import os
import re
import subprocess
import sys
import warnings

import meshio
import numpy as np
import pytest
from conftest import CLI, INSTALLED, ROOT, pack, package_env
from fmu_helpers import OK, Slave

try:
    import membrane_contact.mesh  # noqa: F401  (installed package)
except ImportError:
    sys.path.insert(0, str(ROOT / "python"))
from membrane_contact.arches import ArchError, gaps_on_curve, make_curve  # noqa: E402
from membrane_contact.mesh import MeshImportError, MeshImportWarning, import_mesh  # noqa: E402

EXAMPLE = ROOT / "examples" / "film_over_two_arches"
MSH22 = EXAMPLE / "film_over_two_arches_v22.msh"
MSH41 = EXAMPLE / "film_over_two_arches_v41_bin.msh"
MAPPING = EXAMPLE / "mapping.json"

CENTRE_XZ, RADIUS = np.array([1.5, -2.25]), 2.55
ARCH_Y = {"S": 0.6, "N": 1.4}
TARGET_DZ, STEPS = -0.15, 5
# Tight Newton tolerances for every run through the solver, so that the balance below is checked
# against a bound derived from them (RESIDUAL_TOLERANCE) rather than against a fitted number.
RESIDUAL_TOLERANCE = 1e-10
TIGHT = {"solver.residualTolerance": RESIDUAL_TOLERANCE, "solver.displacementTolerance": RESIDUAL_TOLERANCE}
TIGHT_CLI = ["--residual-tolerance", str(RESIDUAL_TOLERANCE), "--displacement-tolerance", str(RESIDUAL_TOLERANCE)]


def mapping() -> dict:
    return json.loads(MAPPING.read_text())


@pytest.fixture(scope="module")
def model() -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("error", MeshImportWarning)  # every group of the example is mapped
        return import_mesh(MSH22, MAPPING)


@pytest.fixture(scope="module")
def model_file(model, tmp_path_factory):
    path = tmp_path_factory.mktemp("imported") / "film_over_two_arches.json"
    path.write_text(json.dumps(model, indent=1))
    return path


def frame_of(gap) -> np.ndarray:
    f = gap["frame"]
    return np.array([f["x"], f["y"], f["z"]])


# --------------------------------------------------------------------------- the import itself


def test_sizes_are_small():
    for f in (MSH22, MSH41):
        assert f.stat().st_size < 100_000, f


def test_gmsh_22_ascii_and_41_binary_give_the_same_model(model):
    other = import_mesh(MSH41, MAPPING)
    assert other["triangles"] == model["triangles"]
    np.testing.assert_allclose(other["nodes"], model["nodes"], rtol=0, atol=1e-12)
    assert [(g["name"], g["film_node"]) for g in other["gaps"]] == [(g["name"], g["film_node"]) for g in model["gaps"]]
    for a, b in zip(other["gaps"], model["gaps"]):
        np.testing.assert_allclose(frame_of(a), frame_of(b), atol=1e-12)
        assert a["initial_gap"] == pytest.approx(b["initial_gap"], abs=1e-12)
    strip = lambda m: {k: v for k, v in m.items() if k not in ("nodes", "gaps")}  # noqa: E731
    assert strip(other) == strip(model)


def test_model_contents(model):
    nodes = np.array(model["nodes"])
    assert len(model["triangles"]) == 380
    # compact numbering: every node belongs to a triangle
    assert set(np.unique(model["triangles"])) == set(range(len(nodes)))
    (frame,) = model["groups"]
    assert frame["name"] == "frame" and frame["target"] == [0.0, 0.0, TARGET_DZ]
    on_edge = (np.isclose(nodes[:, 0], 0) | np.isclose(nodes[:, 0], 3)
               | np.isclose(nodes[:, 1], 0) | np.isclose(nodes[:, 1], 2))
    assert sorted(frame["nodes"]) == sorted(np.nonzero(on_edge)[0].tolist())
    (centre,) = model["outputs"]["points"]
    np.testing.assert_allclose(nodes[centre["node"]], [1.5, 1.0, 0.3])
    assert model["outputs"]["element_sets"] == [{"name": "sheet", "elements": "all"}]
    assert [g["name"] for g in model["gaps"]] == [f"S{i}" for i in range(1, 14)] + [f"N{i}" for i in range(1, 14)]


def test_frames_are_orthonormal_right_handed_and_follow_the_arch(model):
    nodes = np.array(model["nodes"])
    for gap in model["gaps"]:
        f = frame_of(gap)
        assert np.abs(f @ f.T - np.eye(3)).max() < 1e-9, gap["name"]
        assert np.linalg.norm(np.cross(f[2], f[0]) - f[1]) < 1e-9, gap["name"]  # y = z × x
        assert np.linalg.det(f) == pytest.approx(1.0, abs=1e-9)
        a = nodes[gap["film_node"]]
        radial = np.array([a[0] - CENTRE_XZ[0], 0.0, a[2] - CENTRE_XZ[1]])
        np.testing.assert_allclose(f[2], radial / np.linalg.norm(radial), atol=1e-9)  # z from the centre
        np.testing.assert_allclose(f[1], [0, 1, 0], atol=1e-9)  # y: the arch plane's normal
        assert f[0][0] > 0  # x along the arch, from the start (x = 0.3) to the end (x = 2.7)


def test_initial_gaps_are_the_distances_to_the_arches(model):
    nodes = np.array(model["nodes"])
    for gap in model["gaps"]:
        a = nodes[gap["film_node"]]
        assert a[1] == pytest.approx(ARCH_Y[gap["name"][0]], abs=1e-12)
        expected = np.hypot(a[0] - CENTRE_XZ[0], a[2] - CENTRE_XZ[1]) - RADIUS
        assert gap["initial_gap"] == pytest.approx(expected, abs=1e-9), gap["name"]
        p = np.array(gap["support"]["point"])
        assert np.hypot(p[0] - CENTRE_XZ[0], p[2] - CENTRE_XZ[1]) == pytest.approx(RADIUS, abs=1e-9)
        # the value the Rust model checks (docs/model-format.md "Warnings")
        assert frame_of(gap)[2] @ (a - p) == pytest.approx(gap["initial_gap"], abs=1e-12)
    by_name = {g["name"]: g for g in model["gaps"]}
    for prefix in "SN":
        xs = [nodes[by_name[f"{prefix}{i}"]["film_node"]][0] for i in range(1, 14)]
        assert xs == sorted(xs) and xs[0] == pytest.approx(0.3) and xs[-1] == pytest.approx(2.7)
        assert by_name[f"{prefix}7"]["initial_gap"] == pytest.approx(0.0, abs=1e-12)  # crown touches
        assert by_name[f"{prefix}1"]["initial_gap"] == pytest.approx(np.hypot(1.2, 2.55) - 2.55, abs=1e-12)


def test_a_distance_band_selects_the_same_nodes(model):
    m = mapping()
    groups = m["physical_groups"]
    m["arches"] = []
    for group in ("arch_south", "arch_north"):
        entry = groups[group]
        groups[group] = {"role": "ignore"}
        m["arches"].append({"name": group, "curve": entry["curve"], "prefix": entry["prefix"],
                            "max_gap": 0.3, "plane_tolerance": 1e-6})
    banded = import_mesh(MSH22, m)
    assert banded["gaps"] == model["gaps"]
    # a narrower band keeps only the nodes near the crown
    m["arches"][0]["max_gap"] = 0.05
    narrow = [g for g in import_mesh(MSH22, m)["gaps"] if g["name"].startswith("S")]
    assert 0 < len(narrow) < 13 and all(g["initial_gap"] <= 0.05 for g in narrow)


def sampled_distance(samples: np.ndarray, q: np.ndarray) -> float:
    return float(np.min(np.linalg.norm(samples - q, axis=1)))


@pytest.mark.parametrize("kind", ["parabola", "polyline", "circle_by_centre"])
def test_curves_against_densely_sampled_ones(kind):
    """Closest points of the parabola and polyline (and the circle given by centre, radius and
    axis) against 10⁵ samples of the curve, for random film nodes above an arch in y = 0.6."""
    s = np.linspace(-1.2, 1.2, 100_001)
    if kind == "parabola":
        spec = {"type": "parabola", "apex": [1.5, 0.6, 0.3], "up": [0, 0, 1], "along": [1, 0, 0],
                "half_span": 1.2, "rise": 0.3}
        samples = np.column_stack([1.5 + s, np.full_like(s, 0.6), 0.3 - 0.3 / 1.44 * s**2])
    elif kind == "polyline":
        pts = [[0.3, 0.6, 0.0], [0.9, 0.6, 0.22], [1.5, 0.6, 0.3], [2.1, 0.6, 0.22], [2.7, 0.6, 0.0]]
        spec = {"type": "polyline", "points": pts}
        t = np.linspace(0, 1, 25_001)[:, None]
        samples = np.vstack([np.array(a) + t * (np.array(b) - np.array(a)) for a, b in zip(pts, pts[1:])])
    else:
        spec = {"type": "circle", "centre": [1.5, 0.6, -2.25], "radius": 2.55, "axis": [0, 1, 0],
                "start": [0.3, 0.6, 0.0], "end": [2.7, 0.6, 0.0]}
        half = np.arcsin(1.2 / 2.55)
        phi = np.linspace(-half, half, 100_001)
        samples = np.column_stack([1.5 + 2.55 * np.sin(phi), np.full_like(phi, 0.6), -2.25 + 2.55 * np.cos(phi)])
    rng = np.random.default_rng(9)
    nodes = np.column_stack([rng.uniform(0.45, 2.55, 60), rng.uniform(0.5, 0.7, 60), rng.uniform(0.31, 0.9, 60)])
    curve = make_curve(spec, kind)
    gaps = gaps_on_curve(curve, nodes, range(len(nodes)))
    assert len(gaps) == len(nodes)
    spacing = np.max(np.linalg.norm(np.diff(samples, axis=0), axis=1))
    for g in gaps:
        a = nodes[g.film_node]
        q = np.array([a[0], 0.6, a[2]])
        assert g.initial_gap == pytest.approx(sampled_distance(samples, q), abs=spacing**2 + 1e-12)
        f = g.frame
        assert np.abs(f @ f.T - np.eye(3)).max() < 1e-9 and np.linalg.det(f) > 0
        assert f[2] @ (a - g.support_point) == pytest.approx(g.initial_gap, abs=1e-12)
        assert f[2][2] > 0 and abs(f[1][1]) == pytest.approx(1.0)  # outward (up), y the plane normal
    assert [g.parameter for g in gaps] == sorted(g.parameter for g in gaps)


def test_a_polyline_vertex_turns_the_frame_like_a_rounded_corner():
    curve = make_curve({"type": "polyline", "points": [[0, 0, 0], [1, 0, 1], [2, 0, 0]]}, "roof")
    nodes = np.array([[1.0, 0.0, 1.5], [1.1, 0.0, 1.5]])
    apex, beside = gaps_on_curve(curve, nodes, [0, 1])
    np.testing.assert_allclose(apex.frame[2], [0, 0, 1], atol=1e-12)  # bisector above the ridge
    assert apex.initial_gap == pytest.approx(0.5)
    z = np.array([0.1, 0.0, 0.5]) / np.hypot(0.1, 0.5)  # from the ridge towards the node
    np.testing.assert_allclose(beside.frame[2], z, atol=1e-12)
    assert beside.initial_gap == pytest.approx(np.hypot(0.1, 0.5))


def test_a_circle_through_three_points_is_the_circle_by_centre_and_radius(model):
    m = mapping()
    north = m["physical_groups"]["arch_north"]
    north["curve"] = {"type": "circle", "points": [[0.3, 1.4, 0.0], [1.5, 1.4, 0.3], [2.7, 1.4, 0.0]]}
    same = import_mesh(MSH22, m)
    for a, b in zip(same["gaps"], model["gaps"]):
        np.testing.assert_allclose(frame_of(a), frame_of(b), atol=1e-12)
        assert a["initial_gap"] == pytest.approx(b["initial_gap"], abs=1e-12)


# --------------------------------------------------------------------------- small meshes


def write_msh(path, points, blocks, names, file_format="gmsh22", binary=False):
    """A gmsh file written by meshio: ``blocks`` = [(cell type, connectivity, physical tag)],
    ``names`` = {name: (tag, dim)}."""
    mesh = meshio.Mesh(
        np.asarray(points, dtype=float),
        [(kind, np.asarray(conn, dtype=int)) for kind, conn, _ in blocks],
        cell_data={"gmsh:physical": [np.full(len(conn), tag) for _, conn, tag in blocks],
                   "gmsh:geometrical": [np.full(len(conn), tag) for _, conn, tag in blocks]},
        field_data={name: np.array(td) for name, td in names.items()},
    )
    if file_format == "gmsh":
        # 4.1 needs each node's entity (dim, tag): the lowest-dimensional block holding it
        dim_tags = np.full((len(points), 2), 99, dtype=int)
        for kind, conn, tag in blocks:
            dim = {"vertex": 0, "line": 1}.get(kind, 2)
            for v in np.unique(conn):
                if dim < dim_tags[v, 0]:
                    dim_tags[v] = (dim, tag)
        mesh.point_data["gmsh:dim_tags"] = dim_tags
    meshio.write(str(path), mesh, file_format=file_format, binary=binary)
    return path


def square(n=4, quads=False):
    """A 1 m × 1 m flat film at z = 0 on an n × n grid: node (i, j) = j (n + 1) + i.

    Physical groups: film (surface, tag 1), left (x = 0, tag 2), bottom (y = 0, tag 3),
    top (y = 1, tag 4), corner (point (1, 1), tag 5)."""
    pts = [[i / n, j / n, 0.0] for j in range(n + 1) for i in range(n + 1)]
    nid = lambda i, j: j * (n + 1) + i  # noqa: E731
    cells = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1)
            cells += [[a, b, c, d]] if quads else [[a, b, c], [a, c, d]]
    blocks = [("quad" if quads else "triangle", cells, 1),
              ("line", [[nid(0, j), nid(0, j + 1)] for j in range(n)], 2),
              ("line", [[nid(i, 0), nid(i + 1, 0)] for i in range(n)], 3),
              ("line", [[nid(i, n), nid(i + 1, n)] for i in range(n)], 4),
              ("vertex", [[nid(n, n)]], 5)]
    names = {"film": (1, 2), "left": (2, 1), "bottom": (3, 1), "top": (4, 1), "corner": (5, 0)}
    return pts, blocks, names


MATERIAL = {"youngs_modulus": 1.0e9, "poisson_ratio": 0.43, "thickness": 250e-6, "prestress": [0.5e6, 0.5e6, 0.0]}
# The paper's linear film, for the small squares that are run: their free edges go into compression
# under the wind, where the tension-field film (the default of a file without the entry, issue 19)
# has no unique equilibrium across the wrinkles, and both are refused with it (measured: the wind
# square stalls at 5.2e-4 N against 9.4e-5 N, the closed cable loop with elements switching between
# taut and wrinkled); they converge with the linear film, as before the default changed.
LINEAR = {**MATERIAL, "wrinkling": "none"}


def small_mapping(material=MATERIAL, **groups) -> dict:
    return {"name": "Small", "material": material, "physical_groups": groups}


@pytest.fixture()
def small_mesh(tmp_path):
    return write_msh(tmp_path / "square.msh", *square())


def test_meshio_written_gmsh41_binary_with_a_cable_and_supports_runs(tmp_path):
    path = write_msh(tmp_path / "square41.msh", *square(), file_format="gmsh", binary=True)
    m = small_mapping(
        LINEAR,
        film={"role": "pressure", "name": "wind", "pressure": 50.0},
        left={"role": "support", "set": "held"},
        bottom={"role": "support", "fixed": ["y", "z"], "set": "held"},
        top={"role": "cable", "name": "edge", "area": 1e-5, "youngs_modulus": 1.6e11, "prestress_force": 100.0},
        corner={"role": "boundary", "target": [0.0, 0.0, 0.01], "components": ["z"]},
    )
    model = import_mesh(path, m)
    (cable,) = model["cables"]
    nodes = np.array(model["nodes"])
    assert np.allclose(nodes[cable["nodes"], 1], 1.0) and np.all(np.diff(nodes[cable["nodes"], 0]) > 0)
    by_node = {s["node"]: s for s in model["supports"]}
    origin = int(np.nonzero((nodes[:, 0] == 0) & (nodes[:, 1] == 0))[0][0])
    assert by_node[origin]["fixed"] == ["x", "y", "z"] and by_node[origin]["name"] == "held"  # merged corner
    assert model["loads"]["pressures"] == [{"name": "wind", "elements": "all", "pressure": 50.0}]
    path = tmp_path / "small.json"
    path.write_text(json.dumps(model))
    run = subprocess.run([str(CLI), "model", str(path), "--steps", "2", "--quiet"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "cable edge" in run.stdout and "held" in run.stdout


def test_other_formats_map_cell_sets_and_point_sets(tmp_path):
    """An Abaqus .inp (meshio writes element and node sets): groups from cell_sets/point_sets."""
    pts, blocks, _ = square()
    triangles = np.array(blocks[0][1])
    left = [j * 5 for j in range(5)]
    mesh = meshio.Mesh(np.array(pts), [("triangle", triangles)], cell_sets={"skin": [np.arange(8)]},
                       point_sets={"left": np.array(left), "corner": np.array([24])})
    path = tmp_path / "square.inp"
    meshio.write(str(path), mesh)
    model = import_mesh(path, small_mapping(skin={"role": "pressure", "pressure": 5.0}, left={"role": "support"},
                                            corner={"role": "output_point"}))
    assert model["loads"]["pressures"] == [{"name": "skin", "elements": list(range(8)), "pressure": 5.0}]
    assert [s["node"] for s in model["supports"]] == left
    assert model["outputs"]["points"] == [{"name": "corner", "node": 24}]


def test_a_closed_line_loop_becomes_a_closed_cable(tmp_path):
    pts, blocks, names = square()
    n, nid = 4, lambda i, j: j * 5 + i
    loop = ([[nid(i, 0), nid(i + 1, 0)] for i in range(n)] + [[nid(n, j), nid(n, j + 1)] for j in range(n)]
            + [[nid(i + 1, n), nid(i, n)] for i in range(n)] + [[nid(0, j + 1), nid(0, j)] for j in range(n)])
    blocks.append(("line", loop[5:] + loop[:5], 6))  # element order need not follow the loop
    names["rim"] = (6, 1)
    path = write_msh(tmp_path / "loop.msh", pts, blocks, names)
    model = import_mesh(path, small_mapping(
        LINEAR,
        film={"role": "pressure", "name": "inflation", "pressure": 10.0},
        rim={"role": "cable", "area": 1e-5, "youngs_modulus": 1.6e11, "prestress_force": 50.0},
        left={"role": "support"}, bottom={"role": "support", "fixed": ["z"]}, top={"role": "support", "fixed": ["z"]},
        corner={"role": "ignore"}))
    chain = model["cables"][0]["nodes"]
    assert len(chain) == 17 and chain[0] == chain[-1] and len(set(chain)) == 16
    path = tmp_path / "loop.json"
    path.write_text(json.dumps(model))
    # One increment per step: with the default ten (the FMU's, issue 17) the first step stalls on
    # this slack square (corrections along a direction with almost no stiffness), whatever the
    # number of steps (2, 4, 10 measured); one increment gets through with 6 cut-backs.
    run = subprocess.run([str(CLI), "model", str(path), "--steps", "2", "--increments", "1", "--quiet"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr


def test_quads_are_refused_by_name_or_split_with_a_warning(tmp_path):
    path = write_msh(tmp_path / "quads.msh", *square(quads=True))
    m = small_mapping(left={"role": "boundary"}, bottom={"role": "ignore"}, top={"role": "ignore"},
                      corner={"role": "ignore"}, film={"role": "element_set", "name": "skin"})
    with pytest.raises(MeshImportError, match=r"16 quad cells \(physical group film\).*\"quads\": \"split\""):
        import_mesh(path, m)
    m["quads"] = "split"
    with pytest.warns(MeshImportWarning, match="16 quad cells split into two triangles"):
        model = import_mesh(path, m)
    assert len(model["triangles"]) == 32


def test_second_order_triangles_are_refused_by_name(tmp_path):
    pts = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.5, 0, 0], [0.5, 0.5, 0], [0, 0.5, 0]]
    path = write_msh(tmp_path / "t6.msh", pts, [("triangle6", [[0, 1, 2, 3, 4, 5]], 1)], {"skin": (1, 2)})
    with pytest.raises(MeshImportError, match=r"1 triangle6 cells \(physical group skin\)"):
        import_mesh(path, small_mapping(skin={"role": "element_set"}))


def error_cases():
    """(id, mapping edit on the example, expected message regex)."""

    def edit(groups=None, top=None):
        def apply(m):
            m["physical_groups"].update(groups or {})
            m.update(top or {})
            return m
        return apply

    def shifted_north_arch(m):
        m["physical_groups"]["arch_north"]["curve"]["centre"] = [1.5, 1.4, -2.24]  # crown 1 cm above the film
        return m

    def short_south_arch(m):
        m["physical_groups"]["arch_south"]["curve"]["points"] = [[0.5, 0.6, 0.0], [1.5, 0.6, 0.3], [2.5, 0.6, 0.0]]
        return m

    def both_arches_on_north(m):
        m["arches"] = [{"name": "extra", "curve": m["physical_groups"]["arch_north"]["curve"], "max_gap": 0.1,
                        "plane_tolerance": 1e-6, "prefix": "X"}]
        return m

    def no_stiffness(m):
        del m["gap_defaults"]["normal_stiffness"]
        return m

    return [
        ("unknown group", edit({"arch_west": {"role": "ignore"}}), r"physical group 'arch_west', which the mesh"),
        ("unknown role", edit({"frame": {"role": "clamp"}}), r"physical group 'frame'.*unknown role 'clamp'"),
        ("unknown key", edit({"frame": {"role": "boundary", "traget": [0, 0, 1]}}), r"'frame'.*unknown key\(s\) 'traget'"),
        ("unknown default", edit(top={"gap_defaults": {"friciton": 0.2}}), r"'gap_defaults': unknown key\(s\) 'friciton'"),
        ("unknown top key", edit(top={"materail": {}}), r"mapping: unknown key\(s\) 'materail'"),
        ("point of many nodes", edit({"frame": {"role": "output_point"}}), r"physical group 'frame'.*has 50 nodes"),
        ("reserved name", edit({"film": {"role": "element_set"}}), r"element set 'film': the name is reserved"),
        ("no triangles", edit({"frame": {"role": "element_set"}}), r"physical group 'frame'.*has no film triangles"),
        ("film inside", shifted_north_arch, r"arch 'arch_north': film node \d+ at \(\S+, 1\.4, 0\.3\) lies \S+ m inside the support"),
        ("beyond the end", short_south_arch, r"arch 'arch_south': film node \d+ at \(\S+, 0\.6, 0\.3\) lies beyond the (start|end)"),
        ("two gaps on a node", both_arches_on_north, r"node \d+ at \(\S+, 1\.4, 0\.3\) gets a gap from arch 'arch_north' and from arch 'extra'"),
        ("missing stiffness", no_stiffness, r"'arch_south'.*'normal_stiffness' missing"),
        ("bad curve", edit({"arch_south": {"role": "gaps", "curve": {"type": "spline"}}}), r"curve of 'arch_south': type 'spline'"),
        ("bad name", edit(top={"name": "film over arches"}), r"mapping 'name'.*'film over arches' is not an identifier"),
        ("name twice", edit({"centre": {"role": "output_point", "name": "S1"}}), r"name 'S1' is used twice: by the gap 'S1' and by the output point 'S1'"),
        ("support and group", edit({"film": [{"role": "element_set"}, {"role": "support", "fixed": ["z"]}]}),
         r"node \d+ at \(.*\) is prescribed in z by boundary group 'frame' and also fixed in z by support group 'film'"),
    ]


@pytest.mark.parametrize("case", error_cases(), ids=lambda c: c[0])
def test_errors_name_the_bad_item(case):
    _, apply, pattern = case
    with pytest.raises((MeshImportError, ArchError), match=pattern):
        import_mesh(MSH22, apply(mapping()))


def test_errors_on_small_meshes_name_the_bad_item(tmp_path, small_mesh):
    base = dict(film={"role": "element_set", "name": "skin"}, bottom={"role": "ignore"}, top={"role": "ignore"}, corner={"role": "ignore"})
    # a node in two boundary groups: the corner (0, 0) of left and bottom
    with pytest.raises(MeshImportError, match=r"node \d+ at \(0, 0, 0\) is in boundary groups '(left' and 'bottom|bottom' and 'left)'"):
        import_mesh(small_mesh, small_mapping(**{**base, "left": {"role": "boundary"}, "bottom": {"role": "boundary"}}))
    # a group name that is not an identifier
    pts, blocks, names = square()
    names["left edge"] = names.pop("left")
    path = write_msh(tmp_path / "named.msh", pts, blocks, names)
    with pytest.raises(MeshImportError, match=r"physical group 'left edge' \(role boundary\): name 'left edge' is not"):
        import_mesh(path, small_mapping(**{**base, "left edge": {"role": "boundary"}}))
    # a physical group without elements in the file
    names = {**square()[2], "ghost": (9, 1)}
    path = write_msh(tmp_path / "ghost.msh", pts, blocks, names)
    with pytest.raises(MeshImportError, match=r"physical group 'ghost' \(role support\): the group has no nodes"):
        import_mesh(path, small_mapping(**{**base, "left": {"role": "boundary"}, "ghost": {"role": "support"}}))
    # physical groups with tags only: the mapping cannot name them, and the message says why
    path = write_msh(tmp_path / "unnamed.msh", pts, blocks, {})
    with pytest.raises(MeshImportError, match=r"'left', which the mesh .*its groups: none.*tag 2 \(dimension 1\)"):
        import_mesh(path, small_mapping(left={"role": "boundary"}))
    # an unmapped group is reported, not dropped silently
    with pytest.warns(MeshImportWarning, match="physical group 'left' is not in the mapping"):
        import_mesh(small_mesh, small_mapping(**base))


def test_reserved_names_are_those_of_the_rust_side():
    from membrane_contact.mesh import RESERVED_NAMES

    rust = (ROOT / "src" / "fmi2" / "variables.rs").read_text()
    block = re.search(r"pub const RESERVED_NAMES: \[&str; \d+\] = \[(.*?)\];", rust, re.S)[1]
    assert tuple(re.findall(r'"(\w+)"', block)) == RESERVED_NAMES


def test_an_unreadable_mesh_is_an_error_not_an_exit(tmp_path, capsys):
    bad = tmp_path / "broken.msh"
    bad.write_bytes(MSH22.read_bytes()[:3000])  # cut inside $Nodes
    with pytest.raises(MeshImportError, match=r"mesh file .*broken\.msh: meshio cannot read it"):
        import_mesh(bad, MAPPING)
    with pytest.raises(MeshImportError, match=r"mesh file .*nowhere\.msh: no such file"):
        import_mesh(tmp_path / "nowhere.msh", MAPPING)
    assert capsys.readouterr().out == ""


def test_command_line(tmp_path):
    out = tmp_path / "model.json"
    env = package_env()
    run = subprocess.run([sys.executable, "-m", "membrane_contact.mesh", str(MSH41), str(MAPPING), "-o", str(out)],
                         capture_output=True, text=True, cwd=tmp_path, env=env)
    assert run.returncode == 0, run.stderr
    assert "26 gaps (S1 … N13)" in run.stderr
    assert json.loads(out.read_text())["name"] == "FilmOverTwoArches"
    to_stdout = subprocess.run([sys.executable, "-m", "membrane_contact.mesh", str(MSH41), str(MAPPING), "-q"],
                               capture_output=True, text=True, cwd=tmp_path, env=env)
    assert to_stdout.stdout.startswith("{") and json.loads(to_stdout.stdout) == json.loads(out.read_text())
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({**mapping(), "physical_groups": {"arch_west": {"role": "ignore"}}}))
    run = subprocess.run([sys.executable, "-m", "membrane_contact.mesh", str(MSH22), str(bad)],
                         capture_output=True, text=True, cwd=tmp_path, env=env)
    assert run.returncode == 1 and run.stderr.startswith("error: mapping names physical group 'arch_west'")


# --------------------------------------------------------------------------- through the solver


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    last = max(int(r["step"]) for r in rows)
    return rows, {r["gap"]: r for r in rows if int(r["step"]) == last}


@pytest.fixture(scope="module")
def cli_run(model_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("cli") / "gaps.csv"
    run = subprocess.run([str(CLI), "model", str(model_file), "--steps", str(STEPS), "--csv", str(out), "--quiet",
                          *TIGHT_CLI], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return run, *read_csv(out)


def test_the_imported_model_runs_in_the_cli(model, cli_run):
    run, _, final = cli_run
    assert "warning" not in run.stderr, run.stderr  # in particular no initial_gap ≠ z·(A − P) warning
    uz = float(re.search(r"output point centre \(node \d+\): displacement \(\S+, \S+, (\S+)\) m", run.stdout)[1])
    assert -0.05 < uz < -0.005, "the film's centre goes down with the frame"
    for prefix in "SN":
        crown, foot_a, foot_b = final[f"{prefix}7"], final[f"{prefix}1"], final[f"{prefix}13"]
        assert crown["status"] != "Open" and float(crown["normal_force_N"]) > 100.0, "the crown gap closes"
        assert foot_a["status"] == "Open" == foot_b["status"], "the feet stay open at this target"
        # Symmetric about the crown: slips outward, equal and opposite. Not exactly: the gmsh
        # mesh is not a mirror image of itself about x = 1.5 (its nodes lie up to 0.11 m from
        # the mirror images of others), and that asymmetry of the discretisation is the whole
        # error covered here. Measured: pairs differ by 0.003 … 0.154 mm, the largest at N6/N8
        # (1.57 vs 1.72 mm, 9 %), the relative ones below 1.2 % from the 5.7 mm slips of the
        # fifth pair outward. The band is 5 % or 0.2 mm, whichever is larger.
        for i in range(1, 7):
            a, b = float(final[f"{prefix}{i}"]["slip_x_mm"]), float(final[f"{prefix}{14 - i}"]["slip_x_mm"])
            assert a < 0 < b and a == pytest.approx(-b, rel=0.05, abs=0.2), (prefix, i)
    # The frame pushes the film down onto the arches. The exact balance of the frame's reaction
    # with the gap forces needs the friction components, which the CLI does not print: it is
    # checked from the FMU's outputs in the next test, whose steps equal these.
    rz = float(re.search(r"reaction of group frame: \(\S+, \S+, (\S+)\) N", run.stdout)[1])
    assert rz < -1000.0


@pytest.fixture(scope="module")
def fmu(model_file, tmp_path_factory):
    path = pack(model_file, tmp_path_factory.mktemp("fmu"))
    assert path.name == "FilmOverTwoArches.fmu"
    return path


def test_an_fmu_of_the_imported_model_steps_like_the_cli(model, fmu, cli_run):
    _, rows, _ = cli_run
    names = [g["name"] for g in model["gaps"]]
    with Slave(fmu) as s:
        assert {"frame.dz", "S7.slip", "N13.normalForce", "centre.uz", "film.maxEquivalentStress"} <= set(s.variables)
        s.initialize(parameters=TIGHT)
        for k in range(STEPS):
            s.ramp({"frame.dz": TARGET_DZ}, STEPS, first=k, last=k + 1)
            assert s.get("solver.iterations") > 0
            for g in names:
                row = next(r for r in rows if int(r["step"]) == k + 1 and r["gap"] == g)
                assert s.get(f"{g}.slip") * 1e3 == pytest.approx(float(row["slip_x_mm"]), abs=2e-6), (k, g)
                assert s.get(f"{g}.normalForce") == pytest.approx(float(row["normal_force_N"]), abs=2e-6), (k, g)
        assert s.get("centre.uz") < -0.005
        # Exact balance from the FMU's outputs: the film is held in all three directions by the
        # frame only and loaded by the gaps only, so frame reaction + Σ (N z + T_x x + T_y y) is
        # the sum of the out-of-balance forces of the free nodes. Newton stops with each of
        # them below RESIDUAL_TOLERANCE · F_ref, F_ref the largest nodal force (SolverSettings),
        # here no larger than the largest of |R| and the gap forces, so the sum is below
        # √3 · (free nodes) · RESIDUAL_TOLERANCE · F_ref.
        reaction = np.array(s.get("frame.Rx", "frame.Ry", "frame.Rz"))
        total, largest = reaction.copy(), np.linalg.norm(reaction)
        for g in model["gaps"]:
            f = frame_of(g)
            n, tx, ty = s.get(f"{g['name']}.normalForce", f"{g['name']}.frictionX", f"{g['name']}.frictionY")
            force = n * f[2] + tx * f[0] + ty * f[1]
            total += force
            largest = max(largest, np.linalg.norm(force))
        free = len(model["nodes"]) - len(model["groups"][0]["nodes"])
        assert len(model["groups"]) == 1 and not model["supports"] and not model["symmetry"]
        bound = np.sqrt(3) * free * RESIDUAL_TOLERANCE * largest
        assert np.linalg.norm(total) <= bound, (total, bound)
        assert s.get("reactions.Rz") == pytest.approx(reaction[2], rel=1e-12)
        status = s.step(1.0, 0.2)  # one more step at the same target: nothing moves
        assert status == OK


def test_mesh_to_fmu_to_the_python_package_with_a_staged_path_and_a_rollback(model, fmu, cli_run):
    """Issue 9's end-to-end path: the gmsh mesh imported with its arch gaps (``model``), packed
    (``fmu``), driven by ``membrane_contact.Film`` through a staged table (down, a pause, the
    friction raised) with a rollback to the mid-point that replays the second half exactly; the
    first half lands on the CLI's steps."""
    from membrane_contact import Film

    _, rows, _ = cli_run
    times = [(k + 1) / STEPS for k in range(STEPS)]
    with Film(fmu) as film:
        film.initialize(parameters=TIGHT)
        first = film.run({"time": times, "frame.dz": [TARGET_DZ * t for t in times]})
        for k in range(STEPS):
            row = next(r for r in rows if int(r["step"]) == k + 1 and r["gap"] == "S5")
            assert first["S5.slip"][k + 1] * 1e3 == pytest.approx(float(row["slip_x_mm"]), abs=2e-6)
        state = film.save()
        second_table = {"time": [1.5, 2.0], "frame.dz": [TARGET_DZ, TARGET_DZ * 1.2], "mu": [0.4, 0.4]}
        second = film.run(second_table)
        film.restore(state)
        assert film.time == 1.0 and film["S5.slip"] == first["S5.slip"][-1]
        replay = film.run(second_table)
        for name in ("S5.slip", "N7.normalForce", "frame.Rz", "centre.uz"):
            np.testing.assert_array_equal(replay[name], second[name])
        names, slips = replay.slips()
        assert names[:13] == [f"S{i}" for i in range(1, 14)] and slips.shape == (3, 26)


def test_the_cli_import_command_runs_the_same_importer(model, tmp_path):
    """``membrane-contact import MESH MAPPING -o FILE`` writes the model import_mesh gives; a bad
    mapping fails with the importer's message naming it."""
    out = tmp_path / "model.json"
    run = subprocess.run([str(CLI), "import", str(MSH22), str(MAPPING), "-o", str(out), "--python", sys.executable],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert json.loads(out.read_text()) == json.loads(json.dumps(model))
    run = subprocess.run([str(CLI), "import", str(MSH22), str(tmp_path / "none.json"), "--python", sys.executable],
                         capture_output=True, text=True)
    assert run.returncode == 1 and "none.json" in run.stderr and "the import failed" in run.stderr


def test_the_cli_import_command_runs_the_package_under_test(tmp_path):
    """The checkout's build puts the checkout's python/ ahead on the importer's PYTHONPATH; the
    program installed from the wheel (MEMBRANE_CONTACT_INSTALLED=1) does not, so that the
    interpreter's package, the wheel's, runs even when the checkout it was built from exists."""
    seen, python = tmp_path / "pythonpath", tmp_path / "python"
    python.write_text(f'#!/bin/sh\nprintf "%s" "$PYTHONPATH" > "{seen}"\n')
    python.chmod(0o755)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    run = subprocess.run([str(CLI), "import", str(MSH22), str(MAPPING), "-o", str(tmp_path / "m.json"),
                          "--python", str(python)], capture_output=True, text=True, env=env)
    assert run.returncode == 0, run.stderr
    paths = seen.read_text().split(os.pathsep)
    assert (str(ROOT / "python") in paths) == (not INSTALLED), paths


def test_the_importer_imports_and_runs_without_fmpy(tmp_path):
    """python/README-import.md: the importer needs numpy and meshio, not fmpy (issue 47 item 8)."""
    code = ("import sys; sys.modules['fmpy'] = None  # any import of fmpy fails\n"
            "from membrane_contact.mesh import main\n"
            f"sys.exit(main([{str(MSH22)!r}, {str(MAPPING)!r}, '-o', {str(tmp_path / 'm.json')!r}, '-q']))\n")
    r = subprocess.run([sys.executable, "-c", code], env=package_env(), capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert json.loads((tmp_path / "m.json").read_text())["triangles"]


def test_a_wrong_membrane_contact_cli_skips_the_solvers_check_with_a_warning_saying_so(tmp_path, monkeypatch):
    """The docs say the check is skipped without the program; a wrong $MEMBRANE_CONTACT_CLI
    crashed the import with a raw FileNotFoundError (issue 47 item 8)."""
    monkeypatch.setenv("MEMBRANE_CONTACT_CLI", str(tmp_path / "no-such-program"))
    with pytest.warns(MeshImportWarning, match=r"the solver's check is skipped: \$MEMBRANE_CONTACT_CLI = "
                                               r".*no-such-program cannot be run"):
        model = import_mesh(MSH22, MAPPING)
    assert model["triangles"]
    r = subprocess.run([sys.executable, "-m", "membrane_contact.mesh", str(MSH22), str(MAPPING), "-q"],
                       env={**package_env(), "MEMBRANE_CONTACT_CLI": str(tmp_path)}, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "note: the solver's check is skipped" in r.stderr and "Traceback" not in r.stderr


def test_a_pressure_group_of_kind_plan_becomes_a_load_per_plan_area(small_mesh):
    """Issue 47 item 8: the roof's snow as a load per plan area (``"kind": "plan"``) passes
    through the importer; a follower set writes no kind; an unknown kind is refused naming it."""
    from membrane_contact.mesh import MeshImportError

    m = small_mapping(LINEAR, film={"role": "pressure", "name": "snow", "pressure": 960.0, "kind": "plan"},
                      left={"role": "support"}, top={"role": "support"}, bottom={"role": "support"})
    model = import_mesh(small_mesh, m)
    assert model["loads"]["pressures"] == [{"name": "snow", "elements": "all", "pressure": 960.0, "kind": "plan"}]
    m["physical_groups"]["film"]["kind"] = "follower"
    assert "kind" not in import_mesh(small_mesh, m)["loads"]["pressures"][0]
    m["physical_groups"]["film"]["kind"] = "snow"
    with pytest.raises(MeshImportError, match="kind 'snow' is not 'follower' or 'plan'"):
        import_mesh(small_mesh, m)


def test_a_rails_end_points_on_a_symmetry_plane_leave_the_plane_with_a_note(small_mesh):
    """Issue 47 item 8: the vault roof's symmetry planes took in the end points of curves a rail
    already holds, and the user wrote 14 lines to take them out. A node a boundary group
    prescribes along a plane's normal now leaves the plane: where the group holds it at 0 along
    the normal that is the same constraint (said so), else the group moves it off the plane (said
    so); the model runs. A support that fixes what a group prescribes is still refused."""
    from membrane_contact.mesh import MeshImportError, MeshImportWarning

    for target, verdict in ((0.0, "the same constraint"), (0.01, "moves them by 0.01 m along x, off the plane")):
        m = small_mapping(LINEAR, left={"role": "symmetry", "normal": "x"}, bottom={"role": "support"},
                          top={"role": "boundary", "name": "rail", "target": [target, 0.0, -0.01]})
        with pytest.warns(MeshImportWarning, match=verdict) as caught:
            model = import_mesh(small_mesh, m)
        (note,) = [str(w.message) for w in caught if "symmetry plane 'left'" in str(w.message)]
        assert "symmetry plane 'left' (normal x): 1 nodes left out (20)" in note, note
        (plane,) = model["symmetry"]
        assert 20 not in plane["nodes"] and plane["nodes"] == [0, 5, 10, 15], plane
    m = small_mapping(LINEAR, left={"role": "support"}, top={"role": "boundary", "name": "rail"})
    with pytest.raises(MeshImportError, match="also fixed in x by support group 'left'"):
        import_mesh(small_mesh, m)
