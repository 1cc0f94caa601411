"""A co-simulation master for the film and the structure that carries it (a jack, a winch, a
frame): per communication step it iterates the interface to convergence, rolling both FMUs back
to the step's start (fmi2GetFMUstate / fmi2SetFMUstate) before each new iteration.

The interface: the structure's displacement outputs drive the film's group inputs
(``dz → frame.dz``), the film's reactions drive the structure's force inputs
(``frame.Rz → force``). The unknown of a step is the film's input ``x``; one iteration steps the
film to ``x`` (giving the reactions ``y``), then the structure under ``y`` (giving ``x̃``); the
residual is ``r = x̃ − x``. Schemes (``scheme=``):

* ``"jacobi"``: explicit, no iteration: both FMUs step with the other's outputs of the last
  communication point (what fmpy's and libcosim's SSP runs do);
* ``"staggered"``: explicit Gauss–Seidel: the structure steps first, the film follows;
* ``"gauss-seidel"``: iterated, ``x ← x + ω r`` with a constant ``omega`` (1: plain);
* ``"aitken"``: Gauss–Seidel with Aitken's dynamic relaxation (Küttler & Wall 2008), the first
  ω of a step the last one of the previous step (at most ``omega``);
* ``"iqn-ils"``: interface quasi-Newton with an inverse Jacobian from least squares over the
  iteration's differences of residuals and of ``x̃`` (Degroote, Bathe & Vierendeels 2009,
  Computers & Structures 87, 793–801), optionally reusing ``reuse`` previous steps;
* ``"newton"``: interface Newton with both FMUs' ``fmi2GetDirectionalDerivative`` (one seed
  per interface variable, at the state the iteration reached: the film's ``J_f = ∂y/∂x``, the
  structure's ``J_s = ∂x̃/∂y``). Default ``structure_solve="exact"``: each iteration solves
  ``x̃(ŷ(x)) = x`` with the structure stepped exactly (from the step's start, rolled back per
  trial: it is the cheap FMU) and only the film replaced by its local model ``ŷ`` (tangent at
  the iterate, through the other evaluated point: :func:`film_model`), by semi-smooth Newton
  on the structure with its one-sided derivatives of the branch each trial lies on and Armijo
  backtracking (nonlinear elimination of the structure). The predictor is the same solve with
  the film's model at the step's start (the last converged state's derivative, curved through
  the step before). Why: the jack's law is piecewise linear (its valve's band is far softer
  than its cylinder), so the residual ``x̃ − x`` has slope ≈ −1 on the pumping and
  yielding-back branches and ``−(1 + K_f h rate / ((1 − crack) relief))`` in the band; Newton
  linearizing the jack on an outer branch jumps across the band to the other outer branch and
  back (it cycled at ``h = 100 s``). ``structure_solve="linearized"``: plain interface Newton,
  ``(J_s J_f − I) Δx = −r``, a step that does not lower ``‖r‖`` halved back toward the last
  iterate up to 10 times (damped), with the explicit Gauss–Seidel predictor.
  ``derivatives="finite-differences"`` takes the film's from extra steps with rollback instead,
  for an FMU that does not provide them (the predictor reuses the last such Jacobian).

Every iterated scheme reports, per step, the coupling iterations (film steps), the residual
history (``‖r‖∞`` of each iteration), the rollbacks (restores of the pair) and why it stopped.
A step that diverges (the residual grows beyond ``divergence`` times its first value, is not
finite, or the film refuses the step) or does not converge in ``max_iterations`` raises
:class:`CouplingFailed`, the FMUs back at the step's start.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .film import DISCARD, Film

SCHEMES = ("jacobi", "staggered", "gauss-seidel", "aitken", "iqn-ils", "newton")


@dataclass
class StepRecord:
    """One communication step of the master."""

    time: float
    step: float
    scheme: str
    #: Film steps taken to converge (1 for the explicit schemes), finite-difference steps not
    #: included (:attr:`extra_steps`).
    iterations: int = 0
    #: ``‖x̃ − x‖∞`` after each iteration.
    residuals: list = field(default_factory=list)
    #: Restores of both FMUs to the step's start (one per iteration after the first, one per
    #: finite-difference step).
    rollbacks: int = 0
    #: Film steps spent on finite-difference derivatives.
    extra_steps: int = 0
    #: Structure steps of Newton's exact structure solves (``structure_solve="exact"``), each
    #: from the step's start; the structure steps of the iterations themselves not included.
    structure_steps: int = 0
    converged: bool = True
    reason: str = ""
    #: The interface at the end of the step: film inputs, film outputs, the structure's outputs.
    x: list = field(default_factory=list)
    y: list = field(default_factory=list)
    x_structure: list = field(default_factory=list)


class CouplingFailed(RuntimeError):
    """A coupling step that did not converge; both FMUs are back at the step's start.
    ``record`` holds its residual history and ``report`` the steps before it."""

    def __init__(self, record: StepRecord, report: "CouplingReport"):
        self.record, self.report = record, report
        history = ", ".join(f"{r:.3g}" for r in record.residuals[:12])
        super().__init__(f"{record.scheme}: coupling step at t = {record.time:g} (h = {record.step:g}) "
                         f"{record.reason} after {record.iterations} iterations; residuals {history}")


@dataclass
class CouplingReport:
    """The steps of a run of the master."""

    scheme: str
    steps: list = field(default_factory=list)
    #: The step that failed (the run stopped there), or None.
    failure: StepRecord | None = None

    @property
    def iterations(self) -> np.ndarray:
        """Coupling iterations of each accepted step."""
        return np.asarray([s.iterations for s in self.steps], dtype=int)

    @property
    def rollbacks(self) -> int:
        return sum(s.rollbacks for s in self.steps) + (self.failure.rollbacks if self.failure else 0)

    def summary(self) -> str:
        it = self.iterations
        text = (f"{self.scheme}: {len(self.steps)} steps, iterations per step "
                f"mean {it.mean() if len(it) else 0:.2f} max {it.max() if len(it) else 0}, "
                f"{self.rollbacks} rollbacks")
        if self.failure is not None:
            text += f"; failed at t = {self.failure.time:g}: {self.failure.reason}"
        return text


def film_model(x0, y0, jf, sample=None):
    """The film's reactions near the iterate ``x0`` (reactions ``y0``, Jacobian ``jf``) as
    ``x ↦ (y, ∂y/∂x)``: linear, or with ``sample = (x1, y1, j1)``, another point of the same
    response (its Jacobian ``j1`` or None), a polynomial along ``p = x1 − x0``:
    ``y0 + J_f s + a q² + b q³``, ``q = (p·s)/(p·p)``, through ``y1`` at ``q = 1`` and, with
    ``j1``, with its slope ``j1 p`` there (Hermite; without ``j1``: ``b = 0``, the parabola)."""
    x0, y0, jf = (np.asarray(v, dtype=float) for v in (x0, y0, jf))
    a = b = p = None
    if sample is not None and sample[0] is not None:
        p = np.asarray(sample[0], dtype=float) - x0
        pp = float(p @ p)
        if pp > 0:
            e = np.asarray(sample[1], dtype=float) - y0 - jf @ p
            if sample[2] is None:
                a, b = e, np.zeros_like(e)
            else:
                f = (np.asarray(sample[2], dtype=float) - jf) @ p
                a, b = 3 * e - f, f - 2 * e
            p = p / pp

    def model(x):
        s = np.asarray(x, dtype=float) - x0
        if a is None:
            return y0 + jf @ s, jf
        q = float(p @ s)
        return y0 + jf @ s + a * q * q + b * q ** 3, jf + np.outer(2 * q * a + 3 * q * q * b, p)

    return model


class CoupledSystem:
    """The film and the structure, both initialized FMU instances (:class:`~membrane_contact.Film`
    works for any FMI 2.0 co-simulation FMU), and their interface: ``displacements`` pairs
    (structure output, film input), ``forces`` pairs (film output, structure input)."""

    def __init__(self, film: Film, structure: Film, displacements=(("dz", "frame.dz"),),
                 forces=(("frame.Rz", "force"),)):
        self.film, self.structure = film, structure
        self.displacements = [tuple(p) for p in displacements]
        self.forces = [tuple(p) for p in forces]
        for fmu, names, what in ((structure, [a for a, _ in self.displacements], "output"),
                                 (film, [b for _, b in self.displacements], "input"),
                                 (film, [a for a, _ in self.forces], "output"),
                                 (structure, [b for _, b in self.forces], "input")):
            for n in names:
                v = fmu.variables.get(n)
                if v is None or v.causality != what or v.type != "Real":
                    raise KeyError(f"'{n}' is not a Real {what} of {fmu.md.modelName}")
        if film.time is None or structure.time is None:
            raise RuntimeError("initialize() both FMUs before coupling them")
        self.x = np.asarray([structure.get(a) for a, _ in self.displacements], dtype=float)
        self.y = np.asarray([film.get(a) for a, _ in self.forces], dtype=float)
        self._omega = None
        self._reuse: list = []
        self._jf = None  # the film's last finite-difference Jacobian (Newton's predictor)
        # the film's input of the last accepted step (self.x: the structure's output)
        self._film_x = np.asarray([film.get(b) for _, b in self.displacements], dtype=float)
        self._last_sample = None  # (film input, reactions, Jacobian or None) of the step before

    # -- one evaluation

    def _step_film(self, x, h):
        self.film.set({b: float(v) for (_, b), v in zip(self.displacements, x)})
        if self.film.step(h) == DISCARD:
            return None
        return np.asarray([self.film.get(a) for a, _ in self.forces], dtype=float)

    def _step_structure(self, y, h):
        self.structure.set({b: float(v) for (_, b), v in zip(self.forces, y)})
        if self.structure.step(h) == DISCARD:
            return None
        return np.asarray([self.structure.get(a) for a, _ in self.displacements], dtype=float)

    def _derivative(self, fmu: Film, unknowns, knowns):
        """``∂unknowns/∂knowns`` (a matrix) by fmi2GetDirectionalDerivative, one seed per known."""
        if not fmu.md.coSimulation.providesDirectionalDerivative:
            raise RuntimeError(f"{fmu.md.modelName} does not provide directional derivatives "
                               "(providesDirectionalDerivative is false): use derivatives="
                               "'finite-differences' or the scheme 'iqn-ils'")
        u = [fmu.variables[n].valueReference for n in unknowns]
        k = [fmu.variables[n].valueReference for n in knowns]
        cols = []
        for j in range(len(k)):
            seed = [0.0] * len(k)
            seed[j] = 1.0
            cols.append(fmu._guard("fmi2GetDirectionalDerivative",
                                   lambda: fmu.fmu.getDirectionalDerivative(u, k, seed)))
        return np.asarray(cols, dtype=float).T.reshape(len(u), len(k))

    # -- one communication step

    def step(self, h: float, scheme: str = "aitken", *, tolerance: float = 1e-9, rtol: float = 1e-7,
             max_iterations: int = 50, omega: float = 0.5, divergence: float = 1e3, reuse: int = 0,
             derivatives: str = "fmu", fd_step: float = 1e-7, structure_solve: str = "exact") -> StepRecord:
        """One communication step of size ``h`` with ``scheme`` (:data:`SCHEMES`); converged when
        ``‖r‖∞ ≤ tolerance + rtol ‖x‖∞``. ``structure_solve`` (``"newton"`` only): ``"exact"``
        or ``"linearized"`` (module doc). Returns its record; raises :class:`CouplingFailed`
        with both FMUs back at the step's start."""
        if scheme not in SCHEMES:
            raise ValueError(f"unknown scheme '{scheme}': one of {', '.join(SCHEMES)}")
        if derivatives not in ("fmu", "finite-differences"):
            raise ValueError(f"derivatives = '{derivatives}': 'fmu' or 'finite-differences'")
        if structure_solve not in ("exact", "linearized"):
            raise ValueError(f"structure_solve = '{structure_solve}': 'exact' or 'linearized'")
        film, structure = self.film, self.structure
        if film.time != structure.time:
            raise RuntimeError(f"the film is at t = {film.time:g} and the structure at t = {structure.time:g}: "
                               "a coupling step starts with both FMUs at one time")
        rec = StepRecord(time=film.time, step=h, scheme=scheme)
        # Both FMUs' states at the step's start: whatever ends the step other than success (a
        # refusal of either FMU, a residual that diverges, an exception), both go back there, so
        # that they are never left at different times (issue 47 item 3).
        f0, s0 = film.save(), structure.save()
        try:
            try:
                return self._step(rec, h, scheme, f0, s0, tolerance=tolerance, rtol=rtol,
                                  max_iterations=max_iterations, omega=omega, divergence=divergence,
                                  reuse=reuse, derivatives=derivatives, fd_step=fd_step,
                                  structure_solve=structure_solve)
            except BaseException:
                rec.converged = False
                film.restore(f0)
                structure.restore(s0)
                raise
        finally:
            film.free(f0)
            structure.free(s0)

    def _step(self, rec: StepRecord, h: float, scheme: str, f0, s0, *, tolerance, rtol, max_iterations, omega,
              divergence, reuse, derivatives, fd_step, structure_solve) -> StepRecord:
        """The step of :meth:`step` from the saved states ``f0``, ``s0`` (the caller restores
        both when this raises)."""
        film, structure = self.film, self.structure
        if scheme == "jacobi":
            y = self._step_film(self.x, h)
            xt = self._step_structure(self.y, h) if y is not None else None
            return self._explicit(rec, y, xt, self.x)
        if scheme == "staggered":
            xt = self._step_structure(self.y, h)
            y = self._step_film(xt, h) if xt is not None else None
            return self._explicit(rec, y, xt, xt)

        def restore():
            film.restore(f0)
            structure.restore(s0)
            rec.rollbacks += 1

        def evaluate(x):
            """Film at x, then the structure under its reactions; (y, x̃) or None."""
            if rec.iterations > 0 or rec.extra_steps > 0:
                restore()
            rec.iterations += 1
            y = self._step_film(x, h)
            if y is None:
                return None, None
            return y, self._step_structure(y, h)

        # Predictor: the structure under the last reactions (explicit Gauss-Seidel).
        x_pred = self._step_structure(self.y, h)
        structure.restore(s0)
        x = x_pred if x_pred is not None else self.x.copy()
        jf_start = None
        if scheme == "newton" and structure_solve == "exact":
            # Newton's predictor: the film linearized at the step's start (the last
            # converged state), the structure solved exactly for it.
            jf0 = (self._derivative(film, [a for a, _ in self.forces], [b for _, b in self.displacements])
                   if derivatives == "fmu" else self._jf)
            jf_start = jf0
            if jf0 is not None and x_pred is not None:
                model = film_model(self._film_x, self.y, jf0, self._last_sample)
                x = self._solve_structure(model, self._film_x, None, None, h, s0, rec, tolerance, rtol)
                structure.restore(s0)
        r_prev = xt_prev = x_prev = y_prev = jf_prev = None
        halvings = 0
        V, W = [], []
        omega_k = min(omega, self._omega if self._omega is not None else omega)
        r0 = None
        while True:
            y, xt = evaluate(x)
            if y is None or xt is None:
                rec.reason = f"diverged: the {'film' if y is None else 'structure'} refused the step (fmi2Discard)"
                break
            r = xt - x
            norm = float(np.max(np.abs(r))) if len(r) else 0.0
            rec.residuals.append(norm)
            if not math.isfinite(norm):
                rec.reason = "diverged: residual not finite"
                break
            if norm <= tolerance + rtol * float(np.max(np.abs(x))):
                rec.x, rec.y, rec.x_structure = list(x), list(y), list(xt)
                self._last_sample = (self._film_x, self.y, jf_start)
                self.x, self.y, self._film_x = xt, y, x
                if scheme == "aitken":
                    self._omega = abs(omega_k)
                if scheme == "iqn-ils" and reuse > 0:
                    self._reuse = (self._reuse + [(V, W)])[-reuse:]
                return rec
            r0 = norm if r0 is None else r0
            if norm > divergence * max(r0, tolerance):
                rec.reason = f"diverged: residual grew by {norm / r0:.3g}"
                break
            if rec.iterations >= max_iterations:
                rec.reason = f"not converged in {max_iterations} iterations"
                break
            if scheme == "newton" and r_prev is not None and norm >= (1 - 1e-4) * float(np.max(np.abs(r_prev))) \
                    and halvings < 10:
                # No decrease: a full step across a kink (the valve opening, a gap closing)
                # overshot; halve it back toward the last iterate (damped Newton).
                halvings += 1
                x = x_prev + 0.5 * (x - x_prev)
                continue
            halvings = 0
            if scheme == "gauss-seidel":
                x_next = x + omega * r
            elif scheme == "aitken":
                if r_prev is not None:
                    dr = r - r_prev
                    omega_k = -omega_k * float(r_prev @ dr) / float(dr @ dr) if dr @ dr > 0 else omega_k
                x_next = x + omega_k * r
            elif scheme == "iqn-ils":
                if r_prev is not None:
                    V.insert(0, r - r_prev)
                    W.insert(0, xt - xt_prev)
                Vs = V + [v for old, _ in self._reuse for v in old]
                Ws = W + [w for _, old in self._reuse for w in old]
                if Vs:
                    Vm, Wm = np.column_stack(Vs), np.column_stack(Ws)
                    c = np.linalg.lstsq(Vm, -r, rcond=None)[0]
                    x_next = xt + Wm @ c
                else:
                    x_next = x + omega_k * r
            else:  # newton
                Jf, Js = self._jacobians(x, y, h, derivatives, fd_step, rec, restore)
                if structure_solve == "exact":
                    # the film's other sample of this step: the last iterate, or the
                    # step's start (a rate-independent film stepped back to its last
                    # input gives its last reactions)
                    sample = (x_prev, y_prev, jf_prev) if x_prev is not None else (self._film_x, self.y, jf_start)
                    model = film_model(x, y, Jf, sample)
                    x_next = self._solve_structure(model, x, r, Js, h, s0, rec, tolerance, rtol)
                else:
                    x_next = x - np.linalg.solve(Js @ Jf - np.eye(len(x)), r)
                jf_prev = Jf
            r_prev, xt_prev, x_prev, y_prev, x = r, xt, x, y, x_next
        raise CouplingFailed(rec, None)

    def _jacobians(self, x, y, h, derivatives, fd_step, rec, restore):
        """``J_f = ∂y/∂x`` and ``J_s = ∂x̃/∂y`` at the state the iteration reached."""
        film_in = [b for _, b in self.displacements]
        film_out = [a for a, _ in self.forces]
        Js = self._derivative(self.structure, [a for a, _ in self.displacements], [b for _, b in self.forces])
        if derivatives == "fmu":
            return self._derivative(self.film, film_out, film_in), Js
        cols = []
        for j in range(len(x)):
            d = fd_step * max(1.0, abs(x[j]))
            xp = x.copy()
            xp[j] += d
            restore()
            rec.extra_steps += 1
            yp = self._step_film(xp, h)
            if yp is None:
                raise RuntimeError("the film refused a finite-difference step")
            cols.append((yp - y) / d)
        # Back to the iterate the derivatives belong to (the caller restores before the next).
        self._jf = np.column_stack(cols)
        return self._jf, Js

    def _solve_structure(self, model, x0, r0, js0, h, s0, rec, tolerance, rtol):
        """Newton's step with the structure solved exactly: the ``x`` with ``x̃(ŷ(x)) = x``,
        ``ŷ = model`` the film's local model (:func:`film_model`) around ``x0``, the structure
        stepped from the step's start ``s0`` for each trial. Semi-smooth Newton on the structure,
        its derivatives at each trial (the branch of its piecewise law the trial lies on), with
        Armijo backtracking on ``‖x̃(ŷ(x)) − x‖₂``. ``r0``, ``js0``: residual and structure
        derivatives at ``x0`` when known (after a coupling iteration, where ``ŷ(x0)`` is the
        film's own ``y``), else stepped here. Returns the best ``x`` found."""
        structure = self.structure
        unknowns, knowns = [a for a, _ in self.displacements], [b for _, b in self.forces]
        eye = np.eye(len(x0))

        def trial(x):
            structure.restore(s0)
            rec.structure_steps += 1
            xs = self._step_structure(model(x)[0], h)
            return None if xs is None else xs - x

        x, g, js = np.asarray(x0, dtype=float), r0, js0
        if g is None:
            g = trial(x)
            if g is None:
                return x
            js = self._derivative(structure, unknowns, knowns)
        norm = float(np.linalg.norm(g))
        target = 1e-3 * (tolerance + rtol * float(np.max(np.abs(x))))
        for _ in range(50):
            if norm <= target:
                break
            try:
                d = -np.linalg.solve(js @ model(x)[1] - eye, g)
            except np.linalg.LinAlgError:  # J_s J_f = I: no Newton direction; the best x so far
                return x
            t = 1.0
            while True:
                gt = trial(x + t * d)
                if gt is not None and float(np.linalg.norm(gt)) <= (1 - 1e-4 * t) * norm:
                    break
                t *= 0.5
                if t < 1e-10:
                    return x
            x, g = x + t * d, gt
            norm = float(np.linalg.norm(g))
            js = self._derivative(structure, unknowns, knowns)
        return x

    def _explicit(self, rec, y, xt, x):
        rec.iterations = 1
        if y is None or xt is None:
            rec.converged = False
            rec.reason = "an FMU refused the step (fmi2Discard)"
            raise CouplingFailed(rec, None)
        rec.x, rec.y, rec.x_structure = list(x), list(y), list(xt)
        self.x, self.y = xt, y
        return rec

    def run(self, duration: float, h: float, scheme: str = "aitken", on_step=None, **options) -> CouplingReport:
        """Steps of size ``h`` (the last one shortened) over ``duration``; returns the report.
        A step that fails ends the run: the report's ``failure`` says where and why (the FMUs
        at that step's start). ``on_step(record)`` is called after each accepted step."""
        report = CouplingReport(scheme)
        end = self.film.time + duration
        while self.film.time < end - 1e-9 * max(1.0, abs(end)):
            dt = min(h, end - self.film.time)
            try:
                rec = self.step(dt, scheme, **options)
            except CouplingFailed as e:
                report.failure = e.record
                break
            report.steps.append(rec)
            if on_step is not None:
                on_step(rec)
        return report


def erection_system(film_fmu=None, jack_fmu=None, film_parameters: dict | None = None,
                    jack_parameters: dict | None = None, group: str = "frame") -> CoupledSystem:
    """The coupled erection system of :mod:`membrane_contact.ssp` as two initialized instances:
    the film (default the ParallelArch specimen) and the hydraulic jack (default packed from the
    repository), with the same default parameter values as the SSP archive. Close both
    (``system.film.close()``, ``system.structure.close()``) when done, or use
    :func:`closing`."""
    from .ssp import FILM_PARAMETERS, JACK_PARAMETERS, pack_jack_fmu

    packed = None
    if jack_fmu is None:
        import tempfile
        from pathlib import Path

        packed = tempfile.mkdtemp(prefix="jack_")
        jack_fmu = pack_jack_fmu(Path(packed) / "HydraulicJack.fmu")
    film = Film(film_fmu, name="film", logging=False, quiet=True)
    jack = Film(jack_fmu, name="jack", logging=False, quiet=True)
    film.initialize({**FILM_PARAMETERS, **(film_parameters or {})})
    jack.initialize({**JACK_PARAMETERS, **(jack_parameters or {})})
    system = CoupledSystem(film, jack, displacements=[("dz", f"{group}.dz")], forces=[(f"{group}.Rz", "force")])
    system.packed = packed
    return system


class closing:
    """``with closing(erection_system(...)) as system:`` closes both instances at the end."""

    def __init__(self, system: CoupledSystem):
        self.system = system

    def __enter__(self) -> CoupledSystem:
        return self.system

    def __exit__(self, *exc: Any) -> None:
        import shutil

        self.system.film.close()
        self.system.structure.close()
        if getattr(self.system, "packed", None):
            shutil.rmtree(self.system.packed, ignore_errors=True)
