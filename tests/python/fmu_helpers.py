"""Drive one FMU instance by variable *name*: the package's :class:`membrane_contact.Film`
(fmpy's low-level FMU2Slave with the logger routed per instance) plus what only tests need.

API verified on this machine in FMPY_NOTES.md. What the tests use:

* the FMU's log messages are captured in ``Slave.messages`` as ``(status, category, text)``
  (the package's logger: fmpy's logger proxy holds one logger per process, so messages are
  routed by instance name, made unique by the package);
* ``Slave.fmu`` is fmpy's ``FMU2Slave`` (its wrappers raise ``FMICallException``) and
  ``Slave.c`` the component;
* ``Slave.call(name, *args)`` calls an ``fmi2*`` function raw and returns its status instead of
  raising, so tests can check fmi2Discard / fmi2Error (and pass NULL pointers as ``None``);
* ``Slave.step(t, h)`` is a raw fmi2DoStep at an explicit time (the package's ``Film.step``
  keeps the time itself).
"""

from __future__ import annotations

from ctypes import c_double, c_int, c_uint

from fmpy.fmi1 import FMICallException

from membrane_contact import Film
from membrane_contact.film import DISCARD, ERROR, FATAL, OK, WARNING, callbacks_for

_COUNT = 0


class Slave:
    """One instance of an FMU, addressed by variable names (over the package's ``Film``)."""

    def __init__(self, fmu_path, instance_name=None, logging_on=True):
        global _COUNT
        _COUNT += 1
        self.film = Film(fmu_path, name=instance_name or f"inst{_COUNT}", logging=logging_on)
        self.name = self.film.name
        self.md, self.variables, self.messages = self.film.md, self.film.variables, self.film.messages
        self.fmu = self.film.fmu
        self.c = self.fmu.component

    # ------------------------------------------------------------------ lifecycle

    def initialize(self, parameters=None, inputs=None, start=0.0, stop=None):
        self.film.initialize(parameters, inputs, start_time=start, stop_time=stop)
        return self

    def close(self):
        self.film.close()
        self.fmu = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # ------------------------------------------------------------------ values

    def vr(self, name):
        return self.variables[name].valueReference

    def set(self, values: dict):
        """Sets values by name, each with the setter of its type (``Film.set``)."""
        self.film.set(values)

    def get(self, *names):
        """Values by name (one name: the value, several: a list)."""
        return self.film.get(*names)

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


def vr_array(*vrs):
    return (c_uint * len(vrs))(*vrs)


__all__ = ["Slave", "callbacks_for", "vr_array", "FMICallException", "OK", "WARNING", "DISCARD", "ERROR", "FATAL"]
