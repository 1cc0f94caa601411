"""The Python run report (issue 17 item 9): ``Film.report`` / ``Results.report`` write the
sections a design calculation needs, with the numbers of the recorded outputs.

SOURCE: the recorded outputs themselves (``Results``) and the FMU's log: the report must show
them, not recompute them.

TEST GOAL: (1) a run of the 300 mm specimen FMU (frame lowered to −0.06 m in two steps) reported by
``Film.report``: every section is there; the model's parameters (film.E), the inputs as reached,
the frame's reaction at every recorded point, every gap's last and largest slip, normal force and
status, the stress extremes and the solver's iteration sum match ``Results`` to the printed six
digits; a warning in the FMU's log appears once under Warnings. (2) The reactions per unit length
that ``report.line_reactions`` reads from the FMU's VTK film file equal the closed form of a
uniformly stretched strip at every node of both end edges (as tests/engineering.rs for the core),
and Σ q · tributary is the group's FMU output pull.Rx.

PARAMETERS: the specimen's (src/specimens/parallel_arch.rs), archHeight 0.3 m.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from conftest import pack

from membrane_contact import Film


def rows_under(md: str, heading: str) -> list[list[str]]:
    """The cells of the table right under ``heading``."""
    block = md.split(heading, 1)[1].split("\n#", 1)[0]
    lines = [ln for ln in block.splitlines() if ln.startswith("|")][2:]
    return [[c.strip() for c in ln.strip("|").split("|")] for ln in lines]


def head_of(md: str, heading: str) -> list[str]:
    """The header cells of the table right under ``heading``."""
    block = md.split(heading, 1)[1].split("\n#", 1)[0]
    line = next(ln for ln in block.splitlines() if ln.startswith("|"))
    return [c.strip() for c in line.strip("|").split("|")]


def close(text: str, value: float, rel: float = 5e-6) -> bool:
    return abs(float(text) - value) <= rel * max(abs(value), 1e-12) + 1e-12


def test_film_report_has_every_section_with_the_recorded_numbers(fmu_path, tmp_path):
    with Film(fmu_path) as film:
        film.initialize(parameters={"archHeight": 0.3})
        results = film.run({"time": [1.0, 2.0], "frame.dz": [-0.03, -0.06]})
        film.messages.append((1, "warning", "equivalent stress 21.9 MPa above yield_stress"))
        film.messages.append((1, "warning", "equivalent stress 21.9 MPa above yield_stress"))
        path = film.report(results, tmp_path / "run.md")
        young = film["film.E"]
    md = path.read_text()
    for section in ("# Run report: ParallelArch", "## Model", "## Load steps", "## Reactions",
                    "### Reaction of `frame` (N)", "## Stresses and wrinkling", "## Slips along the supports",
                    "### Gaps", "## Warnings", "## Solver"):
        assert section in md, section
    model = dict(rows_under(md, "## Model"))
    assert model["gaps"] == "9" and close(model["film.E"], young)
    steps = rows_under(md, "## Load steps")
    assert [r[0] for r in steps] == ["0", "1", "2"]
    assert [float(r[2]) for r in steps] == [0.0, -0.03, -0.06]
    reaction = rows_under(md, "### Reaction of `frame` (N)")
    for k, row in enumerate(reaction):
        assert all(close(c, v) for c, v in zip(row[1:], results.reaction("frame")[k]))
    gaps = {r[0]: r for r in rows_under(md, "### Gaps")}
    assert list(gaps) == results.gap_names
    for g, row in gaps.items():
        slip = results[f"{g}.slip"]
        assert close(row[1], slip[-1] * 1e3) and close(row[2], np.max(np.abs(slip)) * 1e3), row
        assert close(row[4], results[f"{g}.normalForce"][-1])
        assert row[6] == {0: "Open", 1: "Stick", 2: "Slip"}[int(results[f"{g}.status"][-1])]
    assert any(r[6] != "Open" for r in gaps.values()), "the crown touches at dz = −0.06"
    stress = {r[1]: r for r in rows_under(md, "## Stresses and wrinkling") if r[0] == "film"}
    assert close(stress["maxEquivalentStress"][2].split()[0], results["film.maxEquivalentStress"][-1])
    warnings = [ln for ln in md.split("## Warnings", 1)[1].split("\n#", 1)[0].splitlines() if ln.startswith("- ")]
    assert warnings == ["- equivalent stress 21.9 MPa above yield_stress"]
    solver = dict(rows_under(md, "## Solver"))
    assert solver["steps taken"] == str(results.steps) == "2"
    assert int(solver["solver.iterations (sum)"]) == int(results["solver.iterations"][1:].sum()) > 0
    assert re.search(r"\| rollbacks \| 0 \|", md)
    # Every Integer statistic of the solver, as a column of the steps and summed.
    for s in ("solver.cutbacks", "solver.stabilizedIncrements"):
        column = head_of(md, "## Load steps").index(s)
        assert [int(r[column]) for r in steps[1:]] == [int(v) for v in results[s][1:]], s
        assert int(solver[f"{s} (sum)"]) == int(results[s][1:].sum()), s


def strip_model() -> dict:
    """The stretched strip of tests/engineering.rs: x = 0, 0.5, 1, 2; y = 0, 0.1, 0.3, 0.4, 0.7, 1;
    edge x = 0 the support set ``clamp``, edge x = 2 the group ``pull`` (x only)."""
    xs, ys = [0.0, 0.5, 1.0, 2.0], [0.0, 0.1, 0.3, 0.4, 0.7, 1.0]
    nid = lambda i, j: j * len(xs) + i  # noqa: E731
    tris = []
    for j in range(len(ys) - 1):
        for i in range(len(xs) - 1):
            a, b, c, d = nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1)
            tris += [[a, b, c], [a, c, d]]
    supports = []
    for j in range(len(ys)):
        for i in range(len(xs) - 1):
            if i == 0:
                supports.append({"node": nid(i, j), "fixed": ["x", "y", "z"] if j == 0 else ["x", "z"], "name": "clamp"})
            else:
                supports.append({"node": nid(i, j), "fixed": ["z"]})
    return {"name": "Strip", "nodes": [[x, y, 0.0] for y in ys for x in xs], "triangles": tris,
            "material": {"youngs_modulus": 1e9, "poisson_ratio": 0.3, "thickness": 2.5e-4},
            "supports": supports,
            "groups": [{"name": "pull", "nodes": [nid(len(xs) - 1, j) for j in range(len(ys))],
                        "target": [0.02, 0, 0], "components": ["x"]}]}


def test_line_reactions_of_the_fmus_vtk_film_file_are_the_stress_resultant(tmp_path):
    """Closed form as in tests/engineering.rs: q = λ · Y (λ² − 1)/2 · t along both end edges."""
    from membrane_contact.report import line_reactions

    model = strip_model()
    path = tmp_path / "strip.json"
    path.write_text(json.dumps(model))
    fmu = pack(path, tmp_path)
    out = tmp_path / "vtk"
    with Film(fmu) as film:
        film.set({"results.directory": str(out), "results.vtkFormat": "ascii",
                  "solver.displacementTolerance": 1e-11, "solver.residualTolerance": 1e-11})
        results = film.run({"time": [1.0], "pull.dx": [0.02]})
        rx = results["pull.Rx"][-1]
    lam = 1.01
    q = lam * 1e9 * 0.5 * (lam * lam - 1) * 2.5e-4
    lines = line_reactions(out / "Strip_film_0001.vtu", path)
    assert set(lines) == {"pull", "clamp"}
    for name, sign in (("pull", 1.0), ("clamp", -1.0)):
        rows = lines[name]
        assert len(rows) == 6 and np.allclose(rows[:, 2], [0.0, 0.1, 0.3, 0.4, 0.7, 1.0])
        np.testing.assert_allclose(rows[:, 4], sign * q, rtol=1e-8)
        np.testing.assert_allclose(rows[:, 5:], 0.0, atol=1e-8 * q)
    tributary = np.array([0.05, 0.15, 0.15, 0.2, 0.3, 0.15])
    assert (lines["pull"][:, 4] * tributary).sum() == pytest.approx(rx, rel=1e-12)
    # The Python run report carries them as the CLI's --line-reactions does (issue 47 item 8).
    report = results.report(tmp_path / "strip.md", title="Strip", line_reactions=lines)
    md = report.read_text()
    summary = {r[0]: r for r in rows_under(md, "## Line reactions (N/m)")}
    assert set(summary) == {"`pull`", "`clamp`"}
    for name in ("pull", "clamp"):
        assert summary[f"`{name}`"][1] == "6" and close(summary[f"`{name}`"][2], q, rel=1e-5)
        rows = rows_under(md, f"### `{name}`")
        assert [int(r[0]) for r in rows] == [int(n) for n in lines[name][:, 0]]
        for row, line in zip(rows, lines[name]):
            assert all(close(c, v, rel=1e-5) for c, v in zip(row[1:7], line[1:7])), row


def test_the_largest_slip_per_support_is_the_largest_magnitude_over_its_gaps_and_the_run(fmu_path):
    with Film(fmu_path, quiet=True) as film:
        film.initialize(parameters={"archHeight": 0.3})
        results = film.run({"time": [1.0, 2.0, 3.0], "frame.dz": [-0.05, -0.1, -0.15]})
    slips = np.stack([results[f"{g}.slip"] for g in results.gap_names], axis=1)
    t, k = np.unravel_index(np.argmax(np.abs(slips)), slips.shape)
    largest = results.largest_slips()
    assert list(largest) == ["G"]  # the specimen's gaps G1 … G9: one support
    assert largest["G"] == (results.gap_names[k], slips[t, k], results.time[t]) and largest["G"][1] != 0.0
    # supports named by the user
    halves = {"first": results.gap_names[:4], "rest": results.gap_names[4:]}
    mine = results.largest_slips(halves)
    for name, gaps in halves.items():
        where, value, _ = mine[name]
        assert where in gaps and abs(value) == max(np.max(np.abs(results[f"{g}.slip"])) for g in gaps)
