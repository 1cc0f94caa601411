"""Tubes from the mesher (issue 17 item 7): a physical curve along a tube's axis plus a tube
radius becomes a curved support whose centreline is fitted to the curve's points.

SOURCE: hand geometry (the two arches of ``examples/film_over_two_arches``, one a circle, one a
parabola, as 60 mm tubes); the model format's curved supports (docs/model-format.md).

TEST GOAL:
* exact points of a circle arc and of a parabolic arch are recognised as such, parameters to
  1e-9 (closed form), residual at rounding; the other shape's residual is far above the
  tolerance; points off both give a polyline through them; a forced shape that does not fit is
  an error naming the residual;
* a gmsh 2.2 mesh written with meshio (a flat film, two centreline curves whose points are not
  film nodes, the film line above one arch) imports to a model with two curved supports (contact
  nodes from the physical group and from a distance band) that the CLI runs;
* approach is not slip: with the frame lowered until the crowns touch but not the feet, the foot
  nodes' curved-support contacts report slip 0 (open, never touched), while the same film nodes
  as fixed-frame gaps report tens of mm of slip along x (the approach travel of the user's
  report);
* a film node inside a tube is refused, named.

MESH: film 3 m × 2 m at z = 0.335 (0.3 m × 0.2 m grid), frame = its four edges (boundary group, dz =
−0.15 m); tube axes in y = 0.6 (circle: feet (0.3, 0), (2.7, 0), crown (1.5, 0.3), R = 2.55 m,
centre z = −2.25) and y = 1.4 (parabola: apex (1.5, 0.3), half span 1.2 m, rise 0.3 m), tube
radius 0.03 m: the crown's tube top is 5 mm below the film.

PARAMETERS: E = 1 GPa, ν = 0.43, t = 250 µm, σ0 = 0.5 MPa, k_n = 2.5e8 N/m, k_s = 2.5e7 N/m,
μ = 0.2.
"""

from __future__ import annotations

import csv
import json
import math
import re
import subprocess
import warnings

import numpy as np
import pytest
from conftest import CLI
from test_import import MATERIAL, write_msh

from membrane_contact.mesh import MeshImportWarning, import_mesh
from membrane_contact.tubes import TubeError, fit_centreline

CENTRE_XZ, R = np.array([1.5, -2.25]), 2.55
APEX_XZ, HALF_SPAN, RISE = np.array([1.5, 0.3]), 1.2, 0.3
Y_S, Y_N, FILM_Z, TUBE = 0.6, 1.4, 0.335, 0.03
CONTACT = {"normal_stiffness": 2.5e8, "tangential_stiffness": 2.5e7, "friction": 0.2}


def circle_points(n=25, y=Y_S):
    a0, a1 = math.atan2(2.25, -1.2), math.atan2(2.25, 1.2)  # foot (0.3, 0) → foot (2.7, 0)
    a = np.linspace(a0, a1, n)
    return np.column_stack([CENTRE_XZ[0] + R * np.cos(a), np.full(n, y), CENTRE_XZ[1] + R * np.sin(a)])


def parabola_points(n=25, y=Y_N):
    s = np.linspace(-HALF_SPAN, HALF_SPAN, n)
    return np.column_stack([APEX_XZ[0] + s, np.full(n, y), APEX_XZ[1] - RISE / HALF_SPAN**2 * s * s])


# --------------------------------------------------------------------------- the fit


def test_exact_circle_points_give_the_circle():
    fit = fit_centreline(circle_points(), 1e-4)
    c = fit.centreline["circle"]
    assert fit.kind == "circle" and fit.residual < 1e-12 and fit.tried["parabola"] > 1e-3
    assert np.allclose(c["centre"], [1.5, Y_S, -2.25], atol=1e-9, rtol=0)
    assert c["radius"] == pytest.approx(R, abs=1e-9)
    # counter-clockwise about the axis from the first foot to the other: axis +y (x → z turns about −y)
    assert np.allclose(c["axis"], [0, 1, 0], atol=1e-12) or np.allclose(c["axis"], [0, -1, 0], atol=1e-12)
    start = np.array(c["start_direction"])
    assert np.allclose(np.array([1.5, Y_S, -2.25]) + R * start, circle_points()[0], atol=1e-9)
    axis, (lo, hi) = np.array(c["axis"]), c["angles"]
    end = math.cos(hi) * start + math.sin(hi) * np.cross(axis, start)
    assert lo == 0.0 and np.allclose(np.array([1.5, Y_S, -2.25]) + R * end, circle_points()[-1], atol=1e-9)
    assert hi == pytest.approx(2 * math.atan2(1.2, 2.25), abs=1e-9)


def test_exact_parabola_points_give_the_parabola_either_way_along():
    for points in (parabola_points(), parabola_points()[::-1]):
        fit = fit_centreline(points, 1e-4)
        p = fit.centreline["parabola"]
        assert fit.kind == "parabola" and fit.residual < 1e-12 and fit.tried["circle"] > 1e-3
        assert np.allclose(p["apex"], [1.5, Y_N, 0.3], atol=1e-9, rtol=0)
        assert np.allclose(p["up"], [0, 0, 1], atol=1e-9)
        assert p["half_span"] == pytest.approx(HALF_SPAN, abs=1e-9)
        assert p["rise"] == pytest.approx(RISE, abs=1e-9)
        # travelled from the first point to the last
        assert np.dot(p["along"], points[-1] - points[0]) > 0


def test_a_tilted_parabola_is_found_by_its_conic_axis():
    """A parabola whose axis is tilted 20° in its plane, spanned symmetrically about its apex."""
    tilt = math.radians(20)
    up, along = np.array([math.sin(tilt), 0, math.cos(tilt)]), np.array([math.cos(tilt), 0, -math.sin(tilt)])
    s = np.linspace(-1.0, 1.0, 21)
    apex = np.array([0.2, 0.5, 1.0])
    pts = apex + np.outer(s, along) - np.outer(0.4 * s * s, up)
    fit = fit_centreline(pts, 1e-6)
    p = fit.centreline["parabola"]
    assert fit.kind == "parabola" and fit.residual < 1e-11
    assert np.allclose(p["up"], up, atol=1e-9) and np.allclose(p["apex"], apex, atol=1e-9)
    assert p["rise"] == pytest.approx(0.4, abs=1e-9) and p["half_span"] == pytest.approx(1.0, abs=1e-9)


def test_points_on_neither_give_a_polyline_and_a_forced_shape_names_the_residual():
    pts = circle_points(13)
    pts[6, 2] += 0.01  # a 10 mm kink at the crown
    fit = fit_centreline(pts, 1e-3)
    assert fit.kind == "polyline" and np.allclose(fit.centreline["polyline"]["points"], pts)
    assert min(fit.tried.values()) > 1e-3
    with pytest.raises(TubeError, match=r"do not lie on a circle within 0.001 m \(residual"):
        fit_centreline(pts, 1e-3, shape="circle", name="kinked")
    bent = circle_points(13)
    bent[3, 1] += 0.01
    with pytest.raises(TubeError, match="'bent'.*do not lie in one plane"):
        fit_centreline(bent, 1e-3, name="bent")
    straight = fit_centreline([[0, 0, 0], [1, 0, 0], [2, 0, 0]], 1e-6)
    assert straight.kind == "polyline" and straight.centreline["polyline"]["normal"] == [0.0, 1.0, 0.0]


# --------------------------------------------------------------------------- the mesh


def film_over_tubes():
    """Points and blocks (write_msh) of the flat film over the two tube axes."""
    nx, ny = 10, 10
    pts = [[3.0 * i / nx, 2.0 * j / ny, FILM_Z] for j in range(ny + 1) for i in range(nx + 1)]
    nid = lambda i, j: j * (nx + 1) + i  # noqa: E731
    tris = []
    for j in range(ny):
        for i in range(nx):
            a, b, c, d = nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1)
            tris += [[a, b, c], [a, c, d]]
    edge = ([[nid(i, 0), nid(i + 1, 0)] for i in range(nx)] + [[nid(i, ny), nid(i + 1, ny)] for i in range(nx)]
            + [[nid(0, j), nid(0, j + 1)] for j in range(ny)] + [[nid(nx, j), nid(nx, j + 1)] for j in range(ny)])
    over_s = [[nid(i, 3), nid(i + 1, 3)] for i in range(1, 9)]  # the film line over arch S: y = 0.6, x = 0.3 … 2.7
    blocks = [("triangle", tris, 1), ("line", edge, 2), ("line", over_s, 5)]
    for tag, curve in ((3, circle_points()), (4, parabola_points())):
        first = len(pts)
        pts += curve.tolist()
        blocks.append(("line", [[first + k, first + k + 1] for k in range(len(curve) - 1)], tag))
    names = {"film": (1, 2), "frame": (2, 1), "tube_s": (3, 1), "tube_n": (4, 1), "over_s": (5, 1)}
    return pts, blocks, names


def tube_mapping(**overrides) -> dict:
    groups = {
        "film": {"role": "element_set", "name": "sheet"},
        "frame": {"role": "boundary", "target": [0.0, 0.0, -0.15]},
        "tube_s": {"role": "curved_support", "name": "archS", "tube_radius": TUBE, "nodes": "over_s"},
        "tube_n": {"role": "curved_support", "name": "archN", "tube_radius": TUBE, "nodes": {"band": 0.35}},
        "over_s": {"role": "ignore"},
    }
    groups.update(overrides)
    return {"name": "FilmOverTubes", "material": MATERIAL, "gap_defaults": CONTACT, "physical_groups": groups}


@pytest.fixture(scope="module")
def mesh_file(tmp_path_factory):
    return write_msh(tmp_path_factory.mktemp("tubes") / "film_over_tubes.msh", *film_over_tubes())


@pytest.fixture(scope="module")
def tube_model(mesh_file):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MeshImportWarning)
        model = import_mesh(mesh_file, tube_mapping())
    return model, [str(w.message) for w in caught]


def test_the_importer_recognises_both_arches_and_reports_the_fit(tube_model):
    model, notes = tube_model
    assert not model["gaps"]
    s, n = model["curved_supports"]
    assert s["name"] == "archS" and list(s["centreline"]) == ["circle"]
    assert n["name"] == "archN" and list(n["centreline"]) == ["parabola"]
    assert np.allclose(s["centreline"]["circle"]["centre"], [1.5, Y_S, -2.25], atol=1e-9)
    assert s["centreline"]["circle"]["radius"] == pytest.approx(R, abs=1e-9)
    p = n["centreline"]["parabola"]
    assert np.allclose(p["apex"], [1.5, Y_N, 0.3], atol=1e-9)
    assert (p["half_span"], p["rise"]) == (pytest.approx(HALF_SPAN, abs=1e-9), pytest.approx(RISE, abs=1e-9))
    assert s["tube_radius"] == TUBE and s["friction"] == 0.2 and s["normal_stiffness"] == 2.5e8
    # the centreline points are not film nodes: the model keeps the film's 176 only
    assert len(model["nodes"]) == 11 * 11
    nodes = np.array(model["nodes"])
    assert np.allclose(nodes[s["nodes"], 1], Y_S) and len(s["nodes"]) == 9  # the physical group's nodes
    # the band: every film node within 0.35 m of the tube surface, and no other
    dense = dense_parabola()
    d = np.array([np.linalg.norm(dense - x, axis=1).min() for x in nodes]) - TUBE
    assert set(n["nodes"]) == set(np.nonzero(d <= 0.35)[0].tolist())
    assert len(n["nodes"]) > 9
    fit_notes = [m for m in notes if "fit residual" in m]
    assert len(fit_notes) == 2 and "curved support 'archS'" in fit_notes[0] and "circle arc" in fit_notes[0]
    residual = float(re.search(r"fit residual (\S+) m", fit_notes[1])[1])
    assert residual < 1e-12


def dense_parabola(n=20001):
    return parabola_points(n)


def run_cli(model: dict, tmp_path, name: str, steps: int = 5, extra=()) -> tuple[str, dict]:
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(model))
    out = tmp_path / f"{name}.csv"
    run = subprocess.run([str(CLI), "model", str(path), "--steps", str(steps), "--csv", str(out), "--quiet", *extra],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    rows = list(csv.DictReader(out.open())) if out.exists() else []
    final = {r["gap"]: r for r in rows if int(r["step"]) == steps}
    return run.stdout, final


def contacts(stdout: str) -> dict:
    """``{node: (slip_mm, travel_mm, normal_N, status)}`` of the CLI's curved-support table."""
    out = {}
    for m in re.finditer(r"^(\w+)\.node(\d+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\w+)$", stdout, re.M):
        out[(m[1], int(m[2]))] = (float(m[3]), float(m[4]), float(m[6]), m[8])
    return out


def test_feet_report_no_slip_before_they_touch_unlike_gaps(tube_model, mesh_file, tmp_path):
    model, _ = tube_model
    stdout, _ = run_cli(model, tmp_path, "tubes", extra=["--report", str(tmp_path / "tubes.md")])
    c = contacts(stdout)
    nodes = np.array(model["nodes"])
    s_nodes = model["curved_supports"][0]["nodes"]
    crown = min(s_nodes, key=lambda v: abs(nodes[v][0] - 1.5))
    feet = [v for v in s_nodes if abs(nodes[v][0] - 1.5) > 0.8]  # x = 0.3, 0.6, 2.4, 2.7: near the feet
    assert len(feet) == 4
    assert c[("archS", crown)][3] != "Open" and c[("archS", crown)][2] > 100.0, "the crown touches its tube"
    for v in feet:
        slip, travel, normal, status = c[("archS", v)]
        assert status == "Open" and normal == 0.0 and slip == 0.0, (v, c[("archS", v)])
    # the same film nodes over the same arch as fixed-frame gaps (the tube's top as the support)
    gap_map = tube_mapping(
        tube_s={"role": "ignore"}, tube_n={"role": "ignore"},
        over_s={"role": "gaps", "prefix": "S", "offset": TUBE,
                "curve": {"type": "circle", "points": [[0.3, Y_S, 0.0], [1.5, Y_S, 0.3], [2.7, Y_S, 0.0]]}})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshImportWarning)
        gap_model = import_mesh(mesh_file, gap_map)
    assert gap_model["nodes"] == model["nodes"]
    _, final = run_cli(gap_model, tmp_path, "gaps", extra=["--report", str(tmp_path / "gaps.md")])
    by_node = {g["film_node"]: final[g["name"]] for g in gap_model["gaps"]}
    for v in feet:
        assert by_node[v]["status"] == "Open"
        # approach travel, reported as slip (measured: 53.5 mm at the feet, 33 mm next to them),
        # which the contact reports as travel along the support, not as slip
        gap_slip, travel = float(by_node[v]["slip_x_mm"]), c[("archS", v)][1]
        assert abs(gap_slip) > 10.0 and abs(travel) > 10.0 and np.sign(gap_slip) == np.sign(travel), (v, by_node[v])
    # the CLI's run reports show the same slips: per gap (as the CSV), per curved-support node
    gap_rows = report_rows(tmp_path / "gaps.md", "### Gaps")
    for g in gap_model["gaps"]:
        row = gap_rows[g["name"]]
        assert row[1] == str(g["film_node"]) and row[6] == final[g["name"]]["status"]
        assert float(row[2]) == pytest.approx(float(final[g["name"]]["slip_x_mm"]), rel=1e-5, abs=1e-6)
    contact_rows = report_rows(tmp_path / "tubes.md", "### Curved support `archS`")
    for v in s_nodes:
        slip, travel, _, status = c[("archS", v)]
        row = contact_rows[str(v)]
        # half a unit of the table's third decimal and of the report's fourth (31.6605 and 31.661)
        assert row[6] == status and float(row[1]) == pytest.approx(slip, abs=5.5e-4)
        assert float(row[2]) == pytest.approx(travel, abs=5.5e-4)


def report_rows(path, heading: str) -> dict:
    """The rows of the table under ``heading`` of a CLI run report, by their first cell."""
    block = path.read_text().split(heading, 1)[1].split("\n#", 1)[0]
    rows = [[c.strip() for c in ln.strip("|").split("|")] for ln in block.splitlines() if ln.startswith("|")][2:]
    return {r[0]: r for r in rows}


def test_a_film_node_inside_a_tube_is_refused_by_name(mesh_file):
    m = tube_mapping(tube_s={"role": "curved_support", "name": "archS", "tube_radius": 0.04, "nodes": "over_s"})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshImportWarning)
        with pytest.raises(TubeError, match=r"curved support 'archS': film node \d+ at \(1.5, 0.6, 0.335\) lies "
                                            r"0.005 m inside the tube"):
            import_mesh(mesh_file, m)


def test_mesh_with_tube_arches_to_an_fmu_and_a_python_master_that_sees_the_yield_warning(mesh_file, tmp_path):
    """The user's flow: gmsh mesh with tube axes → curved supports → FMU → ``Film`` master; the
    film passes a (deliberately low) yield stress and the run report shows the FMU's warning."""
    from conftest import pack

    from membrane_contact import Film

    m = tube_mapping()
    m["material"] = {**MATERIAL, "yield_stress": 1.0e6}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshImportWarning)
        model = import_mesh(mesh_file, m)
    path = tmp_path / "tubes.json"
    path.write_text(json.dumps(model))
    fmu = pack(path, tmp_path)
    nodes = np.array(model["nodes"])
    s_nodes = model["curved_supports"][0]["nodes"]
    foot = min(s_nodes, key=lambda v: nodes[v][0])
    crown = min(s_nodes, key=lambda v: abs(nodes[v][0] - 1.5))
    from membrane_contact import SolverWarning

    with Film(fmu) as film, pytest.warns(SolverWarning, match="yield_stress"):
        results = film.run({"time": [1.0, 2.0], "frame.dz": [-0.075, -0.15]})
        report = film.report(results, tmp_path / "run.md").read_text()
    assert any("yield_stress" in w for w in results.warnings), results.warnings
    # never touched: slip 0 to rounding (the FMU's 10 increments per step leave 1e-17 m)
    assert abs(results[f"archS.node{foot}.slip"][-1]) < 1e-12 and results[f"archS.node{foot}.status"][-1] == 0
    assert results[f"archS.node{crown}.normalForce"][-1] > 100.0
    said = report.split("## Warnings", 1)[1].split("\n#", 1)[0]
    assert "yield_stress" in said, said
    row = report_rows(tmp_path / "run.md", "### Curved support `archS`")[f"node{foot}"]
    assert abs(float(row[1])) < 1e-9 and row[-1] == "Open", row
