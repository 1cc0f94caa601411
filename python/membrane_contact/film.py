"""One FMU instance of a film, driven by variable names through fmpy's ``FMU2Slave``.

* Names, not value references: ``film.set({"frame.dz": -0.1})``, ``film["G2.slip"]``.
* The FMU's log is captured in ``film.messages`` as ``(status, category, text)`` and, with
  ``echo=True``, printed as it comes. fmpy's native logger proxy keeps one Python logger per
  process (the last one registered receives every instance's messages), so one module-level
  logger routes the messages by instance name; instance names are made unique.
* :meth:`Film.run` steps a staged load path (a table of input values over pseudo-time): each
  row's inputs are reached at the row's time (the FMU moves its inputs linearly over a step;
  ``dt`` splits the rows into shorter steps with the inputs interpolated linearly). Before each
  step the FMU state is saved (fmi2GetFMUstate, into one reused buffer); a step the FMU refuses
  (fmi2Discard) is rolled back to it (fmi2SetFMUstate) and split into two halves with the inputs
  interpolated, recursively, up to ``max_halvings`` times; then :class:`StepRefused` says where
  and why (the FMU's last messages), the film at its last converged state.
* :meth:`Film.save` / :meth:`Film.restore` roll the instance back (fmi2Get/SetFMUstate);
  :meth:`Film.serialize` / :meth:`Film.deserialize` give bytes to keep a state on disk.
* The FMU's warnings (a stress above ``yield_stress``, E that looks like MPa, flipped pressure
  triangles) reach the master: each distinct one is emitted once per run as a
  :class:`SolverWarning` (Python ``warnings``), kept in ``Results.warnings`` and summed up in one
  printed line; ``strict=True`` raises :class:`SolverWarningError` at the first one instead.
"""

from __future__ import annotations

import itertools
import os
import re
import shutil
import sys
import warnings
from ctypes import byref, c_double, c_int
from pathlib import Path
from typing import Any

import numpy as np
from fmpy import calloc, extract, free, read_model_description
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2FMUstate,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.logging import addLoggerProxy

from .fmu import find_fmu

OK, WARNING, DISCARD, ERROR, FATAL, PENDING = range(6)
STATUS_NAMES = ("fmi2OK", "fmi2Warning", "fmi2Discard", "fmi2Error", "fmi2Fatal", "fmi2Pending")

#: Inputs the FMU applies as they are for the whole step (not ramped from their last value):
#: split steps take the row's value, not an interpolated one. ``mu`` holds from the next step on
#: (docs/fmu.md); every other input (displacements, angles, pressures, forces) is ramped.
HELD_INPUTS = frozenset({"mu"})

# ---------------------------------------------------------------------------- the FMU's log

_ROUTES: dict[str, tuple[list, bool]] = {}
_UNROUTED: list = []


def _route(env, instance_name, status, category, message):
    name = instance_name.decode() if instance_name else ""
    messages, echo = _ROUTES.get(name, (_UNROUTED, False))
    entry = (status, category.decode() if category else "", message.decode(errors="replace"))
    messages.append(entry)
    if echo:
        print(f"[{name}] {STATUS_NAMES[status] if status < 6 else status}: {entry[2]}")


# Kept for the life of the process: the native proxy may call the logger after the instance
# that registered it is gone.
_LOGGER = fmi2CallbackLoggerTYPE(_route)
_ALLOCATE = fmi2CallbackAllocateMemoryTYPE(calloc)
_FREE = fmi2CallbackFreeMemoryTYPE(free)
_COUNTER = itertools.count(1)


def callbacks_for(messages: list, instance_name: str, echo: bool = False):
    """fmi2CallbackFunctions whose logger appends ``(status, category, text)`` of the instance
    named ``instance_name`` to ``messages`` (and prints them when ``echo``)."""
    _ROUTES[instance_name] = (messages, echo)
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = _LOGGER
    callbacks.allocateMemory = _ALLOCATE
    callbacks.freeMemory = _FREE
    addLoggerProxy(byref(callbacks))
    return callbacks


# ---------------------------------------------------------------------------- errors


class FmuError(RuntimeError):
    """An FMI call returned fmi2Error or fmi2Fatal; the message carries the FMU's last log lines."""

    def __init__(self, function: str, status: int, messages: list):
        self.function, self.status, self.messages = function, status, list(messages)
        tail = "; ".join(m for _, _, m in messages[-3:]) or "no log message"
        super().__init__(f"{function} returned {STATUS_NAMES[status]}: {tail}")


class SolverWarning(UserWarning):
    """A warning of the FMU (logged with fmi2Warning): the result stands but leaves the model's
    assumptions (a stress above ``yield_stress``, strains beyond the small-strain range), or the
    model looks wrong (E that looks like MPa, flipped pressure triangles)."""


class SolverWarningError(RuntimeError):
    """Raised instead of a :class:`SolverWarning` with ``strict=True``: the film stays at the
    state that warned (its step stood); ``message`` is the FMU's text."""

    def __init__(self, message: str, time: float | None):
        self.message, self.time = message, time
        super().__init__(f"the FMU warned (strict) at t = {time}: {message}")


def warning_kind(message: str) -> str:
    """What makes two FMU warnings the same kind: the text without its numbers (the time, the
    stress, the triangle) — a run that stays above the yield stress warns once, not per step."""
    return re.sub(r"[-+]?\d+(\.\d+)?([eE][-+]?\d+)?", "#", message)


class StepRefused(RuntimeError):
    """A step the FMU kept refusing (fmi2Discard) after every allowed halving. The instance is
    at its last converged state, ``time``."""

    def __init__(self, time: float, target_time: float, halvings: int, messages: list):
        self.time, self.target_time, self.halvings = time, target_time, halvings
        self.messages = list(messages)
        refusals = [m for s, _, m in messages if s >= WARNING]
        tail = refusals[-1] if refusals else "no log message"
        super().__init__(
            f"the FMU refused the step from t = {time:g} toward t = {target_time:g} even after "
            f"{halvings} halvings (the film stays at t = {time:g}): {tail}"
        )


# ---------------------------------------------------------------------------- results


class Results:
    """Outputs over the communication points reached: ``time`` and one numpy array per output
    (``results["G2.slip"]``) and per input column of the table, as reached
    (``results["frame.dz"]``)."""

    def __init__(self, names: list[str], gap_names: list[str], input_names: list[str] = ()):
        self.names = list(names)
        self.gap_names = list(gap_names)
        #: The table's input columns, recorded as reached at each point (``results["frame.dz"]``).
        self.input_names = [n for n in input_names if n not in self.names]
        self._time: list[float] = []
        self._rows: list[list[float]] = []
        self._inputs: list[list[float]] = []
        #: The FMU's distinct warnings of the run (the first message of each kind, see
        #: :func:`warning_kind`), each also emitted as a :class:`SolverWarning`.
        self.warnings: list[str] = []
        #: Steps split in halves after a refusal, steps taken in all, and refused steps rolled
        #: back to the state saved before them (fmi2SetFMUstate).
        self.halvings = 0
        self.steps = 0
        self.rollbacks = 0

    def _append(self, time: float, row: list[float], inputs: list[float] = ()):
        self._time.append(time)
        self._rows.append(row)
        self._inputs.append(list(inputs))

    @property
    def time(self) -> np.ndarray:
        return np.asarray(self._time, dtype=float)

    def __getitem__(self, name: str) -> np.ndarray:
        if name == "time":
            return self.time
        if name in self.names:
            k = self.names.index(name)
            return np.asarray([r[k] for r in self._rows], dtype=float)
        if name in self.input_names:
            k = self.input_names.index(name)
            return np.asarray([r[k] for r in self._inputs], dtype=float)
        raise KeyError(f"'{name}' is not recorded; recorded: {', '.join(self.names + self.input_names)}")

    def __len__(self):
        return len(self._time)

    def as_dict(self, inputs: bool = False) -> dict[str, np.ndarray]:
        """``{"time": …, name: …}`` as numpy arrays: the outputs, and with ``inputs`` the
        table's input columns as reached."""
        table = np.asarray(self._rows, dtype=float).reshape(len(self._rows), len(self.names))
        data = {"time": self.time, **{n: table[:, k] for k, n in enumerate(self.names)}}
        if inputs:
            data.update({n: self[n] for n in self.input_names})
        return data

    def to_pandas(self, inputs: bool = False) -> Any:
        """A pandas DataFrame indexed by time (needs pandas): the outputs, and with ``inputs``
        the table's input columns as reached."""
        import pandas as pd

        data = self.as_dict(inputs)
        return pd.DataFrame({n: v for n, v in data.items() if n != "time"}, index=pd.Index(data["time"], name="time"))

    def slips(self, gaps: list[str] | None = None, component: str = "slip") -> tuple[list[str], np.ndarray]:
        """Slip of each gap (m) over time, in the model's gap order (along the support for the
        generated specimens and imported arches): ``(names, array[time, gap])``. ``component``:
        ``slip`` (local x), ``slipY``, ``normalForce``, ``frictionForce``, …"""
        names = list(gaps) if gaps is not None else self.gap_names
        return names, np.stack([self[f"{g}.{component}"] for g in names], axis=1) if names else np.zeros((len(self), 0))

    def report(self, path, *, title: str = "run", variables: dict | None = None, messages: list | None = None,
               line_reactions: dict | None = None) -> Path:
        """Writes a Markdown run report of these results to ``path`` (``report.py``: load steps,
        reactions, line reactions (``line_reactions``: from
        :func:`membrane_contact.report.line_reactions` of a film VTK file), stresses, slips,
        warnings from ``messages``, solver statistics); returns the path. :meth:`Film.report`
        fills in the model and the FMU's log."""
        from .report import write

        return write(self, path, title=title, variables=variables, messages=messages, line_reactions=line_reactions)

    def largest_slips(self, supports: dict[str, list[str]] | None = None,
                      component: str = "slip") -> dict[str, tuple[str, float, float]]:
        """The largest slip per support over the run: ``{support: (where, slip, time)}``, ``where``
        the gap or contact with the largest ``|slip|`` (signed value in m, at ``time``).
        ``supports``: ``{support: [gap, ...]}``; default: each curved support's contacts
        (``<support>.node<k>.slip``), and the gaps grouped by their name without its trailing
        number (``N1`` … ``N13`` → ``N``; the specimen's ``G1`` … ``G9`` → ``G``)."""
        if supports is None:
            supports = {}
            for g in self.gap_names:
                supports.setdefault(re.sub(r"\d+$", "", g) or g, []).append(g)
            for n in self.names:
                m = re.match(r"(\w+)\.(node\d+)\.slip$", n)
                if m and component == "slip":
                    supports.setdefault(m[1], []).append(f"{m[1]}.{m[2]}")
        found = {}
        for support, members in supports.items():
            best = None
            for g in members:
                values = self[f"{g}.{component}"]
                if not len(values):
                    continue
                k = int(np.nanargmax(np.abs(values))) if np.isfinite(values).any() else 0
                if best is None or abs(values[k]) > abs(best[1]):
                    best = (g, float(values[k]), float(self.time[k]))
            if best is not None:
                found[support] = best
        return found

    def reaction(self, group: str) -> np.ndarray:
        """Reaction ``[Rx, Ry, Rz]`` (N) of a group or support set over time (NaN for a component
        it does not have)."""
        out = np.full((len(self), 3), np.nan)
        for c, axis in enumerate("xyz"):
            name = f"{group}.R{axis}"
            if name in self.names:
                out[:, c] = self[name]
        if np.isnan(out).all():
            raise KeyError(f"no reaction outputs {group}.Rx/Ry/Rz recorded")
        return out


# ---------------------------------------------------------------------------- the instance


def _columns(table) -> dict[str, np.ndarray]:
    """A table as ``{name: float array}``: a dict of sequences, a list of row dicts, a numpy
    structured array, or a pandas DataFrame."""
    if hasattr(table, "to_dict") and hasattr(table, "columns"):  # pandas
        table = {str(c): table[c].to_numpy() for c in table.columns}
    elif isinstance(table, np.ndarray) and table.dtype.names:
        table = {n: table[n] for n in table.dtype.names}
    elif isinstance(table, (list, tuple)):
        if not table or not all(isinstance(r, dict) for r in table):
            raise TypeError("a table given as a list must be a non-empty list of row dicts")
        names = list(table[0])
        for i, r in enumerate(table):
            if list(r) != names:
                raise ValueError(f"row {i} has the columns {list(r)}, row 0 {names}")
        table = {n: [r[n] for r in table] for n in names}
    if not isinstance(table, dict):
        raise TypeError(f"cannot read a table from {type(table).__name__}")
    columns = {str(k): np.asarray(v, dtype=float).ravel() for k, v in table.items()}
    lengths = {len(v) for v in columns.values()}
    if len(lengths) != 1:
        raise ValueError(f"the table's columns have different lengths {sorted(lengths)}")
    return columns


class Film:
    """One instance of a membrane-contact FMU (or any FMI 2.0 co-simulation FMU), addressed by
    variable names. Use it as a context manager, or call :meth:`close`."""

    def __init__(self, fmu: str | os.PathLike | None = None, *, name: str | None = None, logging: bool = True,
                 echo: bool = False, model: str | None = None, strict: bool = False, quiet: bool = False) -> None:
        self.path = find_fmu(fmu, model)
        self.md = read_model_description(str(self.path))
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.name = f"{name or self.md.coSimulation.modelIdentifier}#{next(_COUNTER)}"
        self.messages: list[tuple[int, str, str]] = []
        self._unzipdir = extract(str(self.path))
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self._unzipdir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=self.name)
        self._callbacks = callbacks_for(self.messages, self.name, echo)
        self.fmu.instantiate(callbacks=self._callbacks, loggingOn=logging)
        if not logging:
            # Warnings reach the master even without the event log.
            self.fmu.setDebugLogging(True, ["logStatusWarning"])
        #: ``strict``: raise :class:`SolverWarningError` at the FMU's first warning;
        #: ``quiet``: no printed summary line of a run's warnings.
        self.strict, self.quiet = strict, quiet
        # Messages already looked at for warnings, warning kinds of the current run, and the
        # warnings seen outside a run (initialize), handed to the next run's results.
        self._looked_at = 0
        self._kinds: set[str] = set()
        self._pending: list[str] = []
        self.time: float | None = None
        self._states: list = []
        real_inputs = [v for v in self.md.modelVariables if v.causality == "input" and v.type == "Real"]
        # The inputs as set, and as reached by the last converged step: a refused step is
        # halved between the two. The analysis starts unloaded, so before the first step every
        # input but mu (applied as it is, never ramped) is reached at 0.
        self._set_inputs = {v.name: float(v.start) if v.start is not None else 0.0 for v in real_inputs}
        self._reached = {n: 0.0 for n in self._set_inputs}

    # -- names

    def _names(self, causality: str) -> list[str]:
        return [v.name for v in self.md.modelVariables if v.causality == causality]

    @property
    def inputs(self) -> list[str]:
        return self._names("input")

    @property
    def outputs(self) -> list[str]:
        return self._names("output")

    @property
    def parameters(self) -> list[str]:
        return self._names("parameter")

    @property
    def gaps(self) -> list[str]:
        """Gap names in the model's order (those with a ``<gap>.slip`` output)."""
        return [n[: -len(".slip")] for n in self.outputs if n.endswith(".slip")]

    def _variable(self, name: str):
        try:
            return self.variables[name]
        except KeyError:
            raise KeyError(f"'{name}' is not a variable of {self.md.modelName}") from None

    # -- life cycle

    def initialize(self, parameters: dict | None = None, inputs: dict | None = None,
                   start_time: float = 0.0, stop_time: float | None = None) -> "Film":
        """Sets up the experiment, the parameters and the inputs, and leaves initialization mode
        (the FMU builds its analysis there; a bad parameter raises :class:`FmuError`)."""
        self._call("fmi2SetupExperiment", c_int(0), c_double(0.0), c_double(start_time),
                   c_int(stop_time is not None), c_double(stop_time or 0.0))
        self._call("fmi2EnterInitializationMode")
        self.set({**(parameters or {}), **(inputs or {})})
        self._call("fmi2ExitInitializationMode")
        self.time = float(start_time)
        if "mu" in self._reached:
            self._reached["mu"] = self._set_inputs["mu"]
        self._surface(self._pending, self.strict)
        return self

    def _surface(self, into: list, strict: bool):
        """Emits each new warning-level FMU message of a kind not yet seen in this run as a
        :class:`SolverWarning` and appends it to ``into``; with ``strict`` raises
        :class:`SolverWarningError` instead."""
        new = self.messages[self._looked_at:]
        self._looked_at = len(self.messages)
        for status, _, text in new:
            if status != WARNING:
                continue
            kind = warning_kind(text)
            if kind in self._kinds:
                continue
            self._kinds.add(kind)
            into.append(text)
            if strict:
                raise SolverWarningError(text, self.time)
            warnings.warn(f"{self.name}: {text}", SolverWarning, stacklevel=4)

    def close(self) -> None:
        """Frees the saved states and the instance and removes the unpacked FMU."""
        if self.fmu is not None:
            for state, *_ in self._states:
                self.fmu.freeFMUstate(state)
            self._states.clear()
            if self.time is not None:
                self._raw("fmi2Terminate")
            self.fmu.freeInstance()
            self.fmu = None
            _ROUTES.pop(self.name, None)
            shutil.rmtree(self._unzipdir, ignore_errors=True)

    def __enter__(self) -> "Film":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # -- raw calls

    def _raw(self, function: str, *args) -> int:
        return self.fmu._functions[function](self.fmu.component, *args)

    def _call(self, function: str, *args) -> int:
        status = self._raw(function, *args)
        if status >= ERROR:
            raise FmuError(function, status, self.messages)
        return status

    # -- values

    def set(self, values: dict | None = None, **named: Any) -> None:
        """Sets variables by name (``film.set({"frame.dz": -0.1})``; names without dots may be
        given as keywords), each with the setter of its type; a refused value raises
        :class:`FmuError` with the FMU's message."""
        for name, value in {**(values or {}), **named}.items():
            v = self._variable(name)
            vr = [v.valueReference]
            if v.type == "Real":
                self._guard("fmi2SetReal", lambda: self.fmu.setReal(vr, [float(value)]))
                if name in self._set_inputs:
                    self._set_inputs[name] = float(value)
            elif v.type == "Integer":
                self._guard("fmi2SetInteger", lambda: self.fmu.setInteger(vr, [int(value)]))
            elif v.type == "Boolean":
                self._guard("fmi2SetBoolean", lambda: self.fmu.setBoolean(vr, [bool(value)]))
            else:
                self._guard("fmi2SetString", lambda: self.fmu.setString(vr, [str(value)]))

    def _guard(self, function, call):
        from fmpy.fmi1 import FMICallException

        try:
            return call()
        except FMICallException as e:
            raise FmuError(function, e.status, self.messages) from None

    def get(self, *names: str) -> Any:
        """Values by name: one name gives the value, several a list."""
        out = []
        for name in names:
            v = self._variable(name)
            getter = {"Real": self.fmu.getReal, "Integer": self.fmu.getInteger,
                      "Boolean": self.fmu.getBoolean, "String": self.fmu.getString}[v.type]
            value = self._guard(f"fmi2Get{v.type}", lambda: getter([v.valueReference])[0])
            out.append(value.decode() if isinstance(value, bytes) else value)
        return out[0] if len(names) == 1 else out

    def __getitem__(self, name: str):
        return self.get(name)

    def values(self, names=None) -> dict:
        """``{name: value}`` of ``names`` (default: every output)."""
        names = self.outputs if names is None else names
        return {n: self.get(n) for n in names}

    def _reader(self, names):
        """A function returning the values of ``names`` as floats (one getReal and one
        getInteger call)."""
        reals = [(k, self.variables[n].valueReference) for k, n in enumerate(names) if self.variables[n].type == "Real"]
        others = [(k, self.variables[n].valueReference) for k, n in enumerate(names) if self.variables[n].type in ("Integer", "Boolean")]

        def read():
            row = [float("nan")] * len(names)
            if reals:
                for (k, _), x in zip(reals, self.fmu.getReal([vr for _, vr in reals])):
                    row[k] = x
            if others:
                for (k, _), x in zip(others, self.fmu.getInteger([vr for _, vr in others])):
                    row[k] = float(x)
            return row

        return read

    def report(self, results: Results, path: str | os.PathLike, line_reactions: dict | None = None) -> Path:
        """Writes the run report of ``results`` (from :meth:`run`) to ``path``: the model from the
        FMU's parameters, the FMU's warnings from its log, and ``line_reactions`` when given
        (:func:`membrane_contact.report.line_reactions` of a film VTK file); returns the path."""
        params = {n: self.get(n) for n in self.parameters if self.variables[n].type in ("Real", "Integer", "String")
                  and not n.endswith((".kn", ".ks"))}
        return results.report(path, title=self.md.modelName, variables=params, messages=self.messages,
                              line_reactions=line_reactions)

    # -- stepping

    def step(self, dt: float) -> int:
        """fmi2DoStep from the current time over ``dt``. Returns OK, WARNING (the step stands; the
        log says why the result is outside the model's assumptions) or DISCARD (refused: the FMU
        keeps its last converged state and the time does not advance); raises :class:`FmuError`
        on fmi2Error/fmi2Fatal."""
        if self.time is None:
            raise RuntimeError("initialize() the film before stepping it")
        status = self._raw("fmi2DoStep", c_double(self.time), c_double(dt), c_int(1))
        if status >= ERROR:
            raise FmuError("fmi2DoStep", status, self.messages)
        if status in (OK, WARNING):
            self.time += dt
            self._reached = dict(self._set_inputs)
        return status

    def save(self) -> Any:
        """The current state (fmi2GetFMUstate): give it to :meth:`restore` to roll back; it is
        freed by :meth:`free` or when the film closes."""
        state = self.fmu.getFMUstate()
        self._states.append((state, self.time, dict(self._reached), dict(self._set_inputs)))
        return state

    def restore(self, state: Any) -> None:
        """Rolls the instance back to ``state`` (its variables, time and analysis)."""
        for s, t, reached, set_inputs in self._states:
            if s is state:
                self.fmu.setFMUstate(state)
                self.time, self._reached, self._set_inputs = t, dict(reached), dict(set_inputs)
                return
        raise ValueError("not a state saved by this film (or already freed)")

    def free(self, state: Any) -> None:
        for k, (s, *_) in enumerate(self._states):
            if s is state:
                self.fmu.freeFMUstate(state)
                del self._states[k]
                return
        raise ValueError("not a state saved by this film (or already freed)")

    def serialize(self, state) -> bytes:
        """The bytes of a saved state (a later :meth:`deserialize` of this FMU reads them; another
        FMU refuses them)."""
        return bytes(self.fmu.serializeFMUstate(state))

    def deserialize(self, data: bytes, time: float, reached: dict | None = None):
        """A state from bytes, to :meth:`restore`; ``time``: the time it was saved at;
        ``reached``: the inputs reached then (default: the inputs set now), from which a refused
        first step after the restore is halved."""
        state = self._guard("fmi2DeSerializeFMUstate", lambda: self.fmu.deSerializeFMUstate(data))
        reached = {**self._set_inputs, **(reached or {})}
        self._states.append((state, time, reached, dict(reached)))
        return state

    def run(self, table, outputs: list[str] | None = None, max_halvings: int = 6, dt: float | None = None,
            rollback: bool | None = None, strict: bool | None = None, quiet: bool | None = None) -> Results:
        """Steps a staged load path. ``table``: a dict of columns, a list of row dicts, a numpy
        structured array or a pandas DataFrame, with a ``time`` column and columns named after
        inputs; each row's inputs are reached at its time (rows up to the film's current time
        are where it already is and are skipped; an input without a column keeps its value).
        ``dt``: the longest step; a longer row interval is split into equal steps with the
        inputs interpolated linearly over pseudo-time (default: one step per row).

        A refused step (fmi2Discard) is rolled back to the state saved just before it
        (fmi2GetFMUstate/fmi2SetFMUstate; ``rollback``: default when the FMU can get and set
        its state, else the FMU is trusted to keep its last converged state, as this one does)
        and retried as two halves with the inputs interpolated (:data:`HELD_INPUTS` keep the
        row's value), at most ``max_halvings`` deep; then :class:`StepRefused` naming the time
        and the FMU's log, the film at its last converged state. Initializes the film first
        (start time 0) if it is not. Returns the ``outputs`` (default: all) and the table's
        inputs at the start and after every step taken.

        The FMU's warnings: each distinct one (:func:`warning_kind`) of the run, those of the
        initialization included, is emitted once as a :class:`SolverWarning` and kept in
        ``Results.warnings``; a one-line summary is printed after the run (not with ``quiet``).
        ``strict`` (default: the film's) raises :class:`SolverWarningError` at the first one.
        ``strict`` and ``quiet`` default to the film's."""
        strict = self.strict if strict is None else strict
        quiet = self.quiet if quiet is None else quiet
        columns = _columns(table)
        if "time" not in columns:
            raise KeyError("the table needs a 'time' column")
        times = columns.pop("time")
        if np.any(np.diff(times) <= 0):
            raise ValueError("the table's times must increase")
        if dt is not None and not dt > 0:
            raise ValueError(f"dt = {dt} must be > 0")
        inputs = set(self.inputs)
        for name in columns:
            if name not in inputs:
                kind = self.variables[name].causality if name in self.variables else None
                what = f"a{'n' if kind and kind[0] in 'aeiou' else ''} {kind}" if kind else "not a variable"
                raise KeyError(f"column '{name}' is {what}, not an input; inputs: {', '.join(sorted(inputs))}")
            if not np.all(np.isfinite(columns[name])):
                raise ValueError(f"column '{name}' holds values that are not finite")
        self._kinds = set()
        pending, self._pending = self._pending, []
        if self.time is None:
            self.strict, saved = strict, self.strict
            try:
                self.initialize()
            finally:
                self.strict = saved
            pending += self._pending
            self._pending = []
        if rollback is None:
            rollback = bool(self.md.coSimulation.canGetAndSetFMUstate)
        names = self.outputs if outputs is None else list(outputs)
        results = Results(names, [g for g in self.gaps if f"{g}.slip" in names], list(columns))
        results.warnings = pending
        self._strict_run = strict
        read_outputs = self._reader(names)

        def read():
            return read_outputs(), [self._reached[n] for n in results.input_names]

        results._append(self.time, *read())
        current = {n: self._reached[n] for n in columns}
        checkpoint = fmi2FMUstate() if rollback else None
        try:
            for k, t in enumerate(times):
                if t <= self.time + 1e-12 * max(1.0, abs(t)):
                    continue
                target = {n: float(v[k]) for n, v in columns.items()}
                t0, n = self.time, 1
                if dt is not None:
                    n = max(1, int(np.ceil((t - t0) / dt * (1 - 1e-12))))
                start = current
                for j in range(1, n + 1):
                    f = j / n
                    tj = t if j == n else t0 + (t - t0) * f
                    vj = target if j == n else _between(start, target, f)
                    self._advance(self.time, tj, current, vj, 0, max_halvings, results, read, checkpoint)
                    current = vj
        finally:
            if checkpoint is not None and checkpoint.value:
                self._raw("fmi2FreeFMUstate", byref(checkpoint))
        if results.warnings and not quiet:
            more = f" and {len(results.warnings) - 1} more" if len(results.warnings) > 1 else ""
            print(f"{self.name}: {len(results.warnings)} solver warning(s) in this run (Results.warnings): "
                  f"{results.warnings[0]}{more}", file=sys.stderr)
        return results

    def _advance(self, t0, t1, v0, v1, depth, max_halvings, results, read, checkpoint):
        """Reaches the inputs ``v1`` at ``t1`` from ``v0`` at ``t0`` (the film's time), halving
        refused steps."""
        if checkpoint is not None:
            self._call("fmi2GetFMUstate", byref(checkpoint))
            set_before = dict(self._set_inputs)
        self.set(v1)
        status = self.step(t1 - t0)
        if status != DISCARD:
            results.steps += 1
            # Land exactly on the row's time (no drift from summing step sizes).
            self.time = t1
            results._append(t1, *read())
            self._surface(results.warnings, self._strict_run)
            return
        if checkpoint is not None:
            # FMI 2.0: after fmi2Discard the master restores a state before it steps again.
            self._call("fmi2SetFMUstate", checkpoint)
            self._set_inputs = set_before
            results.rollbacks += 1
        if depth >= max_halvings:
            self.set(v0)
            raise StepRefused(t0, t1, depth, self.messages)
        results.halvings += 1
        tm = 0.5 * (t0 + t1)
        vm = {n: v1[n] if n in HELD_INPUTS else 0.5 * (v0[n] + v1[n]) for n in v1}
        self._advance(t0, tm, v0, vm, depth + 1, max_halvings, results, read, checkpoint)
        self._advance(tm, t1, vm, v1, depth + 1, max_halvings, results, read, checkpoint)


def _between(v0: dict, v1: dict, f: float) -> dict:
    """Inputs a fraction ``f`` of the way from ``v0`` to ``v1``: linear, except the held inputs
    (the FMU applies them as they are over a step), which take ``v1``'s value."""
    return {n: v1[n] if n in HELD_INPUTS else v0[n] + f * (v1[n] - v0[n]) for n in v1}
