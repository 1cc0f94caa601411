"""A model without a free DOF through the FMU (issue 17, defect 4): how single elements are verified.

TEST GOAL: the FMU packed from ``examples/driven_gap.json`` (one triangle whose every node is in
the group ``Drive``; the gap ``G`` 1 mm above a fixed point, k_n = 1e5 N/m, k_s = 1e4 N/m,
μ = 0.3) initializes (it was refused at fmi2ExitInitializationMode: "the model has no free DOF")
and, driven by ``Film.run`` along ``examples/driven_gap_path.csv`` (down 2 mm, then x = 1, 2, 4,
6 and back to 5 mm), sticks at k_s·dx, slips at μN = 30 N and sticks again on the way back, the
drive carrying the contact forces: the closed form, and the CLI's rows for the same path.
"""

from __future__ import annotations

import csv

import pytest
from conftest import ROOT, pack

from membrane_contact import Film

MODEL = ROOT / "examples" / "driven_gap.json"
PATH = ROOT / "examples" / "driven_gap_path.csv"
# N = k_n·1 mm; the friction force k_s·dx while it is below μN, μN beyond, k_s·(dx − 3 mm) back.
NORMAL = 100.0
FRICTION = [0.0, 10.0, 20.0, 30.0, 30.0, 20.0]
STATUS = [1, 1, 1, 2, 2, 1]


@pytest.fixture(scope="module")
def gap_fmu(tmp_path_factory):
    return pack(MODEL, tmp_path_factory.mktemp("driven-gap-fmu"))


def staged_path() -> dict[str, list[float]]:
    lines = [l for l in PATH.read_text().splitlines() if l.strip() and not l.startswith("#")]
    rows = list(csv.DictReader(lines, skipinitialspace=True))
    return {name: [float(r[name]) for r in rows] for name in rows[0]}


def test_a_gap_of_a_model_without_free_dofs_sticks_slips_and_sticks_again(gap_fmu, cli):
    with Film(gap_fmu) as film:
        res = film.run(staged_path())
    # Row 0 is the initial state (the gap open), then one row per step.
    assert list(res["G.status"][1:]) == STATUS
    assert res["G.status"][0] == 0
    assert res["G.normalForce"][1:] == pytest.approx([NORMAL] * 6, abs=1e-9)
    # The film feels the opposite of the gap's friction force; the drive pushes it.
    assert -res["G.frictionX"][1:] == pytest.approx(FRICTION, abs=1e-9)
    assert res["Drive.Rx"][1:] == pytest.approx(FRICTION, abs=1e-9)
    assert res["Drive.Rz"][1:] == pytest.approx([-NORMAL] * 6, abs=1e-9)
    assert list(res["solver.iterations"][1:]) == [0] * 6
    rows = cli.run("model", MODEL, "--path", PATH)
    assert [float(r["friction_force_N"]) for r in rows] == pytest.approx(FRICTION, abs=1e-6)
    assert [r["status"] for r in rows] == ["Stick" if s == 1 else "Slip" for s in STATUS]
