"""One case: an FMU run of a load path with some values of its inputs and parameters, shared by
:mod:`membrane_contact.study` (a case of a design) and :mod:`membrane_contact.inverse` (a model
evaluation of a fit), below both (neither imports the other for it).

* :func:`read_path` — a load path table from a CSV file;
* :func:`apply_values` — where each value goes: an input held over the path, a column of the
  path scaled (``scale:<column>``), or a parameter;
* :func:`simulate` — a fresh FMU instance initialized with the parameters and the values,
  stepped row by row along the path: the outputs at each row.
"""

from __future__ import annotations

import csv
from typing import Callable, Mapping, Sequence

import numpy as np

#: Prefix of a design variable (or an unknown of a fit) that multiplies a column of the load path.
SCALE = "scale:"


def read_columns(path, what: str = "table") -> list[dict[str, str]]:
    """The rows of a CSV file (``#`` lines are comments) as dicts of stripped names; refuses a
    header that names a column twice, naming it (csv.DictReader would keep the last one)."""
    with open(path, newline="", encoding="utf-8-sig") as f:
        lines = [line for line in f if not line.lstrip().startswith("#")]
    header = next(csv.reader(lines[:1]), [])
    names = [h.strip() for h in header]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ValueError(f"{path}: the {what} names the column{'s' if len(twice) > 1 else ''} "
                         f"{', '.join(repr(n) for n in twice)} more than once")
    rows = []
    for k, row in enumerate(csv.reader(lines[1:]), start=2):
        if not row:
            continue
        if len(row) != len(names):
            raise ValueError(f"{path}: row {k} of the {what} (comments not counted) has {len(row)} cells, "
                             f"the header {len(names)}")
        rows.append({n: cell.strip() for n, cell in zip(names, row)})
    return rows


def read_path(path) -> dict[str, list[float]]:
    """A load path table (CSV with a ``time`` column and input columns)."""
    rows = read_columns(path, "load path")
    if not rows:
        raise ValueError(f"{path}: the load path has no rows")
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def apply_values(variables: Mapping, path: Mapping, parameters: Mapping,
                 names: Mapping[str, str]) -> tuple[dict[str, np.ndarray], dict]:
    """Where each design value goes: the table ``path`` (an input held over the path, or a
    column scaled by ``scale:<column>``) or the ``parameters``. ``names``: variable → causality.
    Returns the table and the parameters."""
    table = {k: np.asarray(v, dtype=float).copy() for k, v in path.items()}
    params = dict(parameters)
    for name, value in variables.items():
        if name.startswith(SCALE):
            table[name[len(SCALE):]] = table[name[len(SCALE):]] * float(value)
        elif names.get(name) == "input":
            table[name] = np.full(len(table["time"]), float(value))
        else:
            params[name] = value
    return table, params


def simulate(fmu, variables: Mapping, path: Mapping, parameters: Mapping, outputs: Sequence[str],
             causality: Mapping[str, str] | None = None, *, max_halvings: int = 6, dt: float | None = None,
             check: Callable[[dict], None] | None = None, **film_options) -> tuple[np.ndarray, int]:
    """The one way a case runs: a fresh FMU instance of ``fmu`` initialized with ``parameters``
    and the ``variables`` that are parameters, stepped row by row along ``path`` (each row one
    :meth:`Film.run <membrane_contact.Film.run>` with ``max_halvings`` and ``dt``).
    ``causality``: variable → causality (default: the FMU's); ``check(causality)`` runs before
    the initialization (to refuse names). Returns ``(values, halvings)``: ``values`` is
    ``(rows + 1) × outputs``, row 0 the initialized state. A step refused after every halving
    raises :class:`~membrane_contact.StepRefused` (``values`` so far in its ``values``
    attribute), the FMU's refusal :class:`~membrane_contact.FmuError`."""
    from .film import Film, StepRefused

    with Film(fmu, **{"logging": False, "quiet": True, **film_options}) as film:
        if causality is None:
            causality = {n: v.causality for n, v in film.variables.items()}
        if check is not None:
            check(dict(causality))
        table, params = apply_values(variables, path, parameters, causality)
        times = table.pop("time")
        values = np.full((len(times) + 1, len(outputs)), np.nan)
        halvings = 0
        try:
            film.initialize(parameters=params)
            values[0] = [float(film.get(o)) for o in outputs]
            for k, t in enumerate(times):
                row = {"time": [t], **{n: [c[k]] for n, c in table.items()}}
                results = film.run(row, outputs=list(outputs), max_halvings=max_halvings, dt=dt)
                halvings += results.halvings
                values[k + 1] = [results[o][-1] for o in outputs]
        except StepRefused as e:
            e.values, e.halvings = values, halvings
            raise
        except Exception as e:
            e.values = values
            raise
    return values, halvings
