"""The cushion system (issue 43): an ETFE cushion film FMU whose air is a sealed chamber, and the
inflation unit FMU (``fmu/inflation``) that keeps it up.

* :func:`cushion_model` is ``examples/cushion_air.json`` as the cushion stands on its frame: both
  layers spherical caps of the radius at which the film's prestress carries the design pressure
  (``R = 2 σ t / p``, a membrane sphere's equilibrium), the air sealed in at that pressure, and
  two load sets on the top layer: ``snow`` (a load per plan area, down) and ``wind`` (a follower
  pressure pulling the top layer up: suction);
* :func:`pack_cushion_fmu` packs it with ``fmu-pack`` (``InflatedCushion.fmu``);
* :func:`pack_unit_fmu` packs ``InflationUnit.fmu`` (FMI 2.0, or 3.0 with ``fmi_version=3``) from
  the unit's library (``target/release/libinflation_unit.so``, built by ``cargo build
  --release``) and its generated model description;
* :func:`write_cushion_ssp` writes both into an SSP archive: ``film.<chamber>.pressure →
  unit.pressure`` and ``unit.massFlow → film.<chamber>.massFlow``; fmpy and libcosim run it;
* :func:`cushion_system` is the same pair for the co-simulation master
  (:class:`~membrane_contact.coupling.CoupledSystem`; the unit is its "structure").

The exchange: the unit holds the cushion's pressure of the last communication point over a step
and returns the step's average net mass flow; the film adds ``massFlow · h`` to its air. With the
master's ``"staggered"`` scheme (the unit first, the film with its flow of the same step) the air
the film gains is the air the unit delivered, to rounding; the SSP tools exchange Jacobi-style
(the film uses the unit's flow of the step before).
"""

from __future__ import annotations

import json
import subprocess
import tempfile
import zipfile
from pathlib import Path

from .fmu import repository_root
from .ssp import _component, cargo_library, connection, ssd_text

#: The unit's model identifier (its library's name in the FMU) and cargo package.
UNIT_IDENTIFIER, UNIT_PACKAGE = "inflation_unit", "inflation-unit-fmu"
#: The cushion's model name (its FMU's file name) and chamber.
CUSHION_NAME, CHAMBER = "InflatedCushion", "air"
#: The interface: the unit's output to the film's input, the film's output to the unit's input.
FLOWS = (("massFlow", f"{CHAMBER}.massFlow"),)
PRESSURES = ((f"{CHAMBER}.pressure", "pressure"),)
#: Film parameter values of the system: tight tolerances, so that the air's mass and pressure
#: are converged far below what the unit's switch sees.
FILM_PARAMETERS = {"solver.displacementTolerance": 1e-9, "solver.residualTolerance": 1e-9}


def _root(root) -> Path:
    root = Path(root) if root is not None else repository_root()
    if root is None:
        raise RuntimeError("the cushion system is built from the repository (examples/, fmu/inflation)")
    return root


def cushion_model(pressure: float = 300.0, root=None) -> dict:
    """The cushion of ``examples/cushion_air.json`` shaped and sealed at ``pressure`` (Pa), with
    the load sets ``snow`` and ``wind`` on its top layer (the model's element set ``upper``)."""
    model = json.loads((_root(root) / "examples" / "cushion_air.json").read_text())
    material = model["material"]
    sigma, t = material["prestress"][0], material["thickness"]
    radius = 2.0 * sigma * t / pressure
    sets = {s["name"]: s["elements"] for s in model["outputs"]["element_sets"]}
    top = {n for e in sets["upper"] for n in model["triangles"][e]}
    rim = max((x * x + y * y) ** 0.5 for x, y, _ in model["nodes"])
    if not radius > rim:
        raise ValueError(f"{pressure} Pa needs a sphere of radius {radius:.3f} m, smaller than the rim's {rim:.3f} m")
    for k, node in enumerate(model["nodes"]):
        r2 = node[0] ** 2 + node[1] ** 2
        rise = (radius * radius - r2) ** 0.5 - (radius * radius - rim * rim) ** 0.5
        node[2] = rise if k in top else -rise
    model["name"] = CUSHION_NAME
    model["description"] = (f"ETFE cushion, 2 m diameter, two spherical caps of radius {radius:.4g} m (its prestress "
                            f"carries {pressure:g} Pa), the air sealed in; snow and wind suction on the top layer "
                            "(membrane_contact.inflation.cushion_model)")
    (chamber,) = model["chambers"]
    chamber.update(name=CHAMBER, pressure=pressure, sealed=True)
    model.setdefault("loads", {})["pressures"] = [
        {"name": "snow", "elements": sets["upper"], "pressure": 0.0, "kind": "plan"},
        {"name": "wind", "elements": sets["upper"], "pressure": 0.0, "towards": "+z"},
    ]
    return model


def pack_cushion_fmu(out_dir, pressure: float = 300.0, root=None, fmi_version: int = 2) -> Path:
    """Packs :func:`cushion_model` with the release build's ``fmu-pack`` into ``out_dir``;
    returns the FMU's path."""
    root, out_dir = _root(root), Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    model = out_dir / "inflated_cushion.json"
    model.write_text(json.dumps(cushion_model(pressure, root)))
    fmu = out_dir / (f"{CUSHION_NAME}.fmu" if fmi_version == 2 else f"{CUSHION_NAME}_fmi3.fmu")
    r = subprocess.run([str(root / "target" / "release" / "fmu-pack"), str(model), "-o", str(fmu),
                        "--fmi-version", str(fmi_version)], capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"fmu-pack {model} failed: {r.stderr.strip()[-2000:]}")
    return fmu


def unit_library(root=None) -> Path:
    """The unit's shared library of the repository, built with cargo when missing."""
    return cargo_library(UNIT_IDENTIFIER, UNIT_PACKAGE, "the inflation unit", _root(root))


def pack_unit_fmu(out=None, library=None, root=None, fmi_version: int = 2) -> Path:
    """Packs ``InflationUnit.fmu`` (``fmi_version=3``: ``InflationUnit_fmi3.fmu``, FMI 3.0) into
    ``out`` (a file name ending in ``.fmu`` or a directory; default ``target/fmu``) from
    ``library`` (default :func:`unit_library`) and ``fmu/inflation/modelDescription.xml`` (3.0:
    ``modelDescription3.xml``). Returns its path."""
    root = _root(root)
    if fmi_version not in (2, 3):
        raise ValueError(f"fmi_version {fmi_version}: 2 or 3")
    description = root / "fmu" / "inflation" / ("modelDescription.xml" if fmi_version == 2 else "modelDescription3.xml")
    library = Path(library) if library is not None else unit_library(root)
    out = Path(out) if out is not None else root / "target" / "fmu"
    if out.suffix != ".fmu":
        out = out / ("InflationUnit.fmu" if fmi_version == 2 else "InflationUnit_fmi3.fmu")
    out.parent.mkdir(parents=True, exist_ok=True)
    folder = "linux64" if fmi_version == 2 else "x86_64-linux"
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        z.write(description, "modelDescription.xml")
        z.write(library, f"binaries/{folder}/{UNIT_IDENTIFIER}.so")
    return out


def system_structure(film_parameters: dict | None = None, unit_parameters: dict | None = None,
                     start: float = 0.0, stop: float = 120.0, step: float = 1.0) -> str:
    """The text of the cushion system's ``SystemStructure.ssd``: components ``film``
    (``resources/film.fmu``) and ``unit`` (``resources/unit.fmu``), connected through the
    chamber's pressure and mass flow."""
    if not step > 0 or not stop > start:
        raise ValueError(f"need step > 0 and stop > start (step {step}, start {start}, stop {stop})")
    (flow, film_flow), = FLOWS
    (film_pressure, pressure), = PRESSURES
    film = _component("film", "resources/film.fmu", [(film_flow, "input"), (film_pressure, "output")],
                      {**FILM_PARAMETERS, **(film_parameters or {})})
    unit = _component("unit", "resources/unit.fmu", [(pressure, "input"), (flow, "output")], unit_parameters or {})
    connections = connection("unit", flow, "film", film_flow) + connection("film", film_pressure, "unit", pressure)
    return ssd_text("CushionSystem", "cushion", "ETFE cushion kept up by its inflation unit", film + unit,
                    connections, start, stop, step)


def write_cushion_ssp(path, film_fmu, unit_fmu=None, *, film_parameters: dict | None = None,
                      unit_parameters: dict | None = None, start: float = 0.0, stop: float = 120.0,
                      step: float = 1.0) -> Path:
    """Writes the cushion system's ``.ssp`` archive to ``path`` (the unit: ``unit_fmu``, default
    :func:`pack_unit_fmu` into a temporary directory). Returns the path."""
    path = Path(path)
    with tempfile.TemporaryDirectory() as tmp:
        unit_fmu = Path(unit_fmu) if unit_fmu is not None else pack_unit_fmu(Path(tmp))
        path.parent.mkdir(parents=True, exist_ok=True)
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("SystemStructure.ssd",
                       system_structure(film_parameters, unit_parameters, start, stop, step))
            z.write(film_fmu, "resources/film.fmu")
            z.write(unit_fmu, "resources/unit.fmu")
    return path


def cushion_system(film_fmu, unit_fmu, film_parameters: dict | None = None,
                   unit_parameters: dict | None = None):
    """The cushion system as two initialized instances coupled for the master
    (:class:`~membrane_contact.coupling.CoupledSystem`: the film, and the unit as its
    "structure"). Close both when done (:class:`~membrane_contact.coupling.closing`)."""
    from .film import Film

    film = Film(film_fmu, name="cushion", logging=False, quiet=True)
    unit = Film(unit_fmu, name="unit", logging=False, quiet=True)
    film.initialize({**FILM_PARAMETERS, **(film_parameters or {})})
    unit.initialize(unit_parameters or {}, {"pressure": film.get(PRESSURES[0][0])})
    return couple(film, unit)


def couple(film, unit):
    """The master's system of an initialized film and unit at one time, its interface values read
    from them (after restoring saved states, couple them again)."""
    from .coupling import CoupledSystem

    return CoupledSystem(film, unit, displacements=FLOWS, forces=PRESSURES)


#: What :func:`run_events` records per communication step, by column.
COLUMNS = ("time", "pressure", "volume", "mass", "top", "bottom", "snow", "wind", "fed", "massFlow", "fanOn",
           "duty", "dutyTotal", "fanFlow", "snowMode")


def snow_lies(loads: dict) -> bool:
    """The unit's snow mode as a roof's controller with a snow sensor sets it: on while the
    weather's snow load lies on the top layer (``snow.pressure > 0``)."""
    return loads.get("snow.pressure", 0.0) > 0.0


def snow_and_gust(t: float, snow: float = 500.0, suction: float = 400.0) -> dict:
    """The default weather: quiet until 60 s; snow ramped up to ``snow`` Pa (plan) over 60–70 s,
    lying until 120 s, melting by 130 s; a gust of ``suction`` Pa on the top layer over
    170–172 s, held until 182 s, gone by 184 s."""
    def ramp(t0, t1, t2, t3):
        return max(0.0, min(1.0, (t - t0) / (t1 - t0), (t3 - t) / (t3 - t2)))

    return {"snow.pressure": snow * ramp(60.0, 70.0, 120.0, 130.0),
            "wind.pressure": suction * ramp(170.0, 172.0, 182.0, 184.0)}


def run_events(system, duration: float, h: float = 1.0, weather=snow_and_gust, scheme: str = "staggered",
               snow_mode=None) -> dict:
    """Steps the cushion system (:func:`cushion_system`) over ``duration`` in steps of ``h``,
    the top layer's loads of each step ``weather(t + h)`` (reached at the step's end), with the
    master's ``scheme``; returns the records of :data:`COLUMNS` as lists, the first row the
    initial state. ``fed``: the pressure the unit held over the step; ``massFlow``: its flow,
    the one the film took in. ``snow_mode``: a function of a step's loads giving the unit's
    ``snowMode`` for that step (e.g. :func:`snow_lies`); None leaves it as it is."""
    import numpy as np

    film, unit = system.film, system.structure
    rows = []

    def record(loads):
        rows.append((film.time, film["air.pressure"], film["air.volume"], film["air.mass"], film["crownTop.uz"],
                     film["crownBottom.uz"], loads["snow.pressure"], loads["wind.pressure"], unit["pressure"],
                     unit["massFlow"], unit["fanOn"], unit["duty"], unit["dutyTotal"], unit["fanFlow"],
                     float(unit["snowMode"])))

    record(weather(film.time))
    for _ in range(int(round(duration / h))):
        loads = weather(film.time + h)
        film.set(loads)
        if snow_mode is not None:
            unit.set({"snowMode": bool(snow_mode(loads))})
        system.step(h, scheme)
        record(loads)
    return {name: np.asarray(column) for name, column in zip(COLUMNS, zip(*rows))}
