"""Drive one FMU instance by variable *name* through fmpy's low-level FMU2Slave.

API verified on this machine in FMPY_NOTES.md. Two additions for tests:

* the FMU's log messages are captured in ``Slave.messages`` as ``(status, category, text)``
  (through fmpy's logger proxy, which formats the variadic call first; the proxy holds one
  logger per process, so messages are routed by instance name: keep names unique);
* ``Slave.call(name, *args)`` calls an ``fmi2*`` function raw and returns its status instead of
  raising, so tests can check fmi2Discard / fmi2Error (and pass NULL pointers as ``None``).
"""

from __future__ import annotations

import shutil
from ctypes import c_double, c_int, c_uint

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

OK, WARNING, DISCARD, ERROR, FATAL = 0, 1, 2, 3, 4
_COUNT = 0


class Slave:
    """One instance of an FMU, addressed by variable names."""

    def __init__(self, fmu_path, instance_name=None, logging_on=True, unzipdir=None):
        global _COUNT
        _COUNT += 1
        instance_name = instance_name or f"inst{_COUNT}"
        self.name = instance_name
        self.md = read_model_description(str(fmu_path))
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.own_dir = unzipdir is None
        self.unzipdir = unzipdir or extract(str(fmu_path))
        self.messages: list[tuple[int, str, str]] = []
        self.fmu = FMU2Slave(
            guid=self.md.guid,
            unzipDirectory=self.unzipdir,
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName=instance_name,
        )
        self.callbacks = callbacks_for(self.messages, instance_name)
        self.fmu.instantiate(callbacks=self.callbacks, loggingOn=logging_on)
        self.c = self.fmu.component

    # ------------------------------------------------------------------ lifecycle

    def initialize(self, parameters=None, inputs=None, start=0.0, stop=None):
        self.fmu.setupExperiment(startTime=start, stopTime=stop)
        self.fmu.enterInitializationMode()
        self.set({**(parameters or {}), **(inputs or {})})
        self.fmu.exitInitializationMode()
        return self

    def close(self):
        if self.fmu is not None:
            self.fmu.freeInstance()
            self.fmu = None
        if self.own_dir:
            shutil.rmtree(self.unzipdir, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # ------------------------------------------------------------------ values

    def vr(self, name):
        return self.variables[name].valueReference

    def set(self, values: dict):
        """Sets values by name, each with the setter of its type."""
        for name, value in values.items():
            v = self.variables[name]
            if v.type == "Real":
                self.fmu.setReal([v.valueReference], [float(value)])
            elif v.type == "Integer":
                self.fmu.setInteger([v.valueReference], [int(value)])
            elif v.type == "Boolean":
                self.fmu.setBoolean([v.valueReference], [bool(value)])
            elif v.type == "String":
                self.fmu.setString([v.valueReference], [str(value)])
            else:
                raise TypeError(f"{name}: {v.type}")

    def get(self, *names):
        """Values by name (one name: the value, several: a list)."""
        out = []
        for name in names:
            v = self.variables[name]
            getter = {"Real": self.fmu.getReal, "Integer": self.fmu.getInteger, "Boolean": self.fmu.getBoolean}
            out.append(getter[v.type]([v.valueReference])[0])
        return out[0] if len(names) == 1 else out

    def snapshot(self):
        """Every Real, Integer and Boolean variable by name (for exact comparisons)."""
        return {n: self.get(n) for n, v in self.variables.items() if v.type in ("Real", "Integer", "Boolean")}

    def outputs(self):
        return {n: self.get(n) for n, v in self.variables.items() if v.causality == "output"}

    # ------------------------------------------------------------------ stepping

    def step(self, t, h):
        """fmi2DoStep; returns the status instead of raising on Discard/Error."""
        return self.call("fmi2DoStep", self.c, c_double(t), c_double(h), c_int(1))

    def call(self, function, *args):
        """Calls an fmi2 function raw (no exception) and returns its status."""
        return self.fmu._functions[function](*args)

    def ramp(self, target: dict, steps: int, first=0, last=None, t_end=1.0):
        """Steps the inputs linearly from 0 to ``target`` over [0, t_end] in ``steps`` steps,
        the input at the end of step k being ``target * (k / steps)``; runs steps first..last-1."""
        last = steps if last is None else last
        for k in range(first, last):
            fraction = (k + 1) / steps
            self.set({name: value * fraction for name, value in target.items()})
            status = self.step(t_end * k / steps, t_end / steps)
            assert status == OK, f"step {k}: status {status}: {self.messages[-3:]}"

    def assert_states_keep_input_and_nan_is_refused(self, name, first, second):
        """Steps ``name`` to ``first`` over [0, 0.5], saves the FMU state, steps to ``second``;
        restoring the state gives the saved outputs back and the same second step repeats the
        first run exactly; a NaN for ``name`` is then fmi2Error with a message and changes
        nothing. The instance must be initialized."""
        self.set({name: first})
        assert self.step(0.0, 0.5) == OK
        state = self.fmu.getFMUstate()
        at_save = self.snapshot()
        self.set({name: second})
        assert self.step(0.5, 0.5) == OK
        reference = self.snapshot()

        self.fmu.setFMUstate(state)
        assert self.snapshot() == at_save
        self.set({name: second})
        assert self.step(0.5, 0.5) == OK
        assert self.snapshot() == reference
        self.fmu.freeFMUstate(state)

        vr = (c_uint * 1)(self.vr(name))
        status = self.call("fmi2SetReal", self.c, vr, 1, (c_double * 1)(float("nan")))
        assert status == ERROR
        assert self.logged(ERROR, f"{name} = NaN")
        assert self.snapshot() == reference

    def logged(self, status, text):
        return any(s == status and text in m for s, _, m in self.messages)


# fmpy's native logger proxy keeps one Python logger per process: the package routes the
# messages by instance name (membrane_contact.film.callbacks_for), as these tests need too.
from membrane_contact.film import callbacks_for  # noqa: E402


def vr_array(*vrs):
    return (c_uint * len(vrs))(*vrs)


__all__ = ["Slave", "callbacks_for", "vr_array", "FMICallException", "OK", "WARNING", "DISCARD", "ERROR", "FATAL"]
