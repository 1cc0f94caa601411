"""Two importers, one answer: libcosim (libcosimpy) and fmpy run the same FMU to the same results.

TEST GOAL: the FMU behaves the same under libcosim, which differs from fmpy in every way the
FMU can notice: it instantiates on one thread and steps on another, reads *every* variable
(parameters and inputs too, also in initialization mode), passes step sizes with a jitter in
the last bits (0.05 → 0.049999999999999989), never sets a stop time, and unpacks into its own
directory. Also fmpy's high-level ``simulate_fmu``.

BOUNDARY CONDITIONS: ``frame.dz`` ramped to −0.15 m over 20 steps of 0.05 (the default
experiment), default parameters (10 increments per step).
"""

from __future__ import annotations

import numpy as np
from cosim_runner import run_with_libcosim
from fmpy import read_model_description, simulate_fmu
from fmu_helpers import Slave

STEPS, H, TARGET = 20, 0.05, -0.15
OBSERVED = ["G1.slip", "G2.slip", "G4.slip", "G6.slip", "G8.slip", "G9.slip", "G3.normalForce", "frame.Rz",
            "film.maxEquivalentStress", "solver.residual"]
INTEGERS = ["G1.status", "G4.status", "G9.status", "solver.iterations"]


def test_libcosim_and_fmpy_agree(fmu_path):
    md = read_model_description(str(fmu_path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    dz = [TARGET * ((k + 1) / STEPS) for k in range(STEPS)]  # exactly as Slave.ramp
    cosim = run_with_libcosim(str(fmu_path), {vr["frame.dz"]: dz}, H, STEPS,
                              real_outputs=[vr[n] for n in OBSERVED], integer_outputs=[vr[n] for n in INTEGERS])
    assert cosim["time"][-1] == 1.0

    reals = {n: [] for n in OBSERVED}
    integers = {n: [] for n in INTEGERS}
    with Slave(fmu_path) as s:
        s.initialize()
        for k in range(STEPS):
            s.ramp({"frame.dz": TARGET}, STEPS, first=k, last=k + 1)
            for n in OBSERVED:
                reals[n].append(s.get(n))
            for n in INTEGERS:
                integers[n].append(s.get(n))
    for n in OBSERVED:
        assert cosim["real"][vr[n]] == reals[n], n  # bit for bit
    for n in INTEGERS:
        assert cosim["integer"][vr[n]] == integers[n], n
    assert reals["G8.slip"][-1] > 0.04 and integers["G9.status"][-1] == 0


def test_fmpy_simulate_fmu(fmu_path):
    """fmpy's high-level driver: inputs from a table, outputs every step, stopTime defined."""
    signal = np.array([(0.0, 0.0), (1.0, TARGET)], dtype=[("time", float), ("frame.dz", float)])
    messages = []
    result = simulate_fmu(str(fmu_path), input=signal, step_size=H, output=["G8.slip", "frame.Rz", "G1.status"],
                          logger=lambda *a: messages.append(a), debug_logging=True)
    assert len(result) == STEPS + 1
    assert result["time"][-1] == 1.0
    slip = result["G8.slip"]
    assert np.all(np.diff(slip[1:]) > 0), "slip grows as the frame goes down"
    # fmpy sets the input of time t before the step [t, t + h]: the frame reaches TARGET * 0.95.
    assert slip[-1] > 0.04
