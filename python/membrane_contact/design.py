"""Design for a target prestress from Python (issue 46): form finding and cutting patterns, run
by the ``membrane-contact`` program (``form-find`` and ``pattern``; docs/mechanics.md, "Form
finding and patterning").

* :func:`form_find` — the shape in which the film carries its prestress (updated reference
  strategy, Bletzinger & Ramm 1999), returned as a model (dict);
* :func:`pattern` — the strips cut along seams, flattened and compensated, with their sizes and
  distortions, and, with ``erect=N``, the compensation corrected by erections with the analysis.

Both take a model as a dict or a file path; a model the program refuses raises
:class:`DesignError` with the program's message, which names the bad item.
"""

from __future__ import annotations

import json
import subprocess
import tempfile
from pathlib import Path
from typing import Any, Sequence

from .fmu import CLI_VARIABLE, cli_program


class DesignError(RuntimeError):
    """The program refused the model or the options (its message, which names the bad item)."""


def _run(args: list[str]) -> subprocess.CompletedProcess:
    program = cli_program()
    if program is None:
        raise DesignError(f"no membrane-contact program: install the wheel, build the checkout, or set ${CLI_VARIABLE}")
    r = subprocess.run([program, *args], capture_output=True, text=True)
    if r.returncode != 0:
        raise DesignError(r.stderr.strip() or f"membrane-contact {args[0]} failed ({r.returncode})")
    return r


def _model_file(model: dict | str | Path, folder: str) -> str:
    if isinstance(model, dict):
        path = Path(folder) / "model.json"
        path.write_text(json.dumps(model))
        return str(path)
    return str(model)


def form_find(model: dict | str | Path, prestress: Sequence[float] | None = None, tolerance: float | None = None,
              max_steps: int | None = None, force_density_start: bool = False) -> dict:
    """The found model: the geometry in which the film carries ``prestress`` (MPa, ``(sx, sy)`` or
    ``(sx, sy, txy)`` in each element's frame; default the model's) with its boundary held, and
    that prestress as its material's (``membrane-contact form-find``)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "found.json"
        args = ["form-find", _model_file(model, tmp), "--out", str(out)]
        if prestress is not None:
            args += ["--prestress", ",".join(repr(float(p)) for p in prestress)]
        if tolerance is not None:
            args += ["--tolerance", repr(float(tolerance))]
        if max_steps is not None:
            args += ["--max-steps", str(int(max_steps))]
        if force_density_start:
            args.append("--force-density-start")
        _run(args)
        return json.loads(out.read_text())


def pattern(model: dict | str | Path, seam_planes: Sequence[Sequence[float]] = (),
            seam_nodes: Sequence[Sequence[int]] = (), compensation: str | float | Sequence[float] = "prestress",
            svg: str | Path | None = None, erection_model: str | Path | None = None, erect: int = 0,
            erect_tolerance: float = 1.0, erect_increments: int = 10) -> dict[str, Any]:
    """The cutting pattern of a (form found) model (``membrane-contact pattern``): a dict with
    ``strips`` (per strip: ``triangles``, ``size`` (m, length and width), ``compensation`` and
    ``distortion`` ``{max, rms}`` as strains) and ``erections`` (per erection: ``mean_error``,
    ``max_error`` and each strip's ``compensation``; empty without ``erect``).

    ``seam_planes``: ``(px, py, pz, nx, ny, nz)`` each; ``seam_nodes``: node lines;
    ``compensation``: ``"prestress"``, a percentage, or ``(along, across)`` percentages;
    ``svg`` / ``erection_model``: files to write the outlines and the erection model to."""
    with tempfile.TemporaryDirectory() as tmp:
        report = Path(tmp) / "report.json"
        if not isinstance(compensation, str):
            values = [compensation] if isinstance(compensation, (int, float)) else list(compensation)
            compensation = ",".join(repr(float(c)) for c in values)
        args = ["pattern", _model_file(model, tmp), "--compensation", compensation, "--report", str(report),
                "--erect", str(int(erect)), "--erect-tolerance", repr(float(erect_tolerance)),
                "--erect-increments", str(int(erect_increments))]
        for p in seam_planes:
            args += ["--seam-plane", ",".join(repr(float(v)) for v in p)]
        for line in seam_nodes:
            args += ["--seam-nodes", ",".join(str(int(v)) for v in line)]
        if svg is not None:
            args += ["--svg", str(svg)]
        if erection_model is not None:
            args += ["--erection-model", str(erection_model)]
        _run(args)
        return json.loads(report.read_text())
