"""A rotating frame side through fmpy and libcosim (issue 8): one hinged group, one input.

TEST GOAL: the FMU packed from ``examples/hinged_panel.json`` (a 1.0 m × 0.6 m panel held along
x = 0, its x = 1 m edge the group ``rail`` hinged about a pivot line 50 mm below it, the pressure
set ``snow``) has the input ``rail.angle`` (rad, display unit deg) and the output
``rail.moment`` (N·m) beside ``rail.dx/dy/dz`` and ``rail.Rx/Ry/Rz``; ``fmpy validate`` finds
nothing; turning the rail and loading the snow through fmpy ends where the CLI's standard run
(same targets) ends; libcosim, driving the same two inputs, gives the same numbers bit for bit;
a NaN angle is fmi2Error with a message and changes nothing; an FMU state restores the angle
(a step after the restore repeats the original exactly).

BOUNDARY CONDITIONS: ``frame`` supports fixed at x = 0; ``rail.angle`` ramped 0 → 0.1 rad and
``snow.pressure`` 0 → −100 Pa in 4 steps of 0.25.
"""

from __future__ import annotations

import re
import subprocess

import pytest
from conftest import CLI, ROOT, pack
from fmpy.validation import validate_fmu
from fmu_helpers import OK, Slave

EXAMPLE = ROOT / "examples" / "hinged_panel.json"
ANGLE, SNOW, STEPS = 0.1, -100.0, 4


@pytest.fixture(scope="module")
def panel_fmu(tmp_path_factory):
    return pack(EXAMPLE, tmp_path_factory.mktemp("hinged-fmu"))


def path_inputs(k):
    f = (k + 1) / STEPS
    return {"rail.angle": ANGLE * f, "snow.pressure": SNOW * f}


def test_hinged_group_has_an_angle_input_and_a_moment_output(panel_fmu):
    assert validate_fmu(str(panel_fmu)) == []
    with Slave(panel_fmu) as s:
        v = s.variables
        assert v["rail.angle"].causality == "input" and v["rail.angle"].unit == "rad"
        assert float(v["rail.angle"].start) == 0.0
        assert v["rail.moment"].causality == "output" and v["rail.moment"].unit == "N.m"
        units = {u.name: u for u in s.md.unitDefinitions}
        assert units["rad"].baseUnit.rad == 1
        assert [(d.name, d.factor) for d in units["rad"].displayUnits] == [("deg", pytest.approx(57.29577951308232))]
        assert {"rail.dx", "rail.dy", "rail.dz", "rail.Rx", "rail.Ry", "rail.Rz"} <= set(v)


def test_turning_the_rail_through_fmpy_ends_where_the_cli_does(panel_fmu):
    with Slave(panel_fmu) as s:
        s.initialize(inputs={"snow.pressure": 0.0})
        # Before any step the rail holds the warp prestress σ0 t W, 50 mm above its pivot.
        assert s.get("rail.moment") == pytest.approx(0.5e6 * 250e-6 * 0.6 * 0.05, rel=1e-9)
        moments = []
        for k in range(STEPS):
            s.set(path_inputs(k))
            assert s.step(k / STEPS, 1 / STEPS) == OK, s.messages[-3:]
            moments.append(s.get("rail.moment"))
        rx, moment, sag = s.get("rail.Rx", "rail.moment", "mid.uz")
    # The drive holds the pull of the stretched panel: the moment grows with the angle.
    assert all(b > a > 0 for a, b in zip(moments, moments[1:])), moments

    out = subprocess.run([str(CLI), "model", str(EXAMPLE), "--steps", str(STEPS), "--quiet"],
                         check=True, capture_output=True, text=True).stdout
    cli_rx = float(re.search(r"reaction of group rail: \((\S+), \S+, \S+\) N", out).group(1))
    cli_moment = float(re.search(r"moment of group rail about its hinge: (\S+) N·m at 0.100000 rad", out).group(1))
    cli_sag = float(re.search(r"output point mid \(node \d+\): displacement \(\S+, \S+, (\S+)\) m", out).group(1))
    assert cli_rx == pytest.approx(rx, abs=2e-3)
    assert cli_moment == pytest.approx(moment, abs=2e-4)
    assert cli_sag == pytest.approx(sag, abs=2e-6)


def test_libcosim_turns_the_rail_to_the_same_results_as_fmpy(panel_fmu):
    from cosim_runner import run_with_libcosim

    observed = ["rail.moment", "rail.Rx", "mid.uz", "solver.residual"]
    with Slave(panel_fmu) as s:
        vr = {n: s.vr(n) for n in [*observed, "rail.angle", "snow.pressure"]}
        s.initialize(inputs=path_inputs(0))
        fmpy_values = {n: [] for n in observed}
        for k in range(STEPS):
            s.set(path_inputs(k))
            assert s.step(k * 0.25, 0.25) == OK
            for n in observed:
                fmpy_values[n].append(s.get(n))
    inputs = {vr[n]: [path_inputs(k)[n] for k in range(STEPS)] for n in ("rail.angle", "snow.pressure")}
    cosim = run_with_libcosim(str(panel_fmu), inputs, 0.25, STEPS,
                              real_outputs=[vr[n] for n in observed], integer_outputs=[])
    for n in observed:
        assert cosim["real"][vr[n]] == fmpy_values[n], n  # bit for bit


def test_nan_angle_is_an_error_and_states_keep_the_angle(panel_fmu):
    with Slave(panel_fmu) as s:
        s.initialize(inputs={"snow.pressure": 0.0})
        s.assert_states_keep_input_and_nan_is_refused("rail.angle", 0.05, 0.1)
