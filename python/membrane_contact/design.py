"""Design for a target prestress from Python (issue 46): form finding and cutting patterns, run
by the ``membrane-contact`` program (``form-find`` and ``pattern``; docs/mechanics.md, "Form
finding and patterning").

* :func:`form_find` — the shape in which the film carries its prestress (updated reference
  strategy, Bletzinger & Ramm 1999), returned as a model (dict);
* :func:`pattern` — the strips cut along seams, flattened and compensated, with their sizes and
  distortions, and, with ``erect=N``, the compensation corrected by erections with the analysis
  (each strip's, or with ``by_element=True`` each triangle's);
* :func:`pattern_variants` — several patterns and compensations (rail paths, friction-aware or
  uniform, …) at once on the study machinery's Dask cluster, one variant per worker.

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
              max_steps: int | None = None, force_density_start: bool = False, on_supports: bool = False,
              stress_tolerance: float | None = None, warp: Sequence[float] | None = None,
              contact_stiffness: str | None = None) -> dict:
    """The found model: the geometry in which the film carries ``prestress`` (MPa, ``(sx, sy)`` or
    ``(sx, sy, txy)`` in each element's frame; default the model's) with its boundary held, and
    that prestress as its material's (``membrane-contact form-find``). ``on_supports=True``: against
    the model's curved supports, frictionless (``--on-supports``; ``stress_tolerance`` the largest
    ``|σ − σ*|/|σ*|`` of a step accepted, default 1e-3); start from a geometry near them.
    ``warp=(ax, ay, az)``: each element's frame follows that direction (``--warp``), so
    ``prestress=(warp, fill)`` is an orthotropic target; the found model has it as ``frame_axis``.
    ``contact_stiffness``: how the curved supports' penalties are read with ``on_supports``:
    ``"auto"`` (the default: per metre of contact line where a support's nodes lie in a row along
    it, else per node), ``"per-length"`` or ``"per-node"`` (``--contact-stiffness``); the found
    model keeps the numbers as given."""
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
        if on_supports:
            args.append("--on-supports")
        if stress_tolerance is not None:
            args += ["--stress-tolerance", repr(float(stress_tolerance))]
        if warp is not None:
            args += ["--warp", ",".join(repr(float(a)) for a in warp)]
        if contact_stiffness is not None:
            args += ["--contact-stiffness", str(contact_stiffness)]
        _run(args)
        return json.loads(out.read_text())


def _nested(values: Sequence[Any]) -> bool:
    """Whether ``values`` is a list of lists (several lines or waypoints), not one."""
    return len(values) > 0 and not isinstance(values[0], (int, float))


def pattern(model: dict | str | Path, seam_planes: Sequence[Sequence[float]] = (),
            seam_nodes: Sequence[Sequence[int]] = (), compensation: str | float | Sequence[float] = "prestress",
            svg: str | Path | None = None, erection_model: str | Path | None = None, erect: int = 0,
            erect_tolerance: float = 1.0, erect_increments: int = 10, by_element: bool = False,
            rail_path: Sequence[float] | Sequence[Sequence[float]] | None = None,
            settle: str | Sequence[float | str] | None = None,
            contact_stiffness: str | None = None,
            geodesic_from: Sequence[int] | Sequence[Sequence[int]] | None = None,
            strip_width: float | Sequence[float] | None = None,
            erection_models: str | Path | None = None) -> dict[str, Any]:
    """The cutting pattern of a (form found) model (``membrane-contact pattern``): a dict with
    ``strips`` (per strip: ``triangles``, ``size`` (m, length and width), ``compensation``,
    ``distortion`` ``{max, rms}`` as strains and ``outline``, the cut strip's boundary edges as
    ``[[x0, y0], [x1, y1]]`` in m) and ``erections`` (per erection: ``mean_error``, ``max_error``
    and each strip's ``compensation``; empty without ``erect``).

    ``by_element=True`` (with ``erect``) corrects every triangle's reference lengths instead of
    each strip's two compensations (``pattern --by-element``): the errors are then taken away from
    the rails, each erection also has ``worst_triangle``, ``yielded``, ``stress`` (every
    triangle's ``[sx, sy, txy]`` in Pa after erection) and ``contacts`` (every contact node of the
    curved supports at the end: ``node``, ``support``, ``status`` ``"Open"``, ``"Stick"`` or
    ``"Slip"``, ``normal_force`` and ``friction`` ``[along, across]`` in N, ``slip`` in m along
    the support), and the report has
    ``stalled`` (triangles above the tolerance whose error did not halve) and ``held_by_friction``
    (those of them that friction holds on a support: their stress does not follow their cut).
    ``rail_path=(up, in)`` (m): the erections start with the rails that far above and inward of
    their places and pull them down and out (``--rail-path``); a list of such pairs is a winding
    path, the rails going through each in turn, e.g. ``[(0.10, 0.03), (0.0, 0.03)]``: down, then
    out. ``settle=(amplitude, ratio, cycles)`` (with ``rail_path``): then the rails pass their
    places by ``amplitude`` m along the last leg, come back short of them by ``ratio`` times that,
    and so on, ``cycles`` waypoints, and end at their places (``--settle``): the film settles on
    its frictional supports at a nearly even tension (the vault bay: ``(0.001, 0.7, 12)``).
    ``settle="auto"`` (or ``("auto", ratio, cycles)``): the program chooses the amplitude, half the
    length change the target prestress asks of the longest strip (ratio 0.7, 12 waypoints); the
    report's ``settle`` has ``amplitude``, ``ratio``, ``cycles`` and ``chosen``.
    ``contact_stiffness``: how the curved supports' penalties are read in the erections:
    ``"auto"`` (the default: per metre of contact line where a support's nodes lie in a row along
    it, else per node), ``"per-length"`` or ``"per-node"``; the report's ``contact_stiffness`` has
    each support's ``tributary_length`` (m, None where per node) and the penalties per node it
    got (``--contact-stiffness``).

    ``seam_planes``: ``(px, py, pz, nx, ny, nz)`` each; ``seam_nodes``: node lines;
    ``geodesic_from`` (a line of boundary nodes, or a line across the film from boundary to
    boundary, itself a seam with the others on both sides; or a list of lines) and ``strip_width``
    (m, one for all lines or one per line): geodesic seams that far apart along the surface, the
    film split along them (``--geodesic-from``, ``--strip-width``);
    ``compensation``: ``"prestress"``, a percentage, or ``(along, across)`` percentages;
    ``svg`` / ``erection_model``: files to write the outlines and the erection model to;
    ``erection_models``: a folder to write every erection's model to as it is erected
    (``erection-K.json``: models a :class:`membrane_contact.study.Study` can run, packed by
    ``fmu-pack``)."""
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
        if geodesic_from is not None:
            lines = geodesic_from if _nested(geodesic_from) else [geodesic_from]
            for line in lines:
                args += ["--geodesic-from", ",".join(str(int(v)) for v in line)]
            widths = [strip_width] if isinstance(strip_width, (int, float)) else list(strip_width)
            for w in widths:
                args += ["--strip-width", repr(float(w))]
        if by_element:
            args.append("--by-element")
        if rail_path is not None:
            for waypoint in (rail_path if _nested(rail_path) else [rail_path]):
                args.append("--rail-path=" + ",".join(repr(float(v)) for v in waypoint))
        if settle == "auto":
            args.append("--settle=auto")
        elif settle is not None:
            amplitude, ratio, cycles = settle
            amplitude = "auto" if amplitude == "auto" else repr(float(amplitude))
            args.append(f"--settle={amplitude},{float(ratio)!r},{int(cycles)}")
        if contact_stiffness is not None:
            args += ["--contact-stiffness", str(contact_stiffness)]
        if svg is not None:
            args += ["--svg", str(svg)]
        if erection_model is not None:
            args += ["--erection-model", str(erection_model)]
        if erection_models is not None:
            args += ["--erection-models", str(erection_models)]
        _run(args)
        return json.loads(report.read_text())


def _pattern_variant(model_text: str, options: dict) -> dict:
    """One variant of :func:`pattern_variants` on a worker: its report, or its ``error``."""
    try:
        return pattern(json.loads(model_text), **options)
    except DesignError as e:
        return {"error": str(e)}


def pattern_variants(model: dict | str | Path, variants: Sequence[dict], client: Any = None, *,
                     scheduler: str | None = None, workers: int | None = None) -> list[dict]:
    """Runs the cutting pattern and its compensation by erection of each of ``variants`` (keyword
    arguments of :func:`pattern`: another rail path, friction-aware or uniform compensation, more
    erections, …) on the study machinery's Dask cluster (:func:`membrane_contact.cluster.cluster`:
    ``client``, else one to ``scheduler``, else a ``LocalCluster`` of ``workers`` single-threaded
    processes), one variant per task, every erection of its iterations inside it. Returns the
    reports in the order of ``variants``; a variant the program refuses gives ``{"error":
    message}`` and the others go on (as a study's refused case). The workers run the same
    ``membrane-contact`` program as :func:`pattern` (``$MEMBRANE_CONTACT_CLI``, the wheel's, or the
    checkout's build)."""
    if not isinstance(model, dict):
        model = json.loads(Path(model).read_text())
    text = json.dumps(model)
    if client is None:
        from .cluster import cluster

        with cluster(scheduler, workers) as client:
            return pattern_variants(model, variants, client)
    futures = [client.submit(_pattern_variant, text, dict(v), pure=False) for v in variants]
    return client.gather(futures)
