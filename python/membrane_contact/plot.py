"""Plots of a run (matplotlib, imported when a function is called; ``meshio`` for VTK files).

Each function draws into ``ax`` (a new figure's axes when None) and returns the axes.
"""

from __future__ import annotations

import numpy as np


def _axes(ax):
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots()
    return ax


def slip_along_support(results, gaps=None, times=None, ax=None, component="slip"):
    """Slip (mm) of each gap, in the model's order along the support, at the given ``times``
    (default: the last); open gaps are not marked here (plot ``<gap>.status`` for that)."""
    ax = _axes(ax)
    names, slips = results.slips(gaps, component)
    t = results.time
    picks = [len(t) - 1] if times is None else [int(np.argmin(abs(t - x))) for x in times]
    for k in picks:
        ax.plot(range(len(names)), slips[k] * 1e3, marker="o", label=f"t = {t[k]:g}")
    ax.set_xticks(range(len(names)), names, rotation=90 if len(names) > 12 else 0)
    ax.set_xlabel("gap (along the support)")
    ax.set_ylabel(f"{component} (mm)" if component.startswith("slip") else component)
    ax.legend()
    return ax


def reactions_vs_load(results, load: str, reaction: str, components="xyz", ax=None):
    """Reaction components of ``reaction`` (a group or support set, or ``reactions``) against
    the output or input column ``load`` (e.g. ``"time"``, ``"frame.Rz"``, ``"mid.uz"``)."""
    ax = _axes(ax)
    x = results.time if load == "time" else results[load]
    r = results.reaction(reaction)
    for c, axis in enumerate("xyz"):
        if axis in components and not np.isnan(r[:, c]).all():
            ax.plot(x, r[:, c], marker=".", label=f"{reaction}.R{axis}")
    ax.set_xlabel(load)
    ax.set_ylabel("reaction (N)")
    ax.legend()
    return ax


def stress_map(vtu_file, field="von_mises", view="xy", deformed=True, ax=None, scale=1e-6, cmap="viridis"):
    """The film's cell field ``field`` (default von Mises, in MPa with ``scale=1e-6``) from a
    ``<model>_film_NNNN.vtu`` the FMU or the CLI wrote, drawn on the (deformed) mesh projected
    on the plane ``view`` (``"xy"``, ``"xz"`` or ``"yz"``)."""
    import meshio

    ax = _axes(ax)
    mesh = meshio.read(vtu_file)
    triangles = next(c.data for c in mesh.cells if c.type == "triangle")
    k = [c.type for c in mesh.cells].index("triangle")
    values = np.asarray(mesh.cell_data[field][k], dtype=float)
    if values.ndim > 1:
        raise ValueError(f"'{field}' has {values.shape[1]} components: pick a scalar field")
    points = np.asarray(mesh.points, dtype=float)
    if not deformed and "displacement" in mesh.point_data:
        points = points - mesh.point_data["displacement"]
    i, j = ("xyz".index(view[0]), "xyz".index(view[1]))
    art = ax.tripcolor(points[:, i], points[:, j], triangles, facecolors=values * scale, cmap=cmap)
    ax.figure.colorbar(art, ax=ax, label=f"{field}" + (" (MPa)" if scale == 1e-6 else ""))
    ax.set_aspect("equal")
    ax.set_xlabel(f"{view[0]} (m)")
    ax.set_ylabel(f"{view[1]} (m)")
    return ax
