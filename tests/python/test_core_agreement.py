"""The FMU computes what the core computes, and what mechanics requires.

SOURCE: the core's CLI (``membrane-contact specimen|model … --steps N --csv``), which steps
every group to ``target · k/N`` in its default increments per step; the FMU does the same with
its default ``solver.incrementsPerStep`` (the same core constant) and the input
``frame.dz = target · k/N`` before step k. The
CLI's CSV prints slips in mm with 6 decimals, so "to round-off" means within 1e-6 mm here.

TEST GOAL:
* slips (local x and y), normal forces and gap statuses of every step agree with the CLI for the
  200, 300 and 400 mm specimens and for a user model file;
* a friction sweep gives less slip for more friction;
* the String parameter ``frictionLaw = sliding-direction`` (set through fmpy) gives what the
  CLI's ``--friction-law sliding-direction`` gives;
* the film's Z equilibrium: the frame group's reaction balances the gap forces projected on Z
  (the symmetry planes x = 0, y = 0 carry no Z force).

MESH (ParallelArch, 1/4 model, 10 × 10 cells, 2 triangles each)::

    y=1.0  F F F F F F F F F F F      F: frame group (outer edges), dz prescribed
           · · · · G9· · · · · F      G1..G9: gaps on the arch line x = 0.4
           · · · · G8· · · · · F
           ...                 F
    y=0    s s s s G1s s s s s F      s: symmetry plane y = 0 (and x = 0 on the left)
          x=0     x=0.4      x=1.0

BOUNDARY CONDITIONS: ``frame.dz`` from 0 to −H/2, frame dx = dy = 0.

PARAMETERS: the specimen defaults (E = 1 GPa, ν = 0.43, t = 250 µm, σ0 = 0.5 MPa, μ = 0.2).
"""

from __future__ import annotations

import json

import pytest
from conftest import CUSTOM_GAPS
from fmu_helpers import Slave

GAPS = [f"G{i}" for i in range(1, 10)]
STATUS = {0: "Open", 1: "Stick", 2: "Slip"}
STEPS = 20


def run_fmu(fmu_path, group, target_dz, steps, parameters=None, inputs=None, gaps=GAPS):
    """Ramps ``<group>.dz`` and returns, per step, {gap: (slip_x mm, slip_y mm, N, status)}."""
    per_step = []
    with Slave(fmu_path) as s:
        s.initialize(parameters=parameters or {}, inputs=inputs)
        for k in range(steps):
            s.ramp({f"{group}.dz": target_dz}, steps, first=k, last=k + 1)
            per_step.append({
                g: (s.get(f"{g}.slip") * 1e3, s.get(f"{g}.slipY") * 1e3, s.get(f"{g}.normalForce"),
                    STATUS[s.get(f"{g}.status")])
                for g in gaps
            })
    return per_step


def compare(per_step, rows):
    assert len(rows) == sum(len(step) for step in per_step)
    for r in rows:
        slip_x, slip_y, normal, status = per_step[int(r["step"]) - 1][r["gap"]]
        where = f"step {r['step']} gap {r['gap']}"
        assert slip_x == pytest.approx(float(r["slip_x_mm"]), abs=1e-6), where
        assert slip_y == pytest.approx(float(r["slip_y_mm"]), abs=1e-6), where
        assert normal == pytest.approx(float(r["normal_force_N"]), abs=1e-6), where
        assert status == r["status"], where


@pytest.mark.parametrize("height_mm", [200, 300, 400])
def test_specimen_slips_match_the_core(fmu_path, cli, height_mm):
    height = height_mm / 1000
    target = -0.5 * height
    per_step = run_fmu(fmu_path, "frame", target, STEPS, parameters={"archHeight": height})
    rows = cli.run("specimen", "--height", height_mm, "--steps", STEPS)
    compare(per_step, rows)
    # The film slides towards the arch foot, more towards the foot.
    final = [per_step[-1][g][0] for g in GAPS]
    assert final[-1] > final[3] > final[1] > 0


def test_user_model_matches_the_core(custom_fmu, custom_model, cli):
    model = json.loads(custom_model.read_text())
    (target_dz,) = [g["target"][2] for g in model["groups"]]
    gaps = list(CUSTOM_GAPS.values())
    per_step = run_fmu(custom_fmu, "rim", target_dz, 10, gaps=gaps)
    rows = cli.run("model", custom_model, "--steps", 10)
    compare(per_step, rows)


def test_more_friction_less_slip(fmu_path, cli):
    slips = []
    for mu in [0.0, 0.1, 0.2, 0.4]:
        final = run_fmu(fmu_path, "frame", -0.15, 10, inputs={"mu": mu})[-1]
        slips.append([final[g][0] for g in GAPS])
    for gap in (3, 5, 7, 8):  # G4, G6, G8, G9
        column = [s[gap] for s in slips]
        assert column == sorted(column, reverse=True) and column[0] > column[-1], (GAPS[gap], column)
    # mu input = the CLI's --mu.
    reference = cli.final_slips_mm("specimen", "--height", 300, "--steps", 10, "--mu", 0.4)
    assert [slips[-1][i] for i in range(9)] == pytest.approx([reference[g] for g in GAPS], abs=1e-6)


def test_papers_friction_law_matches_the_core(fmu_path, cli):
    # 60 steps: with 20, Newton chatters open <-> closed where G2 closes under this law.
    steps = 60
    per_step = run_fmu(fmu_path, "frame", -0.15, steps, parameters={"frictionLaw": "sliding-direction"})
    rows = cli.run("specimen", "--height", 300, "--steps", steps, "--friction-law", "sliding-direction")
    compare(per_step, rows)
    cone = cli.final_slips_mm("specimen", "--height", 300, "--steps", steps)
    assert per_step[-1]["G2"][0] != pytest.approx(cone["G2"], abs=1e-3), "the law was not applied"


def test_frame_reaction_balances_the_gap_forces(fmu_path, cli):
    """Sum of Z forces on the film: frame reaction + gap forces = 0 (symmetry planes: no Z)."""
    frames = {g["name"]: g["frame"] for g in cli.export_specimen(300)["gaps"]}
    with Slave(fmu_path) as s:
        s.initialize()
        for k in range(STEPS):
            s.ramp({"frame.dz": -0.15}, STEPS, first=k, last=k + 1)
            rz = s.get("frame.Rz")
            gap_z = 0.0
            for g in GAPS:
                f = frames[g]
                n, fx, fy = s.get(f"{g}.normalForce", f"{g}.frictionX", f"{g}.frictionY")
                gap_z += n * f["z"][2] + fx * f["x"][2] + fy * f["y"][2]
                assert abs(fx) ** 2 + abs(fy) ** 2 == pytest.approx(s.get(f"{g}.frictionForce") ** 2, abs=1e-9)
            assert rz + gap_z == pytest.approx(0.0, abs=1e-6 * max(abs(rz), 1.0)), f"step {k}: Rz {rz}, gaps {gap_z}"
        assert rz < -100, "the frame pulls the film down onto the arches"
