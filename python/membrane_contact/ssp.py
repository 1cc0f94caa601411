"""The coupled erection system as an SSP archive (System Structure and Parameterization 1.0):
the film FMU and the hydraulic jack FMU (``fmu/jack``), their connections and parameter values,
in one ``.ssp`` file that fmpy and libcosim run as it is.

* :func:`pack_jack_fmu` packs ``HydraulicJack.fmu`` from the jack's library
  (``target/release/libhydraulic_jack.so``, built by ``cargo build --release``) and its
  ``fmu/jack/modelDescription.xml`` (``fmi_version=3``: ``HydraulicJack_fmi3.fmu`` with
  ``modelDescription3.xml``); installed from the wheel, from the copies the wheel ships
  (``PREFIX/lib/membrane-contact/``), no Rust toolchain needed;
* :func:`write_ssp` writes ``SystemStructure.ssd`` and both FMUs (``resources/``) into the
  archive: the connections ``jack.dz → film.<group>.dz`` and ``film.<group>.Rz → jack.force``
  (the force the frame applies to the film is the force the jack applies to the frame), each
  component's parameter values inline (``ssd:ParameterBindings``, which libcosim applies), the
  default experiment and libcosim's fixed-step annotation;
* :func:`fmpy_parameter_set`: fmpy's ``simulate_ssp`` takes the parameter values as an
  argument; this reads them from the archive's bindings, named ``component.variable``.

Both tools exchange explicitly (Jacobi: every FMU steps with the other's outputs of the last
communication point, whatever the components' order: docs/fmu.md quotes both tools' loops),
which is stable only where the jack is stiffer than the film (``membrane_contact.coupling``
iterates instead); their end values are the master's ``"jacobi"`` run's.

    python -m membrane_contact.ssp erection.ssp [--film F.fmu] [--jack J.fmu] [--stop 400]
        [--step 5] [--set jack.stiffness=1e5 --set film.archHeight=0.3 ...]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import tempfile
import zipfile
from pathlib import Path
from xml.sax.saxutils import quoteattr

from .fmu import ROOT_VARIABLE, _own_checkout, find_fmu, installed_file, repository_root

#: The jack's model identifier (its library's name in the FMU).
JACK_IDENTIFIER = "hydraulic_jack"

#: Default parameter values of the erection system: the 300 mm specimen with μ = 0.2, the FMU
#: without internal cutbacks; a jack 10x stiffer than the film gets at the end of the stroke.
FILM_PARAMETERS = {"archHeight": 0.3, "mu": 0.2}
JACK_PARAMETERS = {"stiffness": 1.0e5, "relief": 600.0}

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
OSP = "http://opensimulationplatform.com/SSP/OSPAnnotations"


#: The jack's library and model descriptions (FMI 2.0, FMI 3.0) as the wheel installs them (in
#: ``PREFIX/lib/membrane-contact``; python/build_backend stages them).
INSTALLED_JACK_LIBRARY, INSTALLED_JACK_DESCRIPTION = f"lib{JACK_IDENTIFIER}.so", "hydraulic_jack.xml"
INSTALLED_JACK_DESCRIPTION3 = "hydraulic_jack3.xml"


def _installed_jack(fmi_version: int = 2) -> tuple[Path, Path] | None:
    """The wheel's jack library and model description of ``fmi_version`` when this package is
    installed (not a checkout's ``python/``, no ``$MEMBRANE_CONTACT_ROOT``), else None."""
    if _own_checkout() is not None or os.environ.get(ROOT_VARIABLE):
        return None
    lib = installed_file(INSTALLED_JACK_LIBRARY, "membrane-contact")
    name = INSTALLED_JACK_DESCRIPTION if fmi_version == 2 else INSTALLED_JACK_DESCRIPTION3
    md = installed_file(name, "membrane-contact")
    return (lib, md) if lib is not None and md is not None else None


def jack_library(root=None) -> Path:
    """The jack's shared library: the repository's (``root``, ``$MEMBRANE_CONTACT_ROOT``, or the
    checkout this package lives in), built with cargo when missing; installed from the wheel,
    the wheel's copy; else the repository around the current directory's."""
    if root is None and _installed_jack() is not None:
        return _installed_jack()[0]
    return cargo_library(JACK_IDENTIFIER, "hydraulic-jack-fmu", "the jack", root)


def cargo_library(identifier: str, package: str, what: str, root=None) -> Path:
    """The repository's (``root``, ``$MEMBRANE_CONTACT_ROOT``, or the checkout this package
    lives in) release library ``lib<identifier>.so`` of the cargo package ``package``, built
    when missing (``what`` names the FMU in the messages)."""
    root = Path(root) if root is not None else repository_root()
    if root is None:
        raise RuntimeError(f"{what} FMU is built from the repository (fmu/) or installed with the "
                           "membrane-contact wheel: neither found")
    lib = root / "target" / "release" / f"lib{identifier}.so"
    if not lib.is_file():
        r = subprocess.run(["cargo", "build", "--release", "-p", package], cwd=root,
                           capture_output=True, text=True)
        if r.returncode != 0 or not lib.is_file():
            raise RuntimeError(f"cargo build of {what} failed: {r.stderr.strip()[-2000:]}")
    return lib


#: Platforms the jack FMU can carry besides linux64 (``fmu-pack --platforms`` names the same
#: folders): folder under ``binaries/`` → (cargo's target triple, the library's file name as cargo
#: writes it, its extension in the FMU). tests/platforms.sh cross-builds them.
CROSS_PLATFORMS = {
    "win64": ("x86_64-pc-windows-gnu", f"{JACK_IDENTIFIER}.dll", "dll"),
    "aarch64-linux": ("aarch64-unknown-linux-gnu", f"lib{JACK_IDENTIFIER}.so", "so"),
    "darwin64": ("x86_64-apple-darwin", f"lib{JACK_IDENTIFIER}.dylib", "dylib"),
    "aarch64-darwin": ("aarch64-apple-darwin", f"lib{JACK_IDENTIFIER}.dylib", "dylib"),
}


#: The FMI 3.0 folders under ``binaries/`` of the platforms of :data:`CROSS_PLATFORMS` (FMI 3.0
#: §2.5.1.4 names them by architecture and operating system), and of the host.
FMI3_FOLDERS = {"linux64": "x86_64-linux", "win64": "x86_64-windows", "aarch64-linux": "aarch64-linux",
                "darwin64": "x86_64-darwin", "aarch64-darwin": "aarch64-darwin"}


def pack_jack_fmu(out=None, library=None, root=None, platforms=(), fmi_version: int = 2) -> Path:
    """Packs ``HydraulicJack.fmu`` (``fmi_version=3``: ``HydraulicJack_fmi3.fmu``, FMI 3.0, the
    same library under ``binaries/x86_64-linux/``) into ``out`` (a file name ending in ``.fmu``
    or a directory; default the repository's ``target/fmu``, installed the current directory)
    from ``library`` (default :func:`jack_library`) and the model description (the repository's
    ``fmu/jack/modelDescription.xml``, 3.0: ``modelDescription3.xml``, both generated from the
    jack's table; installed from the wheel, their copies). Returns its path. ``platforms``:
    further binaries (folders of :data:`CROSS_PLATFORMS`, or for 3.0 their
    :data:`FMI3_FOLDERS`), each the repository's cross build ``target/<triple>/release/<file>``."""
    if fmi_version not in (2, 3):
        raise ValueError(f"fmi_version {fmi_version}: 2 or 3")
    installed = _installed_jack(fmi_version) if root is None else None
    if installed is not None:
        description = installed[1]
        library = Path(library) if library is not None else installed[0]
        out = Path(out) if out is not None else Path.cwd()
    else:
        root = Path(root) if root is not None else repository_root()
        if root is None:
            raise RuntimeError("the jack FMU is packed from the repository (fmu/jack) or installed with the "
                               "membrane-contact wheel: neither found")
        description = root / "fmu" / "jack" / ("modelDescription.xml" if fmi_version == 2 else "modelDescription3.xml")
        library = Path(library) if library is not None else jack_library(root)
        out = Path(out) if out is not None else root / "target" / "fmu"
    if out.suffix != ".fmu":
        out = out / ("HydraulicJack.fmu" if fmi_version == 2 else "HydraulicJack_fmi3.fmu")
    host = "linux64" if fmi_version == 2 else FMI3_FOLDERS["linux64"]
    # Each further platform by the key of CROSS_PLATFORMS (3.0 also takes its 3.0 folder name).
    keys = {f: f for f in CROSS_PLATFORMS}
    if fmi_version == 3:
        keys.update({FMI3_FOLDERS[f]: f for f in CROSS_PLATFORMS})
    cross = [keys.get(f, f) for f in platforms if f not in ("linux64", host)]
    for key in cross:
        if key not in CROSS_PLATFORMS:
            raise ValueError(f"unknown platform {key!r} (known: {host}, {', '.join(keys)})")
    out.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        z.write(description, "modelDescription.xml")
        z.write(library, f"binaries/{host}/{JACK_IDENTIFIER}.so")
        for key in cross:
            triple, name, extension = CROSS_PLATFORMS[key]
            built = (root or repository_root() or Path.cwd()) / "target" / triple / "release" / name
            if not built.is_file():
                raise RuntimeError(f"no {built}: run `cargo build --release --lib -p hydraulic-jack-fmu "
                                   f"--target {triple}` first (tests/platforms.sh does)")
            folder = key if fmi_version == 2 else FMI3_FOLDERS[key]
            z.write(built, f"binaries/{folder}/{JACK_IDENTIFIER}.{extension}")
    return out


def _typed(value) -> tuple[str, str]:
    """SSP type element and value text of a parameter value."""
    if isinstance(value, bool):
        return "Boolean", "true" if value else "false"
    if isinstance(value, int):
        return "Integer", str(value)
    if isinstance(value, float):
        return "Real", repr(value)
    return "String", str(value)


def _connector(name: str, kind: str) -> str:
    return f'<ssd:Connector name={quoteattr(name)} kind="{kind}"><ssc:Real/></ssd:Connector>'


def _component(name: str, source: str, connectors, parameters: dict) -> str:
    params = "".join(
        f'<ssv:Parameter name={quoteattr(p)}><ssv:{t} value={quoteattr(v)}/></ssv:Parameter>'
        for p, (t, v) in ((p, _typed(v)) for p, v in parameters.items()))
    bindings = (f'<ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>'
                f'<ssv:ParameterSet version="1.0" name="{name}"><ssv:Parameters>{params}</ssv:Parameters>'
                f'</ssv:ParameterSet></ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>'
                if parameters else "")
    return (f'<ssd:Component name="{name}" type="application/x-fmu-sharedlibrary" source="{source}">'
            f'<ssd:Connectors>{"".join(_connector(n, k) for n, k in connectors)}</ssd:Connectors>'
            f'{bindings}</ssd:Component>')


def system_structure(group: str = "frame", film_parameters: dict | None = None,
                     jack_parameters: dict | None = None, start: float = 0.0, stop: float = 400.0,
                     step: float = 5.0) -> str:
    """The text of ``SystemStructure.ssd``: components ``film`` (``resources/film.fmu``) and
    ``jack`` (``resources/jack.fmu``), the interface of the film's group ``group``."""
    if not step > 0 or not stop > start:
        raise ValueError(f"need step > 0 and stop > start (step {step}, start {start}, stop {stop})")
    film = _component("film", "resources/film.fmu", [(f"{group}.dz", "input"), (f"{group}.Rz", "output")],
                      {**FILM_PARAMETERS, **(film_parameters or {})})
    jack = _component("jack", "resources/jack.fmu", [("force", "input"), ("dz", "output")],
                      {**JACK_PARAMETERS, **(jack_parameters or {})})
    connections = connection("jack", "dz", "film", f"{group}.dz") + connection("film", f"{group}.Rz", "jack", "force")
    return ssd_text("ErectionSystem", "erection", f"film carried by a hydraulic jack through the group {group}",
                    film + jack, connections, start, stop, step)


def connection(start: str, start_connector: str, end: str, end_connector: str) -> str:
    """One ``ssd:Connection`` element."""
    return (f'<ssd:Connection startElement="{start}" startConnector={quoteattr(start_connector)} '
            f'endElement="{end}" endConnector={quoteattr(end_connector)}/>')


def ssd_text(name: str, system: str, description: str, elements: str, connections: str, start: float,
             stop: float, step: float) -> str:
    """The text of a ``SystemStructure.ssd``: the system ``system`` of ``elements`` (components)
    and ``connections``, the default experiment and libcosim's fixed-step annotation."""
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<ssd:SystemStructureDescription xmlns:ssd="{SSD}" xmlns:ssc="{SSC}" xmlns:ssv="{SSV}" '
            f'xmlns:osp="{OSP}" version="1.0" name="{name}" generationTool="membrane_contact.ssp">'
            f'<ssd:System name="{system}" description={quoteattr(description)}>'
            f'<ssd:Elements>{elements}</ssd:Elements><ssd:Connections>{connections}</ssd:Connections></ssd:System>'
            f'<ssd:DefaultExperiment startTime="{start!r}" stopTime="{stop!r}"><ssd:Annotations>'
            f'<ssc:Annotation type="com.opensimulationplatform"><osp:Algorithm>'
            f'<osp:FixedStepAlgorithm baseStepSize="{step!r}"/></osp:Algorithm></ssc:Annotation>'
            f'</ssd:Annotations></ssd:DefaultExperiment></ssd:SystemStructureDescription>\n')


def write_ssp(path, film_fmu=None, jack_fmu=None, *, group: str = "frame", film_parameters: dict | None = None,
              jack_parameters: dict | None = None, start: float = 0.0, stop: float = 400.0,
              step: float = 5.0) -> Path:
    """Writes the erection system's ``.ssp`` archive to ``path`` (the film: ``film_fmu``,
    default :func:`find_fmu`, the ParallelArch specimen; the jack: ``jack_fmu``, default
    :func:`pack_jack_fmu` into a temporary directory). ``film_parameters`` and
    ``jack_parameters`` are added to :data:`FILM_PARAMETERS` and :data:`JACK_PARAMETERS`
    (Python ``int``: an SSP Integer, ``float``: Real, ``bool``: Boolean, else String). Returns
    the path."""
    path = Path(path)
    film_fmu = find_fmu(film_fmu)
    with tempfile.TemporaryDirectory() as tmp:
        jack_fmu = Path(jack_fmu) if jack_fmu is not None else pack_jack_fmu(Path(tmp) / "HydraulicJack.fmu")
        path.parent.mkdir(parents=True, exist_ok=True)
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("SystemStructure.ssd",
                       system_structure(group, film_parameters, jack_parameters, start, stop, step))
            z.write(film_fmu, "resources/film.fmu")
            z.write(jack_fmu, "resources/jack.fmu")
    return path


def fmpy_parameter_set(ssp_path):
    """The parameter values of the archive's components as one fmpy ``ParameterSet`` with names
    ``component.variable``, the form ``fmpy.ssp.simulation.simulate_ssp(parameter_set=…)``
    applies."""
    from fmpy.ssp.ssd import ParameterSet, read_ssd

    ssd = read_ssd(str(ssp_path))
    merged = ParameterSet(name="components")
    for component in ssd.system.elements:
        for binding in getattr(component, "parameterBindings", []):
            for pset in binding.parameterValues:
                for p in pset.parameters:
                    p.name = f"{component.name}.{p.name}"
                    merged.parameters.append(p)
    return merged


def _value(text: str):
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return {"true": True, "false": False}.get(text, text)


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m membrane_contact.ssp", description=__doc__.splitlines()[0])
    p.add_argument("out", help="the .ssp file to write")
    p.add_argument("--film", help="film FMU (default: target/fmu/ParallelArch.fmu)")
    p.add_argument("--jack", help="jack FMU (default: packed from target/release)")
    p.add_argument("--group", default="frame", help="the film's group the jack carries (frame)")
    p.add_argument("--start", type=float, default=0.0)
    p.add_argument("--stop", type=float, default=400.0)
    p.add_argument("--step", type=float, default=5.0)
    p.add_argument("--set", action="append", default=[], metavar="COMPONENT.NAME=VALUE",
                   help="a parameter value, e.g. jack.stiffness=2e5 or film.archHeight=0.3")
    a = p.parse_args(argv)
    values = {"film": {}, "jack": {}}
    for item in a.set:
        name, eq, text = item.partition("=")
        component, dot, variable = name.partition(".")
        if not eq or not dot or component not in values:
            p.error(f"--set {item}: expected film.NAME=VALUE or jack.NAME=VALUE")
        values[component][variable] = _value(text)
    out = write_ssp(a.out, a.film, a.jack, group=a.group, film_parameters=values["film"],
                    jack_parameters=values["jack"], start=a.start, stop=a.stop, step=a.step)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
