"""Shared helpers of the examples: drive the ParallelArch FMU with fmpy, or the core's CLI.

The examples (``fig7_mu_sweep.py``, ``fig8_vs_experiment.py``, ``fig6_stress.py``,
``erection_sequence.py``) import this module; it sits beside them in ``examples/``.

Units: everything returned here is SI (m, N, Pa); the scripts convert slips to mm for the
figures and CSV files.

* :class:`ArchFMU` wraps one FMI 2.0 Co-Simulation instance through the package's
  :class:`membrane_contact.Film` (``python/``): parameters at initialisation, inputs per step,
  ``fmi2Discard`` returned as ``False`` (the FMU keeps its last converged state, time and
  outputs), and :meth:`ArchFMU.step_to` which retries a refused step in halves.
* :func:`ramp` lowers the frame of a specimen to its target ``dz = -H/2`` in ``steps``
  communication steps through the FMU (``backend="fmu"``) or the CLI (``backend="cli"``, the
  same core without FMI: a cross-check and a fallback).
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import subprocess
import tempfile
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
try:
    from membrane_contact import Film, StepRefused
    from membrane_contact.film import DISCARD
except ImportError:  # run from a checkout without the package installed (pip install ./python)
    sys.path.insert(0, str(ROOT / "python"))
    from membrane_contact import Film, StepRefused
    from membrane_contact.film import DISCARD
DEFAULT_FMU = ROOT / "target" / "fmu" / "ParallelArch.fmu"
# The core's CLI: $MEMBRANE_CONTACT_CLI (e.g. the wheel's membrane-contact), else this checkout's build.
CLI = Path(os.environ.get("MEMBRANE_CONTACT_CLI") or ROOT / "target" / "release" / "membrane-contact")
TABLE1 = ROOT / "data" / "table1_sliding.csv"
BUILD_HINT = "cargo build --release && cargo run --release --bin fmu-pack"

GAPS = [f"G{i}" for i in range(1, 10)]
# Paper §4.4: observed points 1..5 are G1 (crown) and G2, G4, G6, G8.
OBSERVED = {1: "G1", 2: "G2", 3: "G4", 4: "G6", 5: "G8"}
STATUS = {0: "open", 1: "stick", 2: "slip"}
# String parameter of the FMU: write the film and the gaps as VTK (.vtu per step + .pvd) into this
# directory (encoding: results.vtkFormat, binary by default).
RESULTS_DIRECTORY = "results.directory"


# ----------------------------------------------------------------------------- command line


def example_parser(description: str, steps: int, out: str = "out/examples") -> argparse.ArgumentParser:
    """The options every example has: --steps, --out, --fmu."""
    p = argparse.ArgumentParser(description=description)
    p.add_argument("--steps", type=int, default=steps,
                   help=f"communication steps of the frame lowering (default {steps})")
    p.add_argument("--out", default=str(ROOT / out),
                   help="directory of the PNG and CSV outputs (default %(default)s)")
    p.add_argument("--fmu", default=str(DEFAULT_FMU),
                   help="the packed FMU (default %(default)s; build: " + BUILD_HINT + ")")
    return p


def use_agg():
    """matplotlib with the file-only Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_png(fig, path, dpi: int = 100) -> Path:
    """Save ``fig`` as a small PNG: 100 dpi, quantized to a 256-colour palette (plots have
    few colours; this keeps the committed figures at a few tens of kB)."""
    import io

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    try:
        from PIL import Image  # a matplotlib dependency

        img = Image.open(buf).convert("RGB")
        img.quantize(colors=256, method=Image.Quantize.MEDIANCUT,
                     dither=Image.Dither.NONE).save(path, optimize=True)
    except ImportError:
        path.write_bytes(buf.getvalue())
    return path


def write_csv(path: Path, header: list[str], rows: list[list]) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(header)
        for row in rows:
            w.writerow([fmt(x) for x in row])
    return path


def fmt(x):
    """CSV cell: floats with 6 significant decimals (mm to the nanometre is plenty)."""
    if isinstance(x, float):
        return f"{x:.6g}" if abs(x) >= 1e3 else f"{x:.6f}"
    return x


def read_table1() -> dict[int, dict[int, float]]:
    """Table 1 of the paper: {arch height mm: {point 1..5: measured slip mm}}."""
    lines = [l for l in TABLE1.read_text().splitlines() if l.strip() and not l.startswith("#")]
    table = {}
    for row in csv.DictReader(lines):
        table[int(float(row["arch_height_mm"]))] = {p: float(row[f"p{p}"]) for p in range(1, 6)}
    return table


# ----------------------------------------------------------------------------- the FMU


class ArchFMU:
    """One instance of the ParallelArch FMU (FMI 2.0 Co-Simulation) over the package's
    :class:`membrane_contact.Film`, with the specimen's vocabulary (gaps G1…G9, the frame).

    ``parameters`` (name -> value) are set in initialization mode, as are the initial
    ``inputs`` (``mu``, ``frame.dz``, ...). Time is the FMU's pseudo-time: any positive step
    sizes; the inputs are the frame displacement reached at the end of each step.
    """

    def __init__(self, fmu_path=None, parameters=None, inputs=None, name="arch"):
        path = Path(fmu_path or DEFAULT_FMU)
        if not path.is_file():
            raise FileNotFoundError(f"{path} not found; build it with: {BUILD_HINT}")
        self.path = path
        self.film = Film(path, name=name, logging=False)
        self.md, self.variables, self.messages = self.film.md, self.film.variables, self.film.messages
        self.inputs = {v.name: float(v.start) for v in self.md.modelVariables
                       if v.causality == "input" and v.type == "Real" and v.start is not None}
        self.inputs.update(inputs or {})
        # Inputs at the last converged point (inputs set in initialization mode are only
        # reached by the first step): the start of a step that is split after a Discard.
        self.reached = dict(self.inputs)
        self.discards = 0
        try:
            self.film.initialize({k: v for k, v in (parameters or {}).items() if v is not None}, inputs)
        except Exception:
            self.close()
            raise

    @property
    def time(self) -> float:
        return self.film.time

    # -- values

    def has(self, name: str) -> bool:
        return name in self.variables

    def set(self, name: str, value):
        self.film.set({name: value})
        if self.variables[name].causality == "input":
            self.inputs[name] = float(value)

    def get(self, names: list[str]) -> dict:
        """Values of ``names``."""
        return {n: self.film.get(n) for n in names}

    def snapshot(self, **extra) -> dict:
        """Gap results, frame reaction and solver statistics now (SI units)."""
        names = []
        for g in GAPS:
            names += [f"{g}.slip", f"{g}.slipY", f"{g}.normalForce", f"{g}.frictionForce",
                      f"{g}.status"]
        stats = ["frame.Rx", "frame.Ry", "frame.Rz", "solver.iterations", "solver.cutbacks",
                 "solver.residual", "film.maxEquivalentStress"]
        names += [n for n in stats if self.has(n)]
        v = self.get(names)
        snap = {
            "time": self.time,
            "dz": self.reached.get("frame.dz", 0.0),
            "gaps": {g: {"slip": v[f"{g}.slip"], "slipY": v[f"{g}.slipY"],
                         "N": v[f"{g}.normalForce"], "T": v[f"{g}.frictionForce"],
                         "status": int(v[f"{g}.status"])} for g in GAPS},
            "R": tuple(v.get(f"frame.R{a}", math.nan) for a in "xyz"),
            "iterations": v.get("solver.iterations"),
            "cutbacks": v.get("solver.cutbacks"),
            "residual": v.get("solver.residual"),
            "max_von_mises": v.get("film.maxEquivalentStress"),
        }
        snap.update(extra)
        return snap

    # -- stepping

    def step(self, h: float, inputs: dict | None = None) -> bool:
        """One ``fmi2DoStep`` of size ``h`` reaching ``inputs``; ``False`` on ``fmi2Discard``.

        After a Discard the FMU stays at its last converged point (time, state, outputs), so
        the caller may set other inputs and step again from the same time.
        """
        for k, v in (inputs or {}).items():
            self.set(k, v)
        if self.film.step(h) == DISCARD:
            self.discards += 1
            return False
        self.reached = dict(self.inputs)
        return True

    def step_to(self, h: float, inputs: dict, max_halvings: int = 8) -> int:
        """Reach ``inputs`` at ``time + h``; a refused step is split in two halves (inputs
        interpolated linearly), recursively (:meth:`membrane_contact.Film.run`). Returns the
        number of accepted sub-steps."""
        before = self.film.time
        table = {"time": [before + h], **{k: [v] for k, v in inputs.items()}}
        try:
            results = self.film.run(table, outputs=[], max_halvings=max_halvings)
        except StepRefused as e:
            raise RuntimeError(str(e)) from e
        self.discards += results.halvings
        self.inputs.update(inputs)
        self.reached = dict(self.inputs)
        return results.steps

    def log_tail(self, n: int = 3) -> str:
        return " | ".join(m for _, _, m in self.messages[-n:]) or "(no messages)"

    # -- FMU state (rollback)

    def save(self):
        """The FMU state at the last converged point (with its inputs), for :meth:`restore`."""
        return (self.film.save(), dict(self.reached))

    def restore(self, saved):
        """Back to a saved point (fmi2SetFMUstate); set the inputs again before stepping."""
        state, reached = saved
        self.film.restore(state)
        self.reached = dict(reached)
        self.inputs.update(reached)

    def free(self, saved):
        self.film.free(saved[0])

    # -- end

    def close(self):
        self.film.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


# ----------------------------------------------------------------------------- load path


def ramp(height: float, mu: float, steps: int, backend: str = "fmu", fmu_path=None,
         increments: int | None = None, vtk_dir=None) -> list[dict]:
    """Lower the frame of the ``height`` (m) specimen to ``dz = -H/2`` in ``steps`` equal
    communication steps over pseudo-time 0..1; the snapshot after every step.

    ``increments``: the FMU's ``solver.incrementsPerStep`` (None: its default, 10; the CLI
    always takes 1). ``vtk_dir``: write the film of every step as VTK there (the FMU's
    ``results.directory`` parameter, or the CLI's ``--vtk``)."""
    if backend == "cli":
        return ramp_cli(height, mu, steps, vtk_dir=vtk_dir)
    if backend != "fmu":
        raise ValueError(f"backend must be 'fmu' or 'cli', not {backend!r}")
    target = -0.5 * height
    params = {"archHeight": height, "solver.incrementsPerStep": increments}
    if vtk_dir is not None:
        Path(vtk_dir).mkdir(parents=True, exist_ok=True)
        params[RESULTS_DIRECTORY] = str(Path(vtk_dir).resolve())
    history = []
    with ArchFMU(fmu_path, parameters=params, inputs={"mu": mu}) as fmu:
        for k in range(1, steps + 1):
            fraction = k / steps
            fmu.step_to(fraction - fmu.time, {"frame.dz": target * fraction})
            history.append(fmu.snapshot(fraction=fraction, discards=fmu.discards))
    return history


def cli_binary() -> Path:
    """The core's CLI, built if missing."""
    if not CLI.is_file():
        subprocess.run(["cargo", "build", "--release", "--quiet", "--bin", "membrane-contact"],
                       cwd=ROOT, check=True)
    return CLI


def ramp_cli(height: float, mu: float, steps: int, vtk_dir=None) -> list[dict]:
    """:func:`ramp` through ``membrane-contact specimen`` (no FMI): same core, same load path
    as the FMU with ``solver.incrementsPerStep = 1``. Writes VTK files if ``vtk_dir``."""
    status = {"Open": 0, "Stick": 1, "Slip": 2}
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "gaps.csv"
        cmd = [str(cli_binary()), "specimen", "--height", f"{height * 1e3:g}", "--mu", f"{mu:g}",
               "--steps", str(steps), "--csv", str(out), "--quiet"]
        if vtk_dir is not None:
            cmd += ["--vtk", str(vtk_dir)]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        with open(out) as f:
            rows = list(csv.DictReader(f))
    history: dict[int, dict] = {}
    for r in rows:
        k = int(r["step"])
        snap = history.setdefault(k, {
            "time": float(r["fraction"]), "fraction": float(r["fraction"]),
            "dz": -0.5 * height * float(r["fraction"]), "gaps": {},
            "R": (math.nan,) * 3, "iterations": None, "cutbacks": None, "residual": None,
            "max_von_mises": None, "discards": 0})
        snap["gaps"][r["gap"]] = {"slip": float(r["slip_x_mm"]) * 1e-3,
                                  "slipY": float(r["slip_y_mm"]) * 1e-3,
                                  "N": float(r["normal_force_N"]),
                                  "T": float(r["friction_force_N"]),
                                  "status": status[r["status"]]}
    return [history[k] for k in sorted(history)]
