"""membrane-contact from Python: drive the FMU of an ETFE film with friction contact, and turn a
mesh into a model file.

* :class:`Film` — one FMU instance addressed by variable names, with staged load paths
  (:meth:`Film.run`), automatic halving of refused steps (fmi2Discard), FMU-state rollback
  (:meth:`Film.save` / :meth:`Film.restore`) and results as numpy arrays (:class:`Results`);
  the FMU's warnings as :class:`SolverWarning` (``strict=True``: :class:`SolverWarningError`);
* :func:`find_fmu` / :func:`build_fmu` — locate or pack an FMU (``fmu-pack``);
* :func:`membrane_contact.mesh.import_mesh` — a gmsh (or any meshio) mesh and a mapping file
  to a model file, gaps along arches from :mod:`membrane_contact.arches`;
* :mod:`membrane_contact.plot` — slip along a support, reactions against a load, stress maps;
* :mod:`membrane_contact.inverse` — fit μ, parameters or boundary-movement scales to measured
  outputs through the FMU;
* :mod:`membrane_contact.design` — form finding and cutting patterns (the program's ``form-find``
  and ``pattern``).

The FMU names (:class:`Film` and the rest, which need fmpy) are imported on first use, so that
the mesh importer (:mod:`membrane_contact.mesh`: numpy and meshio) imports without fmpy.
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .film import Film, FmuError, Results, SolverWarning, SolverWarningError, StepRefused
    from .fmu import build_fmu, find_fmu, repository_root

__all__ = ["Film", "Results", "StepRefused", "FmuError", "SolverWarning", "SolverWarningError", "build_fmu",
           "find_fmu", "repository_root"]

#: Where each public name lives (imported on first use: PEP 562).
_LAZY = {"Film": "film", "Results": "film", "StepRefused": "film", "FmuError": "film", "SolverWarning": "film",
         "SolverWarningError": "film", "build_fmu": "fmu", "find_fmu": "fmu", "repository_root": "fmu"}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'membrane_contact' has no attribute '{name}'")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(list(globals()) + __all__)


def _version() -> str:
    """The one version: Cargo.toml's. Installed, the wheel's metadata carries it (the build backend
    takes it from Cargo.toml); from a checkout, Cargo.toml itself."""
    cargo = Path(__file__).resolve().parents[2] / "Cargo.toml"
    if cargo.is_file() and (cargo.parent / "python" / "membrane_contact").is_dir():
        import re

        match = re.search(r'(?m)^\[package\][^\[]*?^version\s*=\s*"([^"]+)"', cargo.read_text())
        if match:
            return match.group(1)
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("membrane-contact")
    except PackageNotFoundError:
        return "0+unknown"


__version__ = _version()
