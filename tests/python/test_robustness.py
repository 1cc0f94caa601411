"""The C boundary under misuse, several instances, odd step sizes and refused steps.

TEST GOAL: every bad call (NULL pointers through ctypes, unknown value reference, wrong type,
NaN input, call in the wrong state, bad parameter, bad GUID) returns fmi2Error with a logged
message and leaves the process and the instance alive; two instances side by side stay
independent; variable and jittered step sizes work; a step that cannot converge returns
fmi2Discard, keeps the last converged state and time, and a smaller retry from the same time
succeeds.

MODEL: ParallelArch.fmu; BOUNDARY CONDITIONS: ``frame.dz`` ramped towards −0.15 m.
"""

from __future__ import annotations

import math
from ctypes import byref, c_char_p, c_double, c_int, c_size_t, c_void_p

import pytest
from fmpy import extract
from fmpy.fmi2 import FMU2Slave
from fmu_helpers import DISCARD, ERROR, OK, Slave, callbacks_for, vr_array

RAMP = {"frame.dz": -0.15}


def test_bad_guid_is_refused(fmu_path, tmp_path):
    unzipdir = extract(str(fmu_path), unzipdir=str(tmp_path / "u"))
    messages = []
    slave = FMU2Slave(guid="{12345678-1234-5678-1234-567812345678}", unzipDirectory=unzipdir,
                      modelIdentifier="ParallelArch", instanceName="badguid")
    with pytest.raises(Exception, match="instantiate"):
        slave.instantiate(callbacks=callbacks_for(messages, "badguid"))
    assert any(s == ERROR and "GUID mismatch" in m for s, _, m in messages), messages
    slave.freeLibrary()


def test_bad_calls_return_error_and_log(fmu_path):
    with Slave(fmu_path) as s:
        c = s.c
        f = s.fmu._functions
        # Wrong state: no DoStep, no Get before initialization.
        assert s.step(0.0, 0.1) == ERROR
        assert s.logged(ERROR, "fmi2DoStep must not be called in state Instantiated")
        value = c_double()
        assert f["fmi2GetReal"](c, vr_array(s.vr("G1.slip")), 1, byref(value)) == ERROR
        s.fmu.setupExperiment(startTime=0.0)
        s.fmu.enterInitializationMode()

        # NULL pointers with n > 0 (NULL with n = 0 is fine).
        assert f["fmi2GetReal"](c, None, 1, None) == ERROR and s.logged(ERROR, "vr is NULL")
        assert f["fmi2SetReal"](c, vr_array(s.vr("mu")), 1, None) == ERROR and s.logged(ERROR, "value is NULL")
        assert f["fmi2GetReal"](c, None, 0, None) == OK
        assert f["fmi2GetFMUstate"](c, None) == ERROR and s.logged(ERROR, "FMUstate is NULL")
        assert f["fmi2SerializedFMUstateSize"](c, None, None) == ERROR
        assert f["fmi2DoStep"](None, 0.0, 0.1, 1) == ERROR  # NULL instance: nothing to log to
        assert f["fmi2SetDebugLogging"](c, 1, 1, None) == ERROR and s.logged(ERROR, "categories is NULL")

        # Unknown value reference, wrong type.
        assert f["fmi2GetReal"](c, vr_array(99999), 1, byref(value)) == ERROR
        assert s.logged(ERROR, "value reference 99999 does not exist")
        integer = c_int()
        assert f["fmi2GetInteger"](c, vr_array(s.vr("G1.slip")), 1, byref(integer)) == ERROR
        assert s.logged(ERROR, "(G1.slip) is a Real, not an Integer")
        string = c_char_p()
        assert f["fmi2GetString"](c, vr_array(0), 1, byref(string)) == ERROR
        assert s.logged(ERROR, "(time) is a Real, not a String")

        # Non-finite inputs and parameters, outputs and time.
        for name, v, expect in [("frame.dz", math.nan, "must be finite"), ("film.E", math.inf, "must be finite"),
                                ("G3.slip", 0.0, "is an output"), ("time", 0.0, "time cannot be set")]:
            assert f["fmi2SetReal"](c, vr_array(s.vr(name)), 1, (c_double * 1)(v)) == ERROR, name
            assert s.logged(ERROR, expect), (name, s.messages[-1])

        # A bad parameter: ExitInitializationMode reports the core's message and can be retried.
        s.set({"film.E": -5.0})
        assert f["fmi2ExitInitializationMode"](c) == ERROR
        assert s.logged(ERROR, "E = -5 must be > 0"), s.messages[-1]
        s.set({"film.E": 1e9, "archHeight": 0.9})
        assert f["fmi2ExitInitializationMode"](c) == ERROR
        assert s.logged(ERROR, "archHeight = 0.9"), s.messages[-1]
        s.set({"archHeight": 0.3})
        assert f["fmi2ExitInitializationMode"](c) == OK

        # After initialization: parameters are fixed, time must match, no second init.
        assert f["fmi2SetReal"](c, vr_array(s.vr("film.E")), 1, (c_double * 1)(2e9)) == ERROR
        assert s.logged(ERROR, "film.E is a fixed parameter")
        assert s.step(0.3, 0.1) == ERROR and s.logged(ERROR, "differs from the FMU's time 0")
        assert s.step(0.0, -0.1) == ERROR and s.logged(ERROR, "must be > 0")
        assert f["fmi2ExitInitializationMode"](c) == ERROR
        assert f["fmi2CancelStep"](c) == ERROR
        # Directional derivatives are provided (issue 21): an empty request is answered, a NULL
        # array with a count and an unknown reference are refused with a message.
        assert f["fmi2GetDirectionalDerivative"](c, None, 0, None, 0, None, None) == OK
        assert f["fmi2GetDirectionalDerivative"](c, None, 1, None, 0, None, None) == ERROR
        assert s.logged(ERROR, "vUnknown_ref is NULL"), s.messages[-1]
        unknown = (c_double * 1)(0.0)
        assert f["fmi2GetDirectionalDerivative"](
            c, vr_array(s.vr("G1.slip")), 1, vr_array(99999), 1, (c_double * 1)(1.0), unknown) == ERROR
        assert s.logged(ERROR, "99999"), s.messages[-1]
        assert f["fmi2SetRealInputDerivatives"](c, None, 0, None, None) == ERROR

        # Unknown log category.
        names = (c_char_p * 1)(b"logNothing")
        assert f["fmi2SetDebugLogging"](c, 1, 1, names) == ERROR and s.logged(ERROR, "unknown log category")

        # All of that left the instance working.
        s.ramp(RAMP, 20, last=2)
        assert s.get("G8.slip") > 0
        s.fmu.terminate()
        assert s.step(0.1, 0.05) == ERROR  # terminated


def test_time_and_status_getters(fmu_path):
    with Slave(fmu_path) as s:
        s.fmu.setupExperiment(startTime=2.0, stopTime=3.0)
        s.fmu.enterInitializationMode()
        assert s.get("time") == 2.0
        s.fmu.exitInitializationMode()
        s.set({"frame.dz": -0.01})
        assert s.step(2.0, 0.5) == OK
        assert s.get("time") == 2.5
        assert s.fmu.getRealStatus(2) == 2.5  # fmi2LastSuccessfulTime
        assert not s.fmu.getBooleanStatus(3)  # fmi2Terminated: the FMU never asks to stop
        assert s.step(2.5, 0.6) == ERROR and s.logged(ERROR, "beyond stopTime")
        assert s.step(2.5, 0.5) == OK


def test_two_instances_side_by_side_stay_independent(fmu_path):
    def solo(mu):
        with Slave(fmu_path) as s:
            s.initialize(inputs={"mu": mu})
            s.ramp(RAMP, 10)
            return s.outputs()

    alone = {mu: solo(mu) for mu in (0.1, 0.5)}
    with Slave(fmu_path) as a, Slave(fmu_path) as b:
        a.initialize(inputs={"mu": 0.1})
        b.initialize(inputs={"mu": 0.5})
        for k in range(10):  # interleaved
            a.ramp(RAMP, 10, first=k, last=k + 1)
            b.ramp(RAMP, 10, first=k, last=k + 1)
        assert a.outputs() == alone[0.1]
        assert b.outputs() == alone[0.5]
    assert alone[0.1]["G9.slip"] > alone[0.5]["G9.slip"]


def test_variable_and_jittered_step_sizes(fmu_path):
    """Time is a pseudo-time: the results depend on the input sequence, not on the step sizes."""
    fractions = [0.05, 0.1, 0.3, 0.45, 0.7, 1.0]
    results = []
    for steps in ([0.05, 0.05, 0.2, 0.15, 0.25, 0.3], [1 / 6] * 6, [0.1] * 5 + [0.5]):
        with Slave(fmu_path) as s:
            s.initialize()
            t = 0.0
            for fraction, h in zip(fractions, steps):
                s.set({"frame.dz": -0.15 * fraction})
                assert s.step(t, h) == OK
                t += h
            assert s.get("time") == pytest.approx(t, abs=1e-12)
            results.append(s.outputs())
    assert results[0] == results[1] == results[2]
    # libcosim-style jitter: t_k from integer nanoseconds, h = t_{k+1} - t_k.
    with Slave(fmu_path) as s:
        s.initialize()
        for k in range(10):
            t, t_next = (k * 100_000_000) / 1e9, ((k + 1) * 100_000_000) / 1e9
            s.set({"frame.dz": -0.015 * (k + 1)})
            assert s.step(t, t_next - t) == OK, (t, t_next - t, s.messages[-1:])


def test_a_refused_step_can_be_retried_smaller(fmu_path):
    with Slave(fmu_path) as s:
        # One increment, no cut-backs, 10 iterations, no viscous stabilization (with it the jump
        # converges carrying its damping force): small steps converge, a jump does not.
        s.initialize(parameters={"solver.maxCutbacks": 0, "solver.maxIterations": 10, "solver.incrementsPerStep": 1,
                                 "solver.stabilization": False})
        s.ramp(RAMP, 40, last=3)
        before = s.outputs()
        t = s.get("time")
        s.set({"frame.dz": -0.15})
        assert s.step(t, 1.0 - t) == DISCARD
        assert s.logged(DISCARD, "did not converge") and s.logged(DISCARD, f"Time stays {t}")
        assert s.outputs() == before and s.get("time") == t
        assert s.fmu.getStatus(0) == DISCARD  # fmi2DoStepStatus
        # Retry with a smaller change from the same time.
        s.set({"frame.dz": -0.15 * 4 / 40})
        assert s.step(t, 0.025) == OK
        assert s.get("G9.slip") > before["G9.slip"]
        assert s.fmu.getStatus(0) == OK


def test_reset_gives_the_same_run_again(fmu_path):
    with Slave(fmu_path) as s:
        s.initialize(parameters={"film.E": 1.2e9}, inputs={"mu": 0.3})
        s.ramp(RAMP, 5)
        first = s.outputs()
        s.fmu.reset()
        s.initialize(parameters={"film.E": 1.2e9}, inputs={"mu": 0.3})
        s.ramp(RAMP, 5)
        assert s.outputs() == first


def test_debug_logging_categories(fmu_path):
    with Slave(fmu_path, logging_on=False) as s:
        s.initialize()
        s.ramp(RAMP, 20, last=1)
        assert not any(c == "logEvents" for _, c, _ in s.messages)
        assert s.step(5.0, 0.1) == ERROR and s.logged(ERROR, "differs"), "errors are logged by default"
        s.fmu.setDebugLogging(True, ["logEvents"])
        s.ramp(RAMP, 20, first=1, last=2)
        assert any(c == "logEvents" and "step to t = 0.1" in m for _, c, m in s.messages)
        s.fmu.setDebugLogging(False, [])
        n = len(s.messages)
        assert s.step(5.0, 0.1) == ERROR
        assert len(s.messages) == n, "everything off"


def test_states_are_opaque_handles(fmu_path):
    """A made-up state pointer is refused, never dereferenced."""
    with Slave(fmu_path) as s:
        s.initialize()
        bogus = c_void_p(0xDEADBEEF)
        f = s.fmu._functions
        assert f["fmi2SetFMUstate"](s.c, bogus) == ERROR
        assert f["fmi2FreeFMUstate"](s.c, byref(bogus)) == ERROR
        size = c_size_t()
        assert f["fmi2SerializedFMUstateSize"](s.c, bogus, byref(size)) == ERROR
        assert s.logged(ERROR, "was not created by this instance")
        s.ramp(RAMP, 20, last=1)



def test_simulate_fmu_ends_on_a_refused_step(fmu_path, tmp_path):
    """fmpy.simulate_fmu repeats a Discarded step until fmi2GetBooleanStatus(fmi2Terminated) is
    true. The FMU says so when the identical step is refused a second time, so the run ends at the
    last successful time instead of hanging. Run in a child process with a timeout: a hang must
    fail the test, not the CI job."""
    import subprocess
    import sys
    import textwrap

    script = textwrap.dedent(f"""
        import numpy as np
        from fmpy import simulate_fmu
        signals = np.array([(0.0, 0.0), (0.1, -0.15), (1.0, -0.15)],
                           dtype=[("time", np.float64), ("frame.dz", np.float64)])
        # One increment, no cut-back, few iterations: the jump to -H/2 cannot converge.
        result = simulate_fmu({str(fmu_path)!r}, stop_time=1.0, step_size=0.1, input=signals,
                              start_values={{"solver.incrementsPerStep": 1, "solver.maxCutbacks": 0,
                                             "solver.maxIterations": 3}},
                              output=["frame.Rz"])
        print("ROWS", len(result), "LAST", float(result["time"][-1]))
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    line = [l for l in done.stdout.splitlines() if l.startswith("ROWS")][-1]
    last = float(line.split()[-1])
    # The run stopped early, at a time before the refused jump, instead of looping for ever.
    assert last < 1.0, line
