"""Studies: many FMU runs of one model over a design of inputs and parameters, on a Dask cluster
(issue 22).

A study is a base FMU, a load path (a table for :meth:`membrane_contact.Film.run`), a design
(one row of values per case, :func:`factorial`, :func:`latin_hypercube`, :func:`monte_carlo`,
:func:`read_table`) and the outputs to keep. Each case is one FMU instance on a worker of a
``dask.distributed`` cluster: a ``LocalCluster`` with one single-threaded worker process per
core by default, or any scheduler (an address or a scheduler file). The FMU travels as bytes
(or a path every worker can read): a worker needs this package and fmpy, no cargo and no
repository.

Each design variable names an FMU variable, whatever the model: a parameter (set before the
initialization, ``film.E``, ``archHeight``), an input (held over the whole path, ``mu``), or
``scale:<column>`` (the load path's column multiplied, ``scale:frame.dz``).

Results go to a directory as they come, one Parquet file per case (written whole, then renamed:
a killed study leaves no half file); run again on the same directory, a study runs only the
cases that have no valid file (:func:`check_case`: a damaged or foreign file is moved aside and
its case runs again, with a warning) and refuses a directory that holds another study. One
driver at a time: a driver holds an OS lock on the directory (:func:`driver_lock`). A case the FMU refuses
(a step refused after every halving, a parameter refused at initialization) is stored with the
FMU's message and the study goes on. :meth:`Study.run` returns an ``xarray.Dataset`` (one
variable per output over ``case × step``, the design as coordinates, ``status`` and ``message``
per case)::

    python -m membrane_contact.study examples/study_mu_prestress.toml

The spec file (TOML or YAML) is described in python/README.md.
"""

from __future__ import annotations

import argparse
import contextlib
import itertools
import json
import math
import os
import re
import socket
import sys
import time as _time
import warnings
from dataclasses import dataclass
from pathlib import Path
from statistics import NormalDist
from typing import Any, Iterator

import numpy as np

# Re-exported from the modules below this one (membrane_contact.study.Runner, .cluster,
# .apply_values, … keep working for user scripts).
from .cases import SCALE, apply_values, read_columns, read_path, simulate  # noqa: F401
from .cluster import FmuRef, Runner, call_with_fmu, cluster, local_fmu  # noqa: F401

#: FMU parameter holding the solver's thread count: each case runs single-threaded (one worker
#: per core does the parallel work), unless the study's parameters say otherwise.
THREADS_PARAMETER = "solver.threads"

# ---------------------------------------------------------------------------- distributions


@dataclass(frozen=True)
class Distribution:
    """A named distribution of one design variable, sampled through its inverse CDF
    (:meth:`ppf`) so that Monte-Carlo and Latin-hypercube designs share it:

    * ``uniform(low, high)``, ``loguniform(low, high)``;
    * ``normal(mean, sd)``;
    * ``lognormal(median, sigma)``: ``ln X`` normal with mean ``ln median`` and standard
      deviation ``sigma``;
    * ``triangular(low, mode, high)``."""

    kind: str
    args: tuple

    KINDS = {"uniform": ("low", "high"), "loguniform": ("low", "high"), "normal": ("mean", "sd"),
             "lognormal": ("median", "sigma"), "triangular": ("low", "mode", "high")}

    @classmethod
    def parse(cls, name: str, spec) -> "Distribution":
        """From ``{"dist": "lognormal", "median": 0.2, "sigma": 0.3}`` (or ``"distribution"``),
        or ``[low, high]`` for a uniform one; errors name the variable ``name``."""
        if isinstance(spec, Distribution):
            return spec
        if isinstance(spec, (list, tuple)) and len(spec) == 2:
            spec = {"dist": "uniform", "low": spec[0], "high": spec[1]}
        if not isinstance(spec, dict):
            raise ValueError(f"design variable '{name}': give a distribution as {{dist = ..., ...}} or [low, high], "
                             f"not {spec!r}")
        spec = dict(spec)
        kind = spec.pop("dist", spec.pop("distribution", None))
        if kind not in cls.KINDS:
            raise ValueError(f"design variable '{name}': distribution {kind!r} is not one of "
                             f"{', '.join(cls.KINDS)}")
        names = cls.KINDS[kind]
        if set(spec) != set(names):
            raise ValueError(f"design variable '{name}': a {kind} distribution takes {', '.join(names)}; "
                             f"given {', '.join(sorted(spec)) or 'nothing'}")
        args = tuple(float(spec[k]) for k in names)
        if not all(math.isfinite(a) for a in args):
            raise ValueError(f"design variable '{name}': {kind} parameters must be finite: {args}")
        ok = {"uniform": lambda lo, hi: lo < hi, "loguniform": lambda lo, hi: 0 < lo < hi,
              "normal": lambda m, s: s > 0, "lognormal": lambda m, s: m > 0 and s > 0,
              "triangular": lambda lo, mo, hi: lo <= mo <= hi and lo < hi}[kind]
        if not ok(*args):
            raise ValueError(f"design variable '{name}': invalid {kind} parameters "
                             f"{dict(zip(names, args))}")
        return cls(kind, args)

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """The values at the probabilities ``u`` (0 < u < 1)."""
        u = np.asarray(u, dtype=float)
        a = self.args
        if self.kind == "uniform":
            return a[0] + u * (a[1] - a[0])
        if self.kind == "loguniform":
            return np.exp(np.log(a[0]) + u * (np.log(a[1]) - np.log(a[0])))
        z = np.array([NormalDist().inv_cdf(float(p)) for p in u.ravel()]).reshape(u.shape)
        if self.kind == "normal":
            return a[0] + a[1] * z
        if self.kind == "lognormal":
            return a[0] * np.exp(a[1] * z)
        lo, mode, hi = a
        c = (mode - lo) / (hi - lo)
        return np.where(u < c, lo + np.sqrt(u * (hi - lo) * (mode - lo)),
                        hi - np.sqrt((1 - u) * (hi - lo) * (hi - mode)))


# ---------------------------------------------------------------------------- designs


def _column(name: str, values) -> np.ndarray:
    """A design column: float64 when numeric, else strings (``frictionLaw``)."""
    array = np.asarray(list(values))
    if array.dtype.kind in "iufb":
        return array.astype(float)
    return array.astype(str)


def factorial(factors: dict) -> dict[str, np.ndarray]:
    """Every combination of the factors' levels (``{"mu": [0.15, 0.3], "film.E": [...]}``), the
    last factor varying fastest."""
    if not factors:
        raise ValueError("a factorial design needs at least one factor")
    for name, levels in factors.items():
        if isinstance(levels, (str, bytes)) or not hasattr(levels, "__len__") or len(levels) == 0:
            raise ValueError(f"factor '{name}': give a non-empty list of levels")
    rows = list(itertools.product(*factors.values()))
    return {name: _column(name, [r[k] for r in rows]) for k, name in enumerate(factors)}


def _probabilities(n: int, k: int, rng, strata: bool) -> np.ndarray:
    if strata:  # one point in each of n equal strata per variable, strata shuffled per variable
        u = (np.arange(n)[:, None] + rng.random((n, k))) / n
        for j in range(k):
            u[:, j] = u[rng.permutation(n), j]
        return u
    return rng.random((n, k))


def _sampled(variables: dict, cases: int, seed: int, strata: bool) -> dict[str, np.ndarray]:
    if not variables:
        raise ValueError("a sampled design needs at least one variable")
    if not (isinstance(cases, int) and cases > 0):
        raise ValueError(f"cases = {cases!r}: give a positive number of cases")
    dists = {n: Distribution.parse(n, s) for n, s in variables.items()}
    rng = np.random.default_rng(seed)
    u = _probabilities(cases, len(dists), rng, strata)
    # Keep u strictly inside (0, 1): the inverse CDFs of normal laws are infinite at the ends.
    u = np.clip(u, np.finfo(float).tiny, 1 - np.finfo(float).eps)
    return {n: d.ppf(u[:, j]) for j, (n, d) in enumerate(dists.items())}


def latin_hypercube(variables: dict, cases: int, seed: int = 0) -> dict[str, np.ndarray]:
    """A Latin-hypercube sample of ``cases`` rows: each variable (a :class:`Distribution` spec or
    ``[low, high]``) has one value in each of ``cases`` equally probable strata; ``seed``
    makes it reproducible (numpy's PCG64)."""
    return _sampled(variables, cases, seed, True)


def monte_carlo(variables: dict, cases: int, seed: int = 0) -> dict[str, np.ndarray]:
    """``cases`` independent draws of each variable (a :class:`Distribution` spec or
    ``[low, high]``); ``seed`` makes it reproducible (numpy's PCG64)."""
    return _sampled(variables, cases, seed, False)


def read_table(path) -> dict[str, np.ndarray]:
    """A user's design table: a CSV with one column per design variable, one row per case
    (``#`` lines are comments)."""
    rows = read_columns(path, "design table")  # refuses a column named twice
    if not rows:
        raise ValueError(f"{path}: the design table has no rows")
    columns = {}
    for name in rows[0]:
        texts = [r[name] for r in rows]
        try:
            columns[name] = np.array([float(t) for t in texts])
        except ValueError:
            columns[name] = np.array(texts, dtype=str)
    return columns


def design_from_spec(spec: dict, base: Path = Path(".")) -> dict[str, np.ndarray]:
    """A design from the ``[design]`` table of a study spec: ``kind`` = ``factorial``
    (``factors``), ``lhs`` or ``montecarlo`` (``variables``, ``cases``, ``seed``) or ``table``
    (``csv``); ``same`` = ``{"film.prestressY": "film.prestressX"}`` gives a variable another's
    value in every case."""
    spec = dict(spec)
    kind = spec.pop("kind", None)
    same = spec.pop("same", {}) or {}
    if kind == "factorial":
        design = factorial(spec.pop("factors", {}))
    elif kind in ("lhs", "latin_hypercube", "montecarlo", "monte_carlo"):
        sample = latin_hypercube if kind in ("lhs", "latin_hypercube") else monte_carlo
        design = sample(spec.pop("variables", {}), spec.pop("cases", None), spec.pop("seed", 0))
    elif kind == "table":
        design = read_table(base / spec.pop("csv"))
    else:
        raise ValueError(f"design kind {kind!r}: use factorial, lhs, montecarlo or table")
    if spec:
        raise ValueError(f"design ({kind}): unknown keys {', '.join(sorted(spec))}")
    for target, source in same.items():
        if source not in design:
            raise ValueError(f"design: same.{target} = '{source}', which is not a design variable")
        design[target] = design[source].copy()
    return design


# ---------------------------------------------------------------------------- the FMU on workers


# ---------------------------------------------------------------------------- one case


def check_variables(fmu, design: dict, path: dict, parameters: dict, outputs: list[str]) -> dict[str, str]:
    """Refuses names the FMU does not have, naming them: design variables (a parameter, an
    input or ``scale:<column of the path>``), parameters, path columns (inputs) and outputs.
    Returns ``{variable: causality}``."""
    from fmpy import read_model_description

    md = read_model_description(str(fmu))
    causality = {v.name: v.causality for v in md.modelVariables}

    def refuse(what, name, allowed):
        raise KeyError(f"{what} '{name}' is not {allowed} of {md.modelName} "
                       f"({'a ' + causality[name] if name in causality else 'no such variable'})")

    if "time" not in path:
        raise KeyError("the load path needs a 'time' column")
    for name in path:
        if name != "time" and causality.get(name) != "input":
            refuse("path column", name, "an input")
    for name in design:
        if name.startswith(SCALE):
            if name[len(SCALE):] not in path:
                raise KeyError(f"design variable '{name}': the load path has no column '{name[len(SCALE):]}'")
        elif causality.get(name) not in ("parameter", "input"):
            refuse("design variable", name, "a parameter or an input")
    for name in parameters:
        if causality.get(name) != "parameter":
            refuse("parameter", name, "a parameter")
    for name in outputs:
        if causality.get(name) != "output":
            refuse("output", name, "an output")
    return causality


def run_case(fmu_path, case: int, variables: dict, path: dict, parameters: dict, outputs: list[str],
             causality: dict, max_halvings: int = 6, dt: float | None = None, run_log: str | None = None) -> dict:
    """One case on a worker: a fresh FMU instance initialized with the parameters and the
    case's values, stepped row by row along the path. Returns ``{"case", "status" ("ok",
    "refused": a step refused after every halving, "error": the FMU refused the case, e.g. a
    parameter at initialization), "message", "values" (steps × outputs, step 0 the initial
    state, NaN past a refusal), "halvings", "warnings", "seconds" (wall), "cpu_seconds" (this
    process's CPU time), "worker"}``."""
    from .film import FmuError, StepRefused

    started, cpu = _time.perf_counter(), _time.process_time()
    if run_log:
        with open(run_log, "a") as f:
            f.write(f"{case} start {socket.gethostname()}:{os.getpid()}\n")
    values = np.full((len(path["time"]) + 1, len(outputs)), np.nan)
    status, message, halvings, caught = "ok", "", 0, []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            values, halvings = simulate(fmu_path, variables, path, parameters, outputs, causality,
                                        max_halvings=max_halvings, dt=dt)
    except StepRefused as e:
        status, message, values, halvings = "refused", str(e), e.values, e.halvings
    except FmuError as e:
        status, message, values = "error", str(e), getattr(e, "values", values)
    except (ValueError, RuntimeError) as e:
        status, message, values = "error", f"{type(e).__name__}: {e}", getattr(e, "values", values)
    kinds = sorted({str(w.message) for w in caught or []})
    return {"case": case, "status": status, "message": message, "values": values, "halvings": halvings,
            "warnings": "\n".join(kinds), "seconds": _time.perf_counter() - started,
            "cpu_seconds": _time.process_time() - cpu,
            "worker": f"{socket.gethostname()}:{os.getpid()}"}


# ---------------------------------------------------------------------------- storage


def _case_file(directory: Path, case: int) -> Path:
    return directory / "cases" / f"case-{case:06d}.parquet"


def write_case(directory: Path, result: dict, outputs: list[str], times: np.ndarray):
    """Writes one case's result as a Parquet file (step, time and one column per output; the
    status, message and timing in the file's metadata), whole or not at all (rename)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    values = result["values"]
    columns = {"step": pa.array(np.arange(len(times), dtype=np.int64)), "time": pa.array(times)}
    columns.update({o: pa.array(values[:, j]) for j, o in enumerate(outputs)})
    meta = {k: json.dumps(result[k]) for k in ("case", "status", "message", "halvings", "warnings", "seconds",
                                                "cpu_seconds", "worker")}
    table = pa.table(columns).replace_schema_metadata({f"study.{k}": v for k, v in meta.items()})
    path = _case_file(directory, result["case"])
    tmp = path.with_suffix(".part")
    pq.write_table(table, tmp)
    os.replace(tmp, path)


def read_case(path: Path, outputs: list[str]) -> dict:
    """One stored case file's result (``values``, ``status``, ``message``, ``case``, …)."""
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    meta = {k.decode()[len("study."):]: json.loads(v) for k, v in (table.schema.metadata or {}).items()
            if k.decode().startswith("study.")}
    meta["values"] = np.stack([table.column(o).to_numpy() for o in outputs], axis=1)
    return meta


#: A case file's name: ``case-<id>.parquet``.
CASE_FILE = re.compile(r"case-(\d+)\.parquet")


class InvalidCase(ValueError):
    """A stored case file that cannot be this study's result of its case."""


def check_case(path: Path, outputs: list[str], steps: int | None = None) -> dict:
    """The stored result in ``path`` after checking it is one: a readable Parquet file whose
    recorded case id is the one in its name, with every output over ``steps`` steps (the path's
    rows + 1, when given) and a status. Raises :class:`InvalidCase` saying why not."""
    match = CASE_FILE.fullmatch(Path(path).name)
    if match is None:
        raise InvalidCase(f"{path.name}: not a case file name (case-<id>.parquet)")
    try:
        result = read_case(path, outputs)
    except Exception as e:  # truncated, empty, not Parquet, an output missing, metadata damaged
        raise InvalidCase(f"{path.name} cannot be read ({type(e).__name__}: {e})") from None
    if result.get("case") != int(match.group(1)):
        raise InvalidCase(f"{path.name} holds the result of case {result.get('case')!r}, not of case "
                          f"{int(match.group(1))}")
    missing = [k for k in ("status", "message", "halvings") if k not in result]
    if missing:
        raise InvalidCase(f"{path.name} has no {', '.join(missing)}")
    if steps is not None and result["values"].shape[0] != steps:
        raise InvalidCase(f"{path.name} has {result['values'].shape[0]} steps, the study {steps}")
    return result


def case_files(directory) -> dict[int, Path]:
    """``{case: path}`` of the files named like case files in ``directory/cases``."""
    files = {}
    for p in sorted((Path(directory) / "cases").glob("case-*.parquet")):
        match = CASE_FILE.fullmatch(p.name)
        if match is not None:
            files[int(match.group(1))] = p
    return files


def stored_results(directory: Path, outputs: list[str]) -> dict[int, dict]:
    """``{case: result}`` of every valid case file in ``directory`` (an invalid one, see
    :func:`check_case`, is left out with a warning: its case counts as not run)."""
    results = {}
    for case, p in case_files(directory).items():
        try:
            results[case] = check_case(p, outputs)
        except InvalidCase as e:
            warnings.warn(f"study: {e}: case {case} counts as not run", stacklevel=2)
    return results


# ---------------------------------------------------------------------------- one driver


class DirectoryLocked(RuntimeError):
    """Another driver runs a study in this directory."""


@contextlib.contextmanager
def driver_lock(directory) -> Iterator[Path]:
    """Holds an OS lock on the study directory's ``driver.lock`` while the block runs (one
    driver per directory: two would both run every case and delete each other's partly written
    files). The lock file records the holder's process id and host; a second driver gets
    :class:`DirectoryLocked` naming them. The lock is ``fcntl.flock`` (POSIX) or
    ``msvcrt.locking`` (Windows), released by the OS when the process dies, so a killed driver
    leaves no stale lock."""
    path = Path(directory) / "driver.lock"
    path.parent.mkdir(parents=True, exist_ok=True)
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        if not _try_lock(fd):
            with contextlib.suppress(OSError):
                os.lseek(fd, 0, os.SEEK_SET)
            holder = os.read(fd, 200).decode(errors="replace").strip() or "a process that has not written its id yet"
            raise DirectoryLocked(f"{directory} is in use by another study driver ({holder}): wait for it to "
                                  "end, or stop it; two drivers on one directory would both run every case")
        try:
            os.ftruncate(fd, 0)
            os.lseek(fd, 0, os.SEEK_SET)
            os.write(fd, f"process {os.getpid()} on {socket.gethostname()}\n".encode())
            yield path
        finally:
            _unlock(fd)
    finally:
        os.close(fd)


#: Windows locks a byte range; this one lies past the holder's line, which a second driver reads.
_LOCKED_BYTE = 4096


def _try_lock(fd: int) -> bool:
    try:
        import fcntl
    except ImportError:  # Windows
        import msvcrt

        os.lseek(fd, _LOCKED_BYTE, os.SEEK_SET)
        try:
            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
        except OSError:
            return False
        return True
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True


def _unlock(fd: int) -> None:
    try:
        import fcntl
    except ImportError:
        import msvcrt

        os.lseek(fd, _LOCKED_BYTE, os.SEEK_SET)
        msvcrt.locking(fd, msvcrt.LK_UNLCK, 1)
        return
    fcntl.flock(fd, fcntl.LOCK_UN)


def same_description(a, b) -> bool:
    """Two study descriptions (as JSON reads them) alike, NaN equal to NaN (a design may hold
    NaN, which JSON writes as ``NaN``; ``nan != nan`` would make a study differ from itself)."""
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_description(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(same_description(x, y) for x, y in zip(a, b))
    return a == b


# ---------------------------------------------------------------------------- progress


class Progress:
    """Cases done, failed and the time left, on stderr: one line rewritten in place on a
    terminal, else a plain line every tenth of the cases (and at the end)."""

    def __init__(self, total: int, already: int, stream=None, enabled: bool = True):
        self.total, self.already = total, already
        self.done = already
        self.failed = 0
        self.stream = stream or sys.stderr
        self.enabled = enabled
        self.tty = enabled and hasattr(self.stream, "isatty") and self.stream.isatty()
        self.started = _time.monotonic()
        self._every = max(1, (total - already) // 10)
        if enabled and already:
            print(f"study: {already} of {total} cases already stored, resuming", file=self.stream)

    def line(self) -> str:
        ran = self.done - self.already
        elapsed = _time.monotonic() - self.started
        left = self.total - self.done
        eta = f"{_clock(elapsed / ran * left)} left" if ran else "time left unknown"
        return (f"study: {self.done}/{self.total} cases done, {self.failed} failed, "
                f"{_clock(elapsed)} elapsed, {eta}")

    def update(self, ok: bool):
        self.done += 1
        self.failed += 0 if ok else 1
        if not self.enabled:
            return
        if self.tty:
            print("\r" + self.line() + "\033[K", end="", file=self.stream, flush=True)
        elif (self.done - self.already) % self._every == 0 or self.done == self.total:
            print(self.line(), file=self.stream, flush=True)

    def close(self):
        if self.enabled and self.tty:
            print(file=self.stream)


def _clock(seconds: float) -> str:
    seconds = int(round(seconds))
    return f"{seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


# ---------------------------------------------------------------------------- the study


def _plain(value):
    """A design value for JSON (exact floats, strings)."""
    if isinstance(value, np.ndarray):
        return [_plain(v) for v in value.tolist()]
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    return value


class Study:
    """A study of ``fmu`` (a path) over ``design`` (``{variable: values}``, one value per case),
    each case stepped along ``path`` (``{"time": [...], input: [...]}``) with the fixed
    ``parameters``, keeping ``outputs`` (default: every output) at each row of the path, in
    ``directory`` (one Parquet file per case; see the module's doc). ``max_halvings`` and ``dt``
    go to :meth:`Film.run`. The FMU's ``solver.threads`` is set to 1 unless ``parameters`` set
    it. ``run_log``: a file each worker appends ``<case> start <host>:<pid>`` to when it starts
    a case (a shared filesystem only; an audit of which case ran where)."""

    def __init__(self, fmu, design: dict, path: dict, outputs: list[str] | None = None,
                 parameters: dict | None = None, directory=None, max_halvings: int = 6,
                 dt: float | None = None, run_log=None):
        from fmpy import read_model_description

        from .fmu import find_fmu

        self.fmu = Path(find_fmu(fmu))
        self.design = {str(k): _column(k, v) for k, v in design.items()}
        lengths = {len(v) for v in self.design.values()}
        if len(lengths) != 1 or 0 in lengths:
            raise ValueError(f"the design's columns must have one value per case and the same length: "
                             f"{ {k: len(v) for k, v in self.design.items()} }")
        self.cases = lengths.pop()
        self.path = {str(k): np.asarray(v, dtype=float).ravel() for k, v in path.items()}
        times = self.path.get("time")
        if times is None or len(times) == 0 or np.any(np.diff(times) <= 0):
            raise ValueError("the load path needs a 'time' column of increasing values")
        md = read_model_description(str(self.fmu))
        self.outputs = list(outputs) if outputs else [v.name for v in md.modelVariables if v.causality == "output"]
        self.parameters = dict(parameters or {})
        self.causality = check_variables(self.fmu, self.design, self.path, self.parameters, self.outputs)
        if THREADS_PARAMETER in self.causality and THREADS_PARAMETER not in self.parameters \
                and THREADS_PARAMETER not in self.design:
            self.parameters[THREADS_PARAMETER] = 1
        self.max_halvings, self.dt = int(max_halvings), dt
        self.directory = Path(directory) if directory is not None else None
        self.run_log = str(run_log) if run_log else None
        self.times = np.concatenate([[0.0], self.path["time"]])

    # -- identity, for resuming

    def description(self) -> dict:
        """What defines the study's results: a directory holding another one is refused."""
        return {"fmu_sha256": FmuRef.of(self.fmu)[0].sha256, "fmu": self.fmu.name,
                "design": {k: _plain(v) for k, v in self.design.items()},
                "path": {k: _plain(v) for k, v in self.path.items()},
                "parameters": {k: _plain(v) for k, v in self.parameters.items()},
                "outputs": self.outputs, "max_halvings": self.max_halvings, "dt": self.dt}

    def _prepare_directory(self) -> set[int]:
        """Creates the directory or checks it holds this study; returns the cases stored. Run
        under :func:`driver_lock`. A stored case file that is not this study's result of its
        case (:func:`check_case`: unreadable, truncated, empty, another case's) is moved aside
        to ``case-<id>.parquet.invalid`` with a warning, and its case runs again."""
        d = self.directory
        (d / "cases").mkdir(parents=True, exist_ok=True)
        described = d / "study.json"
        mine = self.description()
        if described.is_file():
            theirs = json.loads(described.read_text())
            differ = [k for k in mine if not same_description(theirs.get(k), json.loads(json.dumps(mine[k])))]
            if differ:
                raise ValueError(f"{d} holds another study (its {', '.join(differ)} differ{'s' if len(differ) == 1 else ''}): "
                                 "give another directory, or delete this one to start again")
        else:
            tmp = described.with_suffix(".part")
            tmp.write_text(json.dumps(mine, indent=1))
            os.replace(tmp, described)
        for stale in (d / "cases").glob("*.part"):
            stale.unlink()
        stored = set()
        for case, path in case_files(d).items():
            try:
                if case >= self.cases:
                    raise InvalidCase(f"{path.name}: the study has cases 0 to {self.cases - 1}")
                check_case(path, self.outputs, len(self.times))
            except InvalidCase as e:
                warnings.warn(f"study: {e}: moved aside to {path.name}.invalid, case {case} runs again",
                              stacklevel=3)
                os.replace(path, path.with_name(path.name + ".invalid"))
                continue
            stored.add(case)
        return stored

    def cases_to_run(self, stored: set[int]) -> list[int]:
        """The cases without a stored result, in order: every id of ``range(cases)`` not in
        ``stored``, wherever the gaps among the stored ids lie."""
        return [k for k in range(self.cases) if k not in stored]

    # -- running

    def case_arguments(self, case: int) -> tuple:
        variables = {k: _plain(v[case]) for k, v in self.design.items()}
        return (case, variables, self.path, self.parameters, self.outputs, self.causality, self.max_halvings,
                self.dt, self.run_log)

    def run(self, client=None, *, scheduler: str | None = None, workers: int | None = None,
            progress: bool = True, shared_fmu: bool = False) -> Any:
        """Runs the cases not yet stored (all of them without a directory) and returns the
        dataset of every case (:meth:`dataset`). ``client``: a ``dask.distributed.Client``;
        else one to ``scheduler`` (an address or a scheduler file), else a ``LocalCluster`` of
        ``workers`` single-threaded processes (default: one per core), closed at the end.
        ``shared_fmu``: workers read the FMU at its path instead of receiving its bytes. With a
        directory, the driver holds its lock (:func:`driver_lock`) throughout: a second driver
        on the same directory is refused (:class:`DirectoryLocked`)."""
        if self.directory is None:
            return self._run(set(), client, scheduler, workers, progress, shared_fmu)
        with driver_lock(self.directory):
            return self._run(self._prepare_directory(), client, scheduler, workers, progress, shared_fmu)

    def _run(self, stored: set[int], client, scheduler, workers, progress, shared_fmu):
        from dask.distributed import as_completed

        todo = self.cases_to_run(stored)
        if not todo:
            if progress:
                print(f"study: all {self.cases} cases already stored in {self.directory}", file=sys.stderr)
            return self.dataset()
        if client is None:
            with cluster(scheduler, workers) as client:
                return self._run(stored, client, scheduler, workers, progress, shared_fmu)
        self._results = {}
        bar = Progress(self.cases, len(stored), enabled=progress)
        runner = Runner(client, self.fmu, shared=shared_fmu)
        futures = [runner.submit(run_case, *self.case_arguments(k)) for k in todo]
        log = open(self.directory / "log.jsonl", "a") if self.directory is not None else None
        try:
            for future in as_completed(futures):
                result = future.result()
                if log is not None:
                    write_case(self.directory, result, self.outputs, self.times)
                    log.write(json.dumps({k: result[k] for k in ("case", "status", "seconds", "worker")}) + "\n")
                    log.flush()
                else:
                    self._results[result["case"]] = result
                bar.update(result["status"] == "ok")
                future.release()
        finally:
            bar.close()
            if log is not None:
                log.close()
        return self.dataset()

    # -- results

    def results(self) -> dict[int, dict]:
        """Every stored case's result (``values``, ``status``, ``message``, ``seconds``, …)."""
        if self.directory is None:
            return dict(getattr(self, "_results", {}))
        return stored_results(self.directory, self.outputs)

    def dataset(self) -> Any:
        """The results as an ``xarray.Dataset``: one variable per output over ``(case, step)``
        (step 0: the initialized state; step k: row k of the path; NaN where a refused case did
        not get), the design's variables and ``time`` as coordinates, ``status`` ("ok",
        "refused", "error", "" for a case not run yet), ``message`` (the FMU's reason) and
        ``halvings`` per case. ``ds[outputs].to_array("output")`` gives one array
        ``output × case × step``."""
        return _assemble(self.description(), self.results())

    def timings(self) -> dict[int, float]:
        """Seconds each stored case took on its worker."""
        return {k: r["seconds"] for k, r in self.results().items()}


def _assemble(description: dict, results: dict[int, dict]):
    """The dataset of a study (:meth:`Study.dataset`) from its description and results."""
    import xarray as xr

    design = {k: _column(k, v) for k, v in description["design"].items()}
    outputs = description["outputs"]
    times = np.concatenate([[0.0], np.asarray(description["path"]["time"], dtype=float)])
    cases = len(next(iter(design.values())))
    values = np.full((cases, len(times), len(outputs)), np.nan)
    status = np.full(cases, "", dtype=object)
    message = np.full(cases, "", dtype=object)
    halvings = np.zeros(cases, dtype=np.int64)
    for k, r in results.items():
        values[k], status[k], message[k], halvings[k] = r["values"], r["status"], r["message"], r["halvings"]
    data = {o: (("case", "step"), values[:, :, j]) for j, o in enumerate(outputs)}
    data.update(status=("case", status.astype(str)), message=("case", message.astype(str)),
                halvings=("case", halvings))
    coords = {"case": np.arange(cases), "step": np.arange(len(times)), "time": ("step", times)}
    coords.update({k: ("case", v) for k, v in design.items()})
    return xr.Dataset(data, coords=coords, attrs={"fmu": description["fmu"],
                                                  "parameters": json.dumps(description["parameters"])})


def largest_slips(ds: Any, supports: dict[str, list[str]] | None = None, component: str = "slip") -> Any:
    """The largest slip per support in each case of a study's dataset (:meth:`Study.dataset`):
    an ``xarray.Dataset`` over ``case`` with, per support, its signed largest slip (m: the
    largest ``|slip|`` over its gaps and the steps) and ``<support>.where`` (that gap).
    ``supports``: ``{support: [gap, ...]}``; default: the gaps among the outputs
    (``<gap>.<component>``) grouped by name without the trailing number (``N1`` … ``N13`` →
    ``N``), as :meth:`Results.largest_slips <membrane_contact.Results.largest_slips>`."""
    import xarray as xr

    suffix = f".{component}"
    if supports is None:
        supports = {}
        for name in ds.data_vars:
            gap = str(name)[: -len(suffix)] if str(name).endswith(suffix) else None
            if gap and re.fullmatch(r"\w+", gap):
                supports.setdefault(re.sub(r"\d+$", "", gap) or gap, []).append(gap)
    data = {}
    for support, gaps in supports.items():
        values = np.stack([ds[f"{g}{suffix}"].values for g in gaps], axis=-1)  # case × step × gap
        flat = np.abs(np.nan_to_num(values, nan=0.0)).reshape(values.shape[0], -1)
        k = np.argmax(flat, axis=1)
        best = values.reshape(values.shape[0], -1)[np.arange(values.shape[0]), k]
        data[support] = ("case", best)
        data[f"{support}.where"] = ("case", np.asarray([gaps[j % len(gaps)] for j in k]))
    return xr.Dataset(data, coords={"case": ds.case.values})


def open_study(directory: str | os.PathLike) -> Any:
    """The dataset of the study stored in ``directory`` (its ``study.json`` and the cases stored
    so far), without the FMU."""
    directory = Path(directory)
    description = json.loads((directory / "study.json").read_text())
    return _assemble(description, stored_results(directory, description["outputs"]))


# ---------------------------------------------------------------------------- spec files


def load_spec(path) -> dict:
    """A study spec from a TOML (``.toml``) or YAML (``.yaml``/``.yml``) file."""
    path = Path(path)
    text = path.read_text()
    if path.suffix in (".yaml", ".yml"):
        import yaml

        spec = yaml.safe_load(text)
    else:
        try:
            import tomllib
        except ImportError:  # Python < 3.11
            import tomli as tomllib

        spec = tomllib.loads(text)
    if not isinstance(spec, dict):
        raise ValueError(f"{path}: a study spec is a table of keys")
    return spec


def path_from_spec(spec: dict, base: Path) -> dict:
    """The load path of a spec's ``[path]``: ``csv = "path.csv"``, or columns (``time = [...]``,
    ``"frame.dz" = [...]``), or ``steps = N`` with ``to = {"frame.dz" = -0.15}`` (each input
    ramped linearly from 0, time k/N)."""
    spec = dict(spec)
    if "csv" in spec:
        return read_path(base / spec["csv"])
    if "steps" in spec:
        n = int(spec["steps"])
        if n < 1:
            raise ValueError(f"path.steps = {n}: give at least one step")
        f = np.arange(1, n + 1) / n
        return {"time": f, **{k: float(v) * f for k, v in (spec.get("to") or {}).items()}}
    return spec


def fmu_from_spec(spec: dict, base: Path, out: Path) -> Path:
    """The spec's FMU: ``fmu`` (a path), or ``model`` (a model file packed with fmu-pack into
    ``out``), or ``mesh`` + ``mapping`` (imported, then packed)."""
    from .fmu import build_fmu, find_fmu

    if "fmu" in spec:
        return find_fmu(base / spec["fmu"])
    if "model" in spec:
        return build_fmu(base / spec["model"], out_dir=out / "fmu")
    if "mesh" in spec:
        from .mesh import import_mesh

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = import_mesh(base / spec["mesh"], base / spec["mapping"])
        return build_fmu(model, out_dir=out / "fmu")
    return find_fmu(None)


def quantile_table(ds, outputs: list[str], quantiles: list[float], step: int = -1) -> str:
    """Quantiles of ``outputs`` at ``step`` over the cases that ran through (status ok), as
    Markdown rows."""
    ok = ds.status == "ok"
    lines = ["| output | " + " | ".join(f"{100 * q:g} %" for q in quantiles) + " | cases |",
             "|---|" + "---|" * (len(quantiles) + 1)]
    for o in outputs:
        values = ds[o].isel(step=step).where(ok, drop=True).values
        qs = np.quantile(values, quantiles) if len(values) else [np.nan] * len(quantiles)
        lines.append(f"| {o} | " + " | ".join(f"{q:.6g}" for q in qs) + f" | {len(values)} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m membrane_contact.study",
                                description="Runs a study (a design of FMU runs) on a Dask cluster.")
    p.add_argument("spec", help="the study spec, TOML or YAML (python/README.md)")
    p.add_argument("--out", help="the results directory (default: the spec's 'out')")
    p.add_argument("--scheduler", help="a Dask scheduler address or scheduler file (default: a LocalCluster)")
    p.add_argument("--workers", type=int, help="LocalCluster worker processes (default: one per core)")
    p.add_argument("--shared-fmu", action="store_true",
                   help="workers read the FMU at its path (a shared filesystem) instead of receiving its bytes")
    p.add_argument("--no-progress", action="store_true", help="no progress lines")
    a = p.parse_args(argv)
    try:
        spec = load_spec(a.spec)
        base = Path(a.spec).resolve().parent
        known = {"fmu", "model", "mesh", "mapping", "out", "outputs", "parameters", "path", "design",
                 "max_halvings", "dt", "report", "description"}
        unknown = sorted(set(spec) - known)
        if unknown:
            raise ValueError(f"{a.spec}: unknown keys {', '.join(unknown)}")
        out = (Path(a.out) if a.out else base / spec.get("out", Path(a.spec).stem)).resolve()
        out.mkdir(parents=True, exist_ok=True)
        study = Study(fmu_from_spec(spec, base, out), design_from_spec(spec.get("design") or {}, base),
                      path_from_spec(spec.get("path") or {}, base), spec.get("outputs"),
                      spec.get("parameters"), out, spec.get("max_halvings", 6), spec.get("dt"))
    except (KeyError, ValueError, FileNotFoundError, RuntimeError) as e:
        print(f"error: {e.args[0] if isinstance(e, KeyError) and e.args else e}", file=sys.stderr)
        return 2
    ds = study.run(scheduler=a.scheduler, workers=a.workers, progress=not a.no_progress, shared_fmu=a.shared_fmu)
    failed = int((ds.status != "ok").sum())
    print(f"{study.cases} cases in {out}: {study.cases - failed} ran through, {failed} refused")
    for k in np.flatnonzero(ds.status.values != "ok")[:10]:
        print(f"  case {k} ({', '.join(f'{n}={ds[n].values[k]}' for n in study.design)}): {ds.message.values[k]}")
    report = spec.get("report")
    if report:
        table = quantile_table(ds, report.get("outputs", study.outputs), report.get("quantiles", [0.05, 0.5, 0.95]),
                               report.get("step", -1))
        (out / "quantiles.md").write_text(table + "\n")
        print(table)
    return 0


if __name__ == "__main__":
    # Run as a script, this file is __main__: the functions the workers run must be pickled as
    # membrane_contact.study's, which they import.
    from membrane_contact.study import main as _main

    sys.exit(_main())
