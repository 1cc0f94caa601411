"""Which unknowns explain what was measured: least-squares fit through the FMU (issue 10 item 4).

Given measured outputs at the end of a load path (slips at observed points, a reaction, a sag),
:func:`fit` finds the unknowns a user names — the friction coefficient ``mu``, any FMU parameter
(``film.E``, ``archHeight``, …), or a scale on a column of the load path (``scale:frame.dz``: the
measured boundary movement known up to a factor) — by Levenberg–Marquardt on the residuals
``(model − measured) / scale``, each model evaluation a fresh run of the FMU through
:class:`membrane_contact.Film`. The Jacobian is taken by central differences of those runs.

Each measurement has a scale in its own unit (its measurement uncertainty, say 0.1 mm for a
slip read off a gauge, 1 N for a load cell), so that the misfit is dimensionless and a slip
and a reaction can be fitted together; without scales, every measured output must have the
same unit (the scale is then 1 in that unit), else the fit is refused naming the units.

It reports the fitted values, their sensitivities (the Jacobian ``∂output/∂unknown`` at the
fit), standard errors from the residual scatter (``s²(JᵀJ)⁻¹``, when there are more
measurements than unknowns) and the remaining misfit per measurement.

    python -m membrane_contact.inverse --fmu target/fmu/ParallelArch.fmu \\
        --measured table1_300.csv --unknown mu=0.2:0:1 --path path.csv --parameter archHeight=0.3

The measured CSV has the columns ``output,value`` and optionally ``scale``.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import sys
from dataclasses import dataclass, field

import numpy as np

from fmpy import read_model_description

from .cases import SCALE, read_path, simulate  # noqa: F401  (read_path: re-exported)
from .fmu import find_fmu


@dataclass
class Unknown:
    """A quantity to fit: ``name`` (an input such as ``mu``, a parameter, or ``scale:<column>``),
    its start value and bounds."""

    name: str
    start: float
    lower: float = -np.inf
    upper: float = np.inf

    @classmethod
    def parse(cls, text: str) -> "Unknown":
        """``name=start[:lower:upper]``."""
        name, _, rest = text.partition("=")
        parts = [float(p) for p in rest.split(":")] if rest else []
        if not name or len(parts) not in (1, 3):
            raise ValueError(f"unknown '{text}': write name=start or name=start:lower:upper")
        return cls(name, *parts)


@dataclass
class FitResult:
    names: list[str]
    values: np.ndarray
    #: ∂output/∂unknown at the fit: one row per measurement, one column per unknown.
    sensitivities: np.ndarray
    standard_errors: np.ndarray
    measured: dict[str, float]
    fitted: dict[str, float]
    evaluations: int
    iterations: int
    converged: bool
    history: list[tuple[list[float], float]] = field(default_factory=list)
    #: The measurement scale of each output (its unit), dividing its residual.
    scales: dict[str, float] = field(default_factory=dict)

    @property
    def misfit(self) -> dict[str, float]:
        """``model − measured`` per measurement, in the output's unit."""
        return {k: self.fitted[k] - v for k, v in self.measured.items()}

    @property
    def scaled_misfit(self) -> dict[str, float]:
        """``(model − measured) / scale`` per measurement: dimensionless."""
        return {k: m / self.scales.get(k, 1.0) for k, m in self.misfit.items()}

    @property
    def rms(self) -> float:
        """RMS of the scaled misfit (dimensionless: in measurement scales)."""
        return float(np.sqrt(np.mean([m * m for m in self.scaled_misfit.values()])))

    def report(self) -> str:
        lines = ["unknown          value      std. error"]
        for n, v, e in zip(self.names, self.values, self.standard_errors):
            lines.append(f"{n:<14} {v:>10.5g}   {e:>10.3g}")
        lines.append("\nmeasurement            measured       fitted      misfit       scale   " +
                     "   ".join(f"d/d{n}" for n in self.names))
        for i, (k, v) in enumerate(self.measured.items()):
            sens = "   ".join(f"{s:>10.4g}" for s in self.sensitivities[i])
            lines.append(f"{k:<20} {v:>11.5g} {self.fitted[k]:>12.5g} {self.fitted[k] - v:>11.4g} "
                         f"{self.scales.get(k, 1.0):>11.4g}   {sens}")
        lines.append(f"\nRMS misfit {self.rms:.4g} (in measurement scales) after {self.iterations} iterations, "
                     f"{self.evaluations} FMU runs{'' if self.converged else ' (not converged)'}")
        return "\n".join(lines)


def read_measurements(path) -> dict[str, float]:
    """A CSV with columns ``output,value`` (the FMU output name and the measured value, SI)."""
    with open(path, newline="") as f:
        rows = [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]
    if not rows or not {"output", "value"} <= set(rows[0]):
        raise ValueError(f"{path}: needs the columns output,value")
    return {r["output"].strip(): float(r["value"]) for r in rows}


def read_scales(path) -> dict[str, float]:
    """The optional ``scale`` column of a measured CSV (empty when it has none)."""
    with open(path, newline="") as f:
        rows = [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]
    return {r["output"].strip(): float(r["scale"]) for r in rows if (r.get("scale") or "").strip()}


def measurement_scales(fmu, outputs: list[str], scales: dict[str, float] | None) -> dict[str, float]:
    """Every output's scale: the given one (> 0), else 1 in its unit when all the outputs
    without a scale share one unit; different units without scales are refused."""
    scales = dict(scales or {})
    for name, value in scales.items():
        if name not in outputs:
            raise KeyError(f"scale given for '{name}', which is not a measured output")
        if not (value > 0 and np.isfinite(value)):
            raise ValueError(f"scale of '{name}' is {value}: it must be > 0 (a measurement uncertainty)")
    missing = [o for o in outputs if o not in scales]
    if missing:
        variables = {v.name: v for v in read_model_description(str(find_fmu(fmu))).modelVariables}
        units = {o: variables[o].unit if o in variables else None for o in missing}
        if len(set(units.values())) > 1:
            listed = ", ".join(f"{o} ({u or 'no unit'})" for o, u in units.items())
            raise ValueError(f"the measured outputs have different units: {listed}; give each a "
                             "measurement scale in its unit (scales=..., or a 'scale' column)")
        scales.update({o: 1.0 for o in missing})
    return scales


def _run(fmu, path: dict, parameters: dict | None, unknowns: list[Unknown], values, outputs: list[str]) -> np.ndarray:
    """The outputs at the end of ``path`` with the unknowns at ``values`` (one case:
    :func:`membrane_contact.cases.simulate`)."""

    def check(causality):
        for u in unknowns:
            if u.name.startswith(SCALE):
                if u.name[len(SCALE):] not in path:
                    raise KeyError(f"'{u.name}': the path has no column '{u.name[len(SCALE):]}'")
            elif causality.get(u.name) not in ("input", "parameter"):
                raise KeyError(f"unknown '{u.name}' is neither an input, a parameter nor scale:<column>")

    table, _ = simulate(fmu, {u.name: x for u, x in zip(unknowns, values)}, path, parameters or {}, outputs,
                        check=check)
    return np.array(table[-1], dtype=float)


def fit(fmu, measured: dict[str, float], unknowns: list[Unknown], path: dict, parameters: dict | None = None,
        max_iterations: int = 30, tolerance: float = 1e-8, relative_step: float = 1e-4,
        scales: dict[str, float] | None = None, client=None) -> FitResult:
    """Levenberg–Marquardt on ``(model(unknowns) − measured) / scale`` over the outputs named in
    ``measured`` at the end of the staged ``path`` (a table for :meth:`Film.run`); ``scales``:
    each output's measurement scale in its unit (see :func:`measurement_scales`). ``client``: a
    ``dask.distributed.Client``; the sensitivity runs of each Jacobian (two per unknown) then run
    in parallel on its workers (:class:`membrane_contact.cluster.Runner`: the FMU travels to them),
    each the same run as in series, so the fit is the same."""
    outputs = list(measured)
    scales = measurement_scales(fmu, outputs, scales)
    w = np.array([1.0 / scales[o] for o in outputs])
    y = np.array([measured[o] for o in outputs], dtype=float)
    x = np.array([u.start for u in unknowns], dtype=float)
    lo = np.array([u.lower for u in unknowns])
    hi = np.array([u.upper for u in unknowns])
    evaluations = 0

    runner = None
    if client is not None:
        from .cluster import Runner

        runner = Runner(client, find_fmu(fmu))

    def models(points):
        """The outputs divided by their scales at each of ``points``: in turn, or at once on the
        cluster."""
        nonlocal evaluations
        evaluations += len(points)
        if runner is None:
            runs = [_run(fmu, path, parameters, unknowns, v, outputs) for v in points]
        else:
            runs = runner.map(_run, [(path, parameters, unknowns, v, outputs) for v in points])
        return [w * r for r in runs]

    def model(v):
        return models([v])[0]

    y = w * y

    def jacobian(v):
        pairs = []
        for j in range(len(v)):
            h = relative_step * max(abs(v[j]), 1e-3)
            plus, minus = v.copy(), v.copy()
            plus[j] = min(v[j] + h, hi[j])
            minus[j] = max(v[j] - h, lo[j])
            pairs += [plus, minus]
        runs = models(pairs)
        cols = [(runs[2 * j] - runs[2 * j + 1]) / (pairs[2 * j][j] - pairs[2 * j + 1][j]) for j in range(len(v))]
        return np.stack(cols, axis=1)

    f = model(x) - y
    cost = float(f @ f)
    damping = 1e-3
    history = [(x.tolist(), cost)]
    converged = False
    iterations = 0
    for iterations in range(1, max_iterations + 1):
        jac = jacobian(x)
        g = jac.T @ f
        a = jac.T @ jac
        while True:
            step = np.linalg.solve(a + damping * np.diag(np.diag(a) + 1e-30), -g)
            trial = np.clip(x + step, lo, hi)
            ft = model(trial) - y
            trial_cost = float(ft @ ft)
            if trial_cost < cost or damping > 1e8:
                break
            damping *= 10.0
        if trial_cost >= cost:
            converged = True  # no descent left: a minimum within the bounds
            break
        moved = np.max(np.abs(trial - x) / np.maximum(np.abs(x), 1e-12))
        x, f, cost = trial, ft, trial_cost
        history.append((x.tolist(), cost))
        damping = max(damping / 10.0, 1e-12)
        if moved < tolerance or cost < 1e-30:
            converged = True
            break
    jac = jacobian(x)
    m, n = jac.shape
    try:
        cov = np.linalg.inv(jac.T @ jac) * (cost / (m - n) if m > n else np.nan)
        errors = np.sqrt(np.abs(np.diag(cov)))
    except np.linalg.LinAlgError:
        errors = np.full(n, np.inf)
    fitted = dict(zip(outputs, ((f + y) / w).tolist()))
    return FitResult([u.name for u in unknowns], x, jac / w[:, None], errors, dict(measured), fitted,
                     evaluations, iterations, converged, history, scales)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fmu", required=True)
    p.add_argument("--measured", required=True,
                   help="CSV with columns output,value (SI units) and optionally scale (the measurement scale)")
    p.add_argument("--path", required=True, help="load path CSV: time and input columns")
    p.add_argument("--unknown", action="append", required=True, help="name=start[:lower:upper], repeatable")
    p.add_argument("--parameter", action="append", default=[], help="name=value, set at initialization")
    p.add_argument("--scheduler", help="run the sensitivity runs on this Dask scheduler (address or scheduler file)")
    p.add_argument("--workers", type=int, help="run the sensitivity runs on a Dask LocalCluster of N processes")
    a = p.parse_args(argv)
    params = {}
    for text in a.parameter:
        k, _, v = text.partition("=")
        params[k] = float(v)
    try:
        with contextlib.ExitStack() as stack:
            client = None
            if a.scheduler or a.workers:
                from .cluster import cluster

                client = stack.enter_context(cluster(a.scheduler, a.workers))
            result = fit(a.fmu, read_measurements(a.measured), [Unknown.parse(u) for u in a.unknown],
                         read_path(a.path), params, scales=read_scales(a.measured), client=client)
    except (KeyError, ValueError) as e:
        print(f"error: {e.args[0] if e.args else e}", file=sys.stderr)
        return 2
    print(result.report())
    return 0 if result.converged else 1


if __name__ == "__main__":
    sys.exit(main())
