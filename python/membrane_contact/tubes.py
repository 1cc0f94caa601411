"""Curved supports (tubes) from a mesh: a centreline fitted to the points of a physical curve,
and the film nodes that may touch the tube.

``fit_centreline(points)`` takes the points of a curve in their order along it (the nodes of a
gmsh ``Physical Curve`` drawn along the tube's axis) and returns the model file's
``centreline`` (docs/model-format.md, "Curved supports"):

* a **circle** arc when the points lie on a circle within the tolerance: the least-squares
  circle in the points' plane (algebraic fit refined by Gauss–Newton on the distances), travelled
  counter-clockwise about its ``axis`` from the first point to the last (so that ``t × p`` is
  the outer side of an arch);
* else a **parabola** when they lie on one: the axis from a conic fitted to the points (its
  quadratic part's null direction) or, for a symmetric arch, the chord's normal, whichever fits
  better; the arch ``apex + s·along − (rise/half_span²) s² up`` must span the points
  symmetrically about its apex (the model's parabola has one ``half_span``);
* else a **polyline** through the points (a straight one, with a ``normal`` whose ``t × p`` side
  is up, when they lie on a line).

The residual of a fit is the largest distance from a point to the fitted curve (m), out-of-plane
distance included. ``shape`` forces a kind (an error names the residual when it is above the
tolerance); the default ``"auto"`` takes the circle or parabola of smaller residual when it is
within the tolerance, else the polyline.

``tube_nodes`` selects the film nodes of a curved support: those within a search band of the
tube surface (distance to the centreline minus the tube radius), refusing a node inside the
tube. Errors are :class:`TubeError` naming the item.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .arches import Parabola as _ArchParabola


class TubeError(ValueError):
    """A centreline or a set of contact nodes that cannot be built; the message names the item."""


#: Default fit tolerance as a share of the tube radius: 1 % (0.3 mm for a 60 mm tube).
DEFAULT_TOLERANCE_SHARE = 0.01


@dataclass
class CentrelineFit:
    """A fitted centreline: ``kind`` (``circle``, ``parabola``, ``polyline``), the model file's
    ``centreline`` object, the fit ``residual`` (m, largest point distance to the curve) and the
    residuals of every shape tried (``tried``: kind → residual, ``inf`` when it does not apply)."""

    kind: str
    centreline: dict
    residual: float
    tolerance: float
    tried: dict = field(default_factory=dict)

    def describe(self) -> str:
        """One line: the shape, its parameters and the residual."""
        spec = self.centreline[self.kind]
        r = lambda v: "(" + ", ".join(f"{x:.6g}" for x in v) + ")"  # noqa: E731
        if self.kind == "circle":
            what = (f"circle arc, centre {r(spec['centre'])}, radius {spec['radius']:.6g} m, "
                    f"{spec.get('angles', [0, 2 * math.pi])[1]:.6g} rad")
        elif self.kind == "parabola":
            what = (f"parabola, apex {r(spec['apex'])}, up {r(spec['up'])}, half span {spec['half_span']:.6g} m, "
                    f"rise {spec['rise']:.6g} m")
        else:
            what = f"polyline of {len(spec['points'])} points"
        others = ", ".join(f"{k} {v:.3g} m" for k, v in self.tried.items() if k != self.kind)
        return (f"{what}; fit residual {self.residual:.3g} m (tolerance {self.tolerance:.3g} m"
                + (f"; {others}" if others else "") + ")")


def _list(v) -> list[float]:
    """A vector as a list of floats, without "-0.0"."""
    return (np.asarray(v, dtype=float) + 0.0).tolist()


def _unit(v):
    return v / np.linalg.norm(v)


def _plane(points: np.ndarray):
    """Centroid, unit normal of the best plane, out-of-plane residual, and whether the points
    lie on a line (second singular value ≈ 0)."""
    c = points.mean(axis=0)
    _, s, vt = np.linalg.svd(points - c)
    size = max(float(np.ptp(points, axis=0).max()), 1e-300)
    collinear = len(points) < 3 or s[1] <= 1e-12 * max(s[0], 1e-300) * math.sqrt(len(points))
    normal = vt[2]
    off = float(np.max(np.abs((points - c) @ normal))) if not collinear else 0.0
    return c, normal, off, collinear, size


def _circle_2d(q: np.ndarray):
    """Least-squares circle (centre, radius) of 2-D points: Kåsa's algebraic fit refined by
    Gauss–Newton on the geometric distances."""
    a = np.column_stack([2 * q, np.ones(len(q))])
    b = (q * q).sum(axis=1)
    (cx, cy, k), *_ = np.linalg.lstsq(a, b, rcond=None)
    centre = np.array([cx, cy])
    radius = math.sqrt(max(k + centre @ centre, 0.0))
    for _ in range(20):
        d = q - centre
        dist = np.linalg.norm(d, axis=1)
        if np.any(dist == 0):
            break
        res = dist - radius
        jac = np.column_stack([-d / dist[:, None], -np.ones(len(q))])
        step, *_ = np.linalg.lstsq(jac, -res, rcond=None)
        centre, radius = centre + step[:2], radius + step[2]
        if np.linalg.norm(step) <= 1e-15 * max(radius, 1e-300):
            break
    return centre, float(radius)


def _fit_circle(points, c, normal, e1, e2, tol):
    q = np.column_stack([(points - c) @ e1, (points - c) @ e2])
    if len(points) < 3:
        return None, math.inf
    centre2, radius = _circle_2d(q)
    if not (math.isfinite(radius) and radius > 0):
        return None, math.inf
    centre = c + centre2[0] * e1 + centre2[1] * e2
    # travel counter-clockwise about the axis from the first point to the last
    rel = points - centre
    turning = sum(np.cross(a, b) for a, b in zip(rel[:-1], rel[1:])) @ normal
    axis = normal if turning >= 0 else -normal
    start = rel[0] - (rel[0] @ axis) * axis
    start = _unit(start)
    other = np.cross(axis, start)
    angles = np.unwrap(np.arctan2(rel @ other, rel @ start))
    sweep = float(angles[-1] - angles[0])
    closed = np.linalg.norm(points[-1] - points[0]) <= tol
    if closed:
        sweep = 2 * math.pi
    if not (0 < sweep <= 2 * math.pi + 1e-9) or np.any(np.diff(angles) <= 0):
        return None, math.inf
    radial = np.linalg.norm(rel - np.outer(rel @ axis, axis), axis=1)
    residual = float(np.max(np.hypot(radial - radius, rel @ axis)))
    spec = {"centre": _list(centre), "axis": _list(axis), "radius": radius,
            "angles": [0.0, min(sweep, 2 * math.pi)], "start_direction": _list(start)}
    return spec, residual


def _parabola_residual(spec, points, tol):
    """Largest distance from the points to the arch, or inf when a point lies beyond its ends."""
    try:
        arch = _ArchParabola({"type": "parabola", **spec}, "fit")
    except ValueError:
        return math.inf
    worst = 0.0
    for p in points:
        off = float((p - arch.origin) @ arch.normal)
        q = p - off * arch.normal
        c = arch.closest(q)  # beyond an end: the end point
        worst = max(worst, math.hypot(float(np.linalg.norm(q - c.point)), off))
    return worst


def _fit_parabola_along(points, c, normal, up, tol):
    """The parabola with axis ``up`` (in the plane) through the points by least squares, as the
    model's symmetric arch, or (None, inf)."""
    up = _unit(up - (up @ normal) * normal)
    along = np.cross(up, normal)
    if (points[-1] - points[0]) @ along < 0:
        along = -along
    s = (points - c) @ along
    u = (points - c) @ up
    (g, b, a), *_ = np.linalg.lstsq(np.column_stack([s * s, s, np.ones(len(s))]), u, rcond=None)
    if abs(g) <= 1e-12 / max(float(np.ptp(s)), 1e-300):
        return None, math.inf
    if g > 0:  # the crown is the highest point along "up": fit again about the opposite axis
        return _fit_parabola_along(points, c, normal, -up, tol)
    s0 = -b / (2 * g)
    u0 = a - b * b / (4 * g)
    spans = np.abs(s - s0)
    half_span = float(max(spans[0], spans[-1]))
    if abs(spans[0] - spans[-1]) > tol:
        return None, math.inf  # not symmetric about the apex: the model's parabola cannot take it
    apex = c + s0 * along + u0 * up
    spec = {"apex": _list(apex), "up": _list(up), "along": _list(along), "half_span": half_span,
            "rise": float(-g * half_span * half_span)}
    return spec, _parabola_residual(spec, points, tol)


def _conic_axis(q: np.ndarray):
    """The axis direction of the conic fitted to 2-D points (the null direction of its quadratic
    part), or None."""
    if len(q) < 5:
        return None
    scale = max(float(np.abs(q).max()), 1e-300)
    x, y = q[:, 0] / scale, q[:, 1] / scale
    design = np.column_stack([x * x, x * y, y * y, x, y, np.ones(len(x))])
    _, _, vt = np.linalg.svd(design)
    a, b, cc = vt[-1][:3]
    w, v = np.linalg.eigh(np.array([[a, b / 2], [b / 2, cc]]))
    return v[:, int(np.argmin(np.abs(w)))]


def _fit_parabola(points, c, normal, e1, e2, tol):
    chord = points[-1] - points[0]
    chord = chord - (chord @ normal) * normal
    candidates = []
    if np.linalg.norm(chord) > 0:
        candidates.append(np.cross(normal, _unit(chord)))  # a symmetric arch: axis ⟂ chord
    q = np.column_stack([(points - c) @ e1, (points - c) @ e2])
    axis2 = _conic_axis(q)
    if axis2 is not None:
        candidates.append(axis2[0] * e1 + axis2[1] * e2)
    best = (None, math.inf)
    for up in candidates:
        spec, res = _fit_parabola_along(points, c, normal, up, tol)
        if res < best[1]:
            best = (spec, res)
    return best


def _polyline(points, normal, collinear):
    spec = {"points": [_list(p) for p in points]}
    if collinear:
        t = _unit(points[-1] - points[0])
        up = np.array([0.0, 0.0, 1.0]) if abs(t[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        spec = {"points": [_list(points[0]), _list(points[-1])], "normal": _list(_unit(np.cross(up, t)))}
    return spec


def fit_centreline(points, tolerance: float, shape: str = "auto", name: str = "curve") -> CentrelineFit:
    """The centreline through ``points`` (n × 3, in order along the curve): a circle arc or a
    parabola when one fits within ``tolerance`` (m), else a polyline; ``shape`` (``auto``,
    ``circle``, ``parabola``, ``polyline``) forces one. Raises :class:`TubeError` naming ``name``
    for fewer than two points, points off one plane, or a forced shape that does not fit."""
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 2:
        raise TubeError(f"centreline '{name}': needs at least two points along the curve, got {len(pts)}")
    if shape not in ("auto", "circle", "parabola", "polyline"):
        raise TubeError(f"centreline '{name}': shape {shape!r} must be \"auto\", \"circle\", \"parabola\" or \"polyline\"")
    c, normal, off, collinear, _ = _plane(pts)
    if off > tolerance:
        raise TubeError(f"centreline '{name}': its {len(pts)} points do not lie in one plane (the farthest is "
                        f"{off:.3g} m off the best plane, tolerance {tolerance:.3g} m): a curved support's "
                        "centreline is a plane curve; split it into plane pieces")
    tried = {}
    fits = {}
    if not collinear:
        e1 = _unit(pts[-1] - pts[0] - ((pts[-1] - pts[0]) @ normal) * normal) \
            if np.linalg.norm(pts[-1] - pts[0]) > tolerance else _unit(np.cross(normal, [1.0, 0.0, 0.0])
                                                                        if abs(normal[0]) < 0.9 else np.cross(normal, [0.0, 1.0, 0.0]))
        e2 = np.cross(normal, e1)
        fits["circle"] = _fit_circle(pts, c, normal, e1, e2, tolerance)
        fits["parabola"] = _fit_parabola(pts, c, normal, e1, e2, tolerance)
        tried = {k: v[1] for k, v in fits.items()}
    else:
        tried = {"circle": math.inf, "parabola": math.inf}
    if shape in ("circle", "parabola"):
        spec, res = fits.get(shape, (None, math.inf))
        if spec is None or res > tolerance:
            raise TubeError(f"centreline '{name}': its {len(pts)} points do not lie on a {shape} within "
                            f"{tolerance:.3g} m (residual {res:.3g} m)")
        return CentrelineFit(shape, {shape: spec}, res, tolerance, tried)
    if shape == "auto":
        good = [(v[1], k) for k, v in fits.items() if v[0] is not None and v[1] <= tolerance]
        if good:
            res, kind = min(good)
            return CentrelineFit(kind, {kind: fits[kind][0]}, res, tolerance, tried)
    spec = _polyline(pts, normal, collinear)
    residual = 0.0
    if collinear:
        t = _unit(pts[-1] - pts[0])
        rel = pts - pts[0]
        residual = float(np.max(np.linalg.norm(rel - np.outer(rel @ t, t), axis=1)))
    return CentrelineFit("polyline", {"polyline": spec}, residual, tolerance, tried)


def sample_centreline(centreline: dict, count: int = 4001) -> np.ndarray:
    """Points along a centreline (circle arc, parabola or polyline), in order: the polyline
    through them is the curve to within its chord sag."""
    kind, spec = next(iter(centreline.items()))
    if kind == "circle":
        centre, axis = np.asarray(spec["centre"], float), _unit(np.asarray(spec["axis"], float))
        start = np.asarray(spec["start_direction"], float)
        start = _unit(start - (start @ axis) * axis)
        lo, hi = spec.get("angles", [0.0, 2 * math.pi])
        a = np.linspace(lo, hi, count)
        other = np.cross(axis, start)
        return centre + spec["radius"] * (np.outer(np.cos(a), start) + np.outer(np.sin(a), other))
    if kind == "parabola":
        apex, up, along = (np.asarray(spec[k], float) for k in ("apex", "up", "along"))
        up = _unit(up)
        along = _unit(along - (along @ up) * up)
        s = np.linspace(-spec["half_span"], spec["half_span"], count)
        k = spec["rise"] / spec["half_span"] ** 2
        return apex + np.outer(s, along) - np.outer(k * s * s, up)
    if kind == "polyline":
        return np.asarray(spec["points"], float)
    raise TubeError(f"centreline kind {kind!r} is not circle, parabola or polyline")


def distances_to_polyline(nodes: np.ndarray, chain: np.ndarray) -> np.ndarray:
    """Distance of each node to the polyline ``chain`` (segments between consecutive points,
    end points included)."""
    a, b = chain[:-1], chain[1:]
    ab = b - a
    length2 = np.maximum((ab * ab).sum(axis=1), 1e-300)
    out = np.empty(len(nodes))
    for i, p in enumerate(nodes):
        t = np.clip(((p - a) * ab).sum(axis=1) / length2, 0.0, 1.0)
        closest = a + t[:, None] * ab
        out[i] = float(np.sqrt(((p - closest) ** 2).sum(axis=1)).min())
    return out


def tube_nodes(centreline: dict, tube_radius: float, nodes: np.ndarray, candidates, band: float | None,
               name: str, label) -> list[int]:
    """The candidate film nodes (indices into ``nodes``) within ``band`` (m) of the tube surface
    (all candidates when ``band`` is None), sorted. A candidate inside the tube (closer to the
    centreline than ``tube_radius``, beyond rounding) is an error naming it (``label(node)``)."""
    candidates = np.asarray(list(candidates), dtype=int)
    if not len(candidates):
        return []
    curve = sample_centreline(centreline)
    size = float(np.linalg.norm(np.ptp(curve, axis=0))) or 1.0
    dist = distances_to_polyline(nodes[candidates], curve) - tube_radius
    chosen = []
    for v, d in zip(candidates, dist):
        if band is not None and d > band:
            continue
        if d < -1e-9 * size:
            raise TubeError(f"curved support '{name}': film {label(int(v))} lies {-d:.6g} m inside the tube "
                            f"(radius {tube_radius:g} m): the film must start outside it")
        chosen.append(int(v))
    return sorted(chosen)
