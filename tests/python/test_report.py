"""The Python run report (issue 17 item 9): ``Film.report`` / ``Results.report`` write the
sections a design calculation needs, with the numbers of the recorded outputs.

SOURCE: the recorded outputs themselves (``Results``) and the FMU's log: the report must show
them, not recompute them.

TEST GOAL: a run of the 300 mm specimen FMU (frame lowered to −0.06 m in two steps) reported by
``Film.report``: every section is there; the model's parameters (film.E), the inputs as reached,
the frame's reaction at every recorded point, every gap's last and largest slip, normal force and
status, the stress extremes and the solver's iteration sum match ``Results`` to the printed six
digits; a warning in the FMU's log appears once under Warnings.

PARAMETERS: the specimen's (src/mech/specimen.rs), archHeight 0.3 m.
"""

from __future__ import annotations

import re

import numpy as np

from membrane_contact import Film


def rows_under(md: str, heading: str) -> list[list[str]]:
    """The cells of the table right under ``heading``."""
    block = md.split(heading, 1)[1].split("\n#", 1)[0]
    lines = [ln for ln in block.splitlines() if ln.startswith("|")][2:]
    return [[c.strip() for c in ln.strip("|").split("|")] for ln in lines]


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
