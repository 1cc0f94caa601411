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
  outputs through the FMU.
"""

from .film import Film, FmuError, Results, SolverWarning, SolverWarningError, StepRefused
from .fmu import build_fmu, find_fmu, repository_root

__version__ = "0.1.0"

__all__ = ["Film", "Results", "StepRefused", "FmuError", "SolverWarning", "SolverWarningError", "build_fmu",
           "find_fmu", "repository_root"]
