"""Loads through fmpy (issue 8): a pressure input inflates a circular membrane.

TEST GOAL: the FMU packed from ``examples/circular_membrane.json`` (a clamped disc, rim = group
``rim``, pressure set ``top`` 200 Pa, force set ``lamp`` −5 N on the centre node, ETFE density,
gravity −9.81 m/s² along z) exposes ``top.pressure`` and ``lamp.Fx/Fy/Fz`` as inputs with the
model's values as start, ``film.density`` and ``gravity.*`` as parameters; ``fmpy validate`` finds
nothing; a pressure ramp driven through fmpy gives, at every step, the rim reaction that balances
the loads exactly (the resultant of a pressure on a surface with a fixed rim is p times the rim's
projected area); the final state agrees with the CLI, which ramps the file's loads; a NaN
pressure is fmi2Error with a message; FMU states keep the load levels.

BOUNDARY CONDITIONS: rim held at zero; ``top.pressure`` ramped 0 → 200 Pa in 4 steps (through
fmpy, and through libcosim, which must give the same numbers bit for bit); gravity and the lamp
load applied in the first step.
"""

from __future__ import annotations

import csv
import math
import re
import subprocess

import pytest
from conftest import CLI, ROOT, pack
from fmpy.validation import validate_fmu
from fmu_helpers import OK, Slave

EXAMPLE = ROOT / "examples" / "circular_membrane.json"
PRESSURE, LAMP, DENSITY, THICKNESS, G = 200.0, -5.0, 1750.0, 250e-6, 9.81
SIDES = 24  # 4 rings: 6·4 rim nodes
AREA = 0.5 * SIDES * math.sin(2 * math.pi / SIDES)  # the rim polygon, radius 1 m
STEPS = 4


@pytest.fixture(scope="module")
def membrane_fmu(tmp_path_factory):
    return pack(EXAMPLE, tmp_path_factory.mktemp("membrane-fmu"))


def rim_balance(pressure):
    """Rz that holds p·A up against the weight and the lamp."""
    return -(pressure * AREA - DENSITY * THICKNESS * AREA * G + LAMP)


def test_load_variables_come_from_the_model_file(membrane_fmu):
    assert validate_fmu(str(membrane_fmu)) == []
    with Slave(membrane_fmu) as s:
        v = s.variables
        assert v["top.pressure"].causality == "input" and v["top.pressure"].unit == "Pa"
        assert float(v["top.pressure"].start) == PRESSURE
        assert float(v["lamp.Fz"].start) == LAMP and v["lamp.Fx"].causality == "input"
        assert v["film.density"].causality == "parameter" and float(v["film.density"].start) == DENSITY
        assert float(v["gravity.z"].start) == -G


def test_pressure_ramp_balances_the_rim_reaction_and_matches_the_cli(membrane_fmu):
    with Slave(membrane_fmu) as s:
        s.initialize(inputs={"top.pressure": 0.0})
        assert s.get("rim.Rz") == 0.0
        for k in range(STEPS):
            p = PRESSURE * (k + 1) / STEPS
            s.set({"top.pressure": p})
            assert s.step(k / STEPS, 1 / STEPS) == OK, s.messages[-3:]
            assert s.get("rim.Rz") == pytest.approx(rim_balance(p), rel=1e-6)
        fmu_rz = s.get("rim.Rz")
        stress = s.get("film.maxEquivalentStress")

    out = subprocess.run([str(CLI), "model", str(EXAMPLE), "--steps", str(STEPS), "--quiet"],
                         check=True, capture_output=True, text=True).stdout
    assert f"load: pressure set top at {PRESSURE:.6f} Pa" in out
    rz = float(re.search(r"reaction of group rim: \(\S+, \S+, (\S+)\) N", out).group(1))
    assert rz == pytest.approx(fmu_rz, abs=2e-3)
    hi = float(re.search(r"stress: \S+ … (\S+) MPa", out).group(1))
    assert hi == pytest.approx(stress / 1e6, abs=2e-3)


def test_nan_pressure_is_an_error_and_states_keep_the_load_level(membrane_fmu):
    with Slave(membrane_fmu) as s:
        s.initialize(inputs={"top.pressure": 100.0})
        s.assert_states_keep_input_and_nan_is_refused("top.pressure", 100.0, 200.0)


def test_libcosim_drives_the_pressure_to_the_same_results_as_fmpy(membrane_fmu):
    from cosim_runner import run_with_libcosim

    observed = ["rim.Rz", "film.maxEquivalentStress", "solver.residual"]
    with Slave(membrane_fmu) as s:
        vr = {n: s.vr(n) for n in [*observed, "top.pressure"]}
        pressures = [PRESSURE * (k + 1) / STEPS for k in range(STEPS)]
        s.initialize(inputs={"top.pressure": pressures[0]})
        fmpy_values = {n: [] for n in observed}
        for k, p in enumerate(pressures):
            s.set({"top.pressure": p})
            assert s.step(k * 0.25, 0.25) == OK
            for n in observed:
                fmpy_values[n].append(s.get(n))
    cosim = run_with_libcosim(str(membrane_fmu), {vr["top.pressure"]: pressures}, 0.25, STEPS,
                              real_outputs=[vr[n] for n in observed], integer_outputs=[])
    for n in observed:
        assert cosim["real"][vr[n]] == fmpy_values[n], n  # bit for bit
    assert cosim["real"][vr["rim.Rz"]][-1] == pytest.approx(rim_balance(PRESSURE), rel=1e-6)


def test_thread_count_parameter_gives_the_same_bits_and_a_negative_count_is_refused_by_name(membrane_fmu):
    """``solver.threads`` 1, 2 and 3 (the assembly's scoped threads) through fmpy: every output of
    every step equal bit for bit; −1 fails ``fmi2ExitInitializationMode`` with a message naming
    ``solver.threads``."""
    from membrane_contact.film import FmuError

    observed = ["rim.Rz", "film.maxEquivalentStress", "solver.iterations"]
    runs = {}
    for threads in (1, 2, 3):
        with Slave(membrane_fmu) as s:
            s.initialize(parameters={"solver.threads": threads}, inputs={"top.pressure": 0.0})
            assert s.get("solver.threads") == threads
            values = []
            for k in range(STEPS):
                s.set({"top.pressure": PRESSURE * (k + 1) / STEPS})
                assert s.step(k / STEPS, 1 / STEPS) == OK, s.messages[-3:]
                values.append([s.get(n) for n in observed])
            runs[threads] = values
    assert runs[2] == runs[1] and runs[3] == runs[1]
    with Slave(membrane_fmu) as s:
        with pytest.raises(FmuError, match="solver.threads = -1 must be ≥ 0"):
            s.initialize(parameters={"solver.threads": -1})


def test_cushion_example_inflates_through_simulate_fmu_to_the_cli_answer(tmp_path):
    """README's cushion: ``examples/inflate_cushion.py`` drives ``Cushion.fmu`` through fmpy's
    ``simulate_fmu`` to 300 Pa and ends where the CLI's run of ``examples/cushion.json`` ends
    (an elastic film: the answer does not depend on the path)."""
    import sys

    example = ROOT / "examples" / "cushion.json"
    fmu = pack(example, tmp_path)
    out_csv = tmp_path / "cushion.csv"
    run = subprocess.run([sys.executable, str(ROOT / "examples" / "inflate_cushion.py"), "--steps", "5",
                          "--fmu", str(fmu), "--out", str(out_csv)],
                         capture_output=True, text=True, check=True)
    assert "Warning" not in run.stdout + run.stderr
    with open(out_csv) as f:
        rows = list(csv.DictReader(f))
    assert [float(r["time"]) for r in rows] == pytest.approx([0.0, 0.2, 0.4, 0.6, 0.8, 1.0])
    crowns = [float(r["crownTop.uz"]) for r in rows]
    assert all(b > a for a, b in zip(crowns, crowns[1:])), crowns

    cli = subprocess.run([str(CLI), "model", str(example), "--steps", "5", "--quiet"],
                         check=True, capture_output=True, text=True).stdout
    top = float(re.search(r"output point crownTop \(node 0\): displacement \(\S+, \S+, (\S+)\) m", cli).group(1))
    rz = float(re.search(r"reaction of group rim: \(\S+, \S+, (\S+)\) N", cli).group(1))
    assert crowns[-1] == pytest.approx(top, abs=2e-6)
    assert float(rows[-1]["rim.Rz"]) == pytest.approx(rz, abs=2e-3)
