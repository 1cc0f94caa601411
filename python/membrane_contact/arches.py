"""Friction gaps from film nodes to a support curve (an arch), with the paper's §4.3 frames.

A support is a plane curve: a circle arc, a parabola or a polyline, swept along the normal of
its plane (an arch seen as a cylinder strip: a film node a little off the arch's plane is
treated as lying over it). For each selected film node ``A`` the importer

1. projects ``A`` onto the curve's plane: ``A' = A - ((A - O)·n) n`` (``n`` the plane normal);
2. finds the closest point ``P`` of the curve to ``A'`` and the unit tangent ``t`` there;
3. builds the gap frame (Bui & Kawabata 2016, §4.3; ``src/specimens/parallel_arch.rs``, ``gaps_on_arc``
   in ``src/specimens/scenarios/arc.rs``)::

       x = t               the sliding direction, along the curve in its direction of travel
       y = n               the plane normal
       z = x × n           the support's outward normal: for a circle traversed
                           counter-clockwise about n it is the radius from the centre of
                           curvature through P, for any curve the side of its convex bulge

   ``y = z × x`` holds by construction; the frame is re-orthonormalised to 1e-12;
4. sets the support point to ``P + ((A - O)·n) n + r z`` (on the swept surface, right below
   the node along ``z``; ``r`` the optional ``offset``, e.g. the radius of a steel tube) and the
   initial gap to ``g0 = z·(A - support point)``, the distance along ``z`` (the value the Rust
   model checks, docs/model-format.md "Warnings").

``g0 < 0`` means the film node lies inside the support: refused, naming the node. At an inner
vertex of a polyline the closest point is the vertex for a whole wedge of nodes; there ``z``
turns with the direction from the vertex to the node (a rounded corner of zero radius) and
``x = n × z``.

Curves (``"curve"`` of an arch entry, see ``python/README-import.md``)::

    {"type": "circle", "centre": [..], "radius": R, "axis": [..], "start": [..], "end": [..]}
    {"type": "circle", "points": [start, middle, end]}
    {"type": "parabola", "apex": [..], "up": [..], "along": [..], "half_span": L, "rise": H}
    {"type": "polyline", "points": [[..], [..], ...], "normal": [..]}

Circle: counter-clockwise about ``axis`` (right-hand rule) from ``start`` to ``end`` (both
projected on the circle; without them the full circle). ``points``: the circle through three
points, traversed from the first through the second to the third (``axis`` follows).
Parabola: ``apex + s·along - (rise/half_span²) s² up`` for ``s`` in ``[-half_span, half_span]``
(an arch of span ``2 half_span`` and rise ``rise`` whose crown is ``apex``), traversed along
``along``; ``n = up × along`` so that ``z`` is ``up`` at the crown. Polyline: traversed from the
first point to the last; ``z = x × normal``; without ``normal`` the one about which the polyline
turns counter-clockwise (so that ``z`` points to its convex side, like a circle's radius).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Relative tolerance (of the curve's size) for "on the curve", "at its end", "in its plane".
REL_TOL = 1e-9


class ArchError(ValueError):
    """A support curve or a gap that cannot be built; the message names the item."""


def _vec(spec: dict, key: str, where: str) -> np.ndarray:
    if key not in spec:
        raise ArchError(f"{where}: '{key}' is missing")
    try:
        v = np.asarray(spec[key], dtype=float)
    except (TypeError, ValueError):
        raise ArchError(f"{where}: '{key}' = {spec[key]!r} is not a vector [x, y, z]") from None
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ArchError(f"{where}: '{key}' = {spec[key]!r} is not a finite vector [x, y, z]")
    return v


def _positive(spec: dict, key: str, where: str) -> float:
    if key not in spec:
        raise ArchError(f"{where}: '{key}' is missing")
    v = spec[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and v > 0):
        raise ArchError(f"{where}: '{key}' = {v!r} must be a number > 0")
    return float(v)


def _unit(v: np.ndarray, what: str) -> np.ndarray:
    norm = float(np.linalg.norm(v))
    if not norm > 0.0 or not math.isfinite(norm):
        raise ArchError(f"{what} is zero")
    return v / norm


def _check_keys(spec: dict, allowed: set[str], where: str) -> None:
    unknown = sorted(set(spec) - allowed)
    if unknown:
        raise ArchError(f"{where}: unknown key(s) {', '.join(map(repr, unknown))} "
                        f"(allowed: {', '.join(sorted(allowed))})")


@dataclass
class Closest:
    """The closest point of a curve to a point of its plane."""

    point: np.ndarray  # P (in the plane)
    tangent: np.ndarray  # unit t at P (direction of travel)
    parameter: float  # arc length from the start (orders the gaps along the curve)
    where: str  # "interior", "vertex" (inner polyline vertex), "start" or "end"


class Curve:
    """A plane support curve: ``origin`` and unit ``normal`` of its plane, ``size`` (m)."""

    name: str
    origin: np.ndarray
    normal: np.ndarray
    size: float

    def closest(self, q: np.ndarray) -> Closest:  # pragma: no cover - abstract
        raise NotImplementedError

    def outward(self, c: Closest) -> np.ndarray:
        """The support's outward normal ``z = t × n`` at a closest point."""
        return np.cross(c.tangent, self.normal)


class Circle(Curve):
    def __init__(self, spec: dict, name: str):
        where = f"curve of '{name}'"
        self.name = name
        if "points" in spec:
            _check_keys(spec, {"type", "points"}, where)
            pts = spec["points"]
            if not isinstance(pts, list) or len(pts) != 3:
                raise ArchError(f"{where}: 'points' must be three points [start, middle, end]")
            a, b, c = (_vec({"p": p}, "p", f"{where} points[{i}]") for i, p in enumerate(pts))
            normal = np.cross(b - a, c - b)
            scale = max(np.linalg.norm(b - a), np.linalg.norm(c - b), np.linalg.norm(c - a))
            if not scale > 0 or np.linalg.norm(normal) <= 1e-9 * scale**2:
                raise ArchError(f"{where}: the three points are collinear (or coincide): no circle")
            n = normal / np.linalg.norm(normal)
            # circumcentre of a, b, c
            ab, ac = b - a, c - a
            w = np.cross(ab, ac)
            centre = a + (np.cross(w, ab) * ac.dot(ac) + np.cross(ac, w) * ab.dot(ab)) / (2 * w.dot(w))
            self.centre, self.axis, self.radius = centre, n, float(np.linalg.norm(a - centre))
            start, end = a, c
        else:
            _check_keys(spec, {"type", "centre", "radius", "axis", "start", "end"}, where)
            self.centre = _vec(spec, "centre", where)
            self.radius = _positive(spec, "radius", where)
            self.axis = _unit(_vec(spec, "axis", where), f"{where}: 'axis'")
            if ("start" in spec) != ("end" in spec):
                raise ArchError(f"{where}: give both 'start' and 'end' (an arc) or neither (a full circle)")
            start = _vec(spec, "start", where) if "start" in spec else None
            end = _vec(spec, "end", where) if "end" in spec else None
        self.origin, self.normal, self.size = self.centre, self.axis, self.radius
        if start is None:
            # full circle: any in-plane direction starts it
            trial = np.eye(3)[int(np.argmin(np.abs(self.axis)))]
            self.e1 = _unit(trial - trial.dot(self.axis) * self.axis, where)
            self.sweep = 2 * math.pi
            self.closed = True
        else:
            self.e1 = self._radial(start, f"{where}: 'start'")
            e_end = self._radial(end, f"{where}: 'end'")
            self.sweep = self._angle(e_end)
            if self.sweep <= 1e-12:
                self.sweep = 2 * math.pi  # start == end: the full circle from there
            self.closed = False
        self.e2 = np.cross(self.axis, self.e1)

    def _radial(self, p: np.ndarray, what: str) -> np.ndarray:
        d = p - self.centre
        d = d - d.dot(self.axis) * self.axis
        if np.linalg.norm(d) <= REL_TOL * self.radius:
            raise ArchError(f"{what} lies on the circle's axis")
        return d / np.linalg.norm(d)

    def _angle(self, u: np.ndarray) -> float:
        """Counter-clockwise angle about the axis from e1 to u, in [0, 2π)."""
        e2 = np.cross(self.axis, self.e1)
        a = math.atan2(u.dot(e2), u.dot(self.e1))
        return a + 2 * math.pi if a < 0 else a

    def at(self, angle: float) -> tuple[np.ndarray, np.ndarray]:
        r = math.cos(angle) * self.e1 + math.sin(angle) * self.e2
        return self.centre + self.radius * r, np.cross(self.axis, r)

    def closest(self, q):
        d = q - self.centre
        if np.linalg.norm(d) <= REL_TOL * self.radius:
            raise ArchError("lies on the axis of the circle (every point of it is closest)")
        angle = self._angle(d / np.linalg.norm(d))
        where = "interior"
        if not self.closed and angle > self.sweep:
            # beyond the arc: the nearer end (angles past the end vs before the start); within
            # rounding of an end it is that end
            past_end, before_start = angle - self.sweep, 2 * math.pi - angle
            outside = min(past_end, before_start) * self.radius > REL_TOL * self.radius
            if outside:
                where = "end" if past_end < before_start else "start"
            angle = self.sweep if past_end < before_start else 0.0
        point, tangent = self.at(angle)
        return Closest(point, tangent, self.radius * angle, where)


class Parabola(Curve):
    def __init__(self, spec: dict, name: str):
        where = f"curve of '{name}'"
        _check_keys(spec, {"type", "apex", "up", "along", "half_span", "rise"}, where)
        self.name = name
        self.apex = _vec(spec, "apex", where)
        self.up = _unit(_vec(spec, "up", where), f"{where}: 'up'")
        along = _vec(spec, "along", where)
        along = along - along.dot(self.up) * self.up
        self.along = _unit(along, f"{where}: 'along' (its part normal to 'up')")
        self.half_span = _positive(spec, "half_span", where)
        self.rise = _positive(spec, "rise", where)
        self.k = self.rise / self.half_span**2
        self.origin, self.normal = self.apex, np.cross(self.up, self.along)
        self.size = max(self.half_span, self.rise)

    def _point(self, s: float):
        point = self.apex + s * self.along - self.k * s * s * self.up
        tangent = _unit(self.along - 2 * self.k * s * self.up, "tangent")
        return point, tangent

    def _arc_length(self, s: float) -> float:
        # ∫ sqrt(1 + (2 k u)²) du from -L to s, closed form
        def primitive(u):
            w = 2 * self.k * u
            return (w * math.sqrt(1 + w * w) + math.asinh(w)) / (4 * self.k)

        return primitive(s) - primitive(-self.half_span)

    def closest(self, q):
        d = q - self.apex
        pa, pu = d.dot(self.along), d.dot(self.up)
        # d/ds |Q(s) - q|² = 0  ⇔  2k² s³ + (1 + 2k pu) s - pa = 0
        roots = np.roots([2 * self.k**2, 0.0, 1 + 2 * self.k * pu, -pa])
        real = [r.real for r in roots if abs(r.imag) <= 1e-9 * (1 + abs(r.real))]
        candidates = [min(max(s, -self.half_span), self.half_span) for s in real]
        candidates += [-self.half_span, self.half_span]
        s = min(candidates, key=lambda s: (s - pa) ** 2 + (self.k * s * s + pu) ** 2)
        unclamped = min(real, key=lambda s: (s - pa) ** 2 + (self.k * s * s + pu) ** 2) if real else s
        where = "interior"
        if abs(s) >= self.half_span and abs(unclamped) - self.half_span > REL_TOL * self.size:
            where = "end" if s > 0 else "start"
        point, tangent = self._point(s)
        return Closest(point, tangent, self._arc_length(s), where)


class Polyline(Curve):
    def __init__(self, spec: dict, name: str):
        where = f"curve of '{name}'"
        _check_keys(spec, {"type", "points", "normal"}, where)
        self.name = name
        pts = spec.get("points")
        if not isinstance(pts, list) or len(pts) < 2:
            raise ArchError(f"{where}: 'points' must list at least two points")
        self.points = np.array([_vec({"p": p}, "p", f"{where} points[{i}]") for i, p in enumerate(pts)])
        seg = np.diff(self.points, axis=0)
        lengths = np.linalg.norm(seg, axis=1)
        self.size = float(lengths.sum())
        for i, length in enumerate(lengths):
            if length <= REL_TOL * max(self.size, 1e-300):
                raise ArchError(f"{where}: points[{i}] and points[{i + 1}] coincide")
        self.tangents = seg / lengths[:, None]
        self.cumulative = np.concatenate([[0.0], np.cumsum(lengths)])
        if "normal" in spec:
            n = _unit(_vec(spec, "normal", where), f"{where}: 'normal'")
        else:
            turning = sum((np.cross(a, b) for a, b in zip(self.tangents[:-1], self.tangents[1:])), np.zeros(3))
            if np.linalg.norm(turning) <= 1e-9:
                raise ArchError(f"{where}: the points are collinear: give the plane's 'normal' "
                                "(z = x × normal is the side the film is on)")
            n = turning / np.linalg.norm(turning)
        if np.max(np.abs(self.tangents @ n)) > 1e-6:
            raise ArchError(f"{where}: the points do not lie in one plane normal to {n.round(6).tolist()}")
        self.origin, self.normal = self.points[0], n

    def closest(self, q):
        best = None
        for i, (a, t) in enumerate(zip(self.points[:-1], self.tangents)):
            length = self.cumulative[i + 1] - self.cumulative[i]
            tau = float(np.clip((q - a).dot(t), 0.0, length))
            p = a + tau * t
            dist = float(np.linalg.norm(q - p))
            if best is None or dist < best[0] - REL_TOL * self.size:
                best = (dist, i, tau, p)
        _, i, tau, p = best
        length = self.cumulative[i + 1] - self.cumulative[i]
        at_start = tau <= REL_TOL * self.size
        at_end = tau >= length - REL_TOL * self.size
        where, tangent = "interior", self.tangents[i]
        if i == 0 and at_start:
            where = "start" if (q - p).dot(tangent) < -REL_TOL * self.size else "interior"
        elif i == len(self.tangents) - 1 and at_end:
            where = "end" if (q - p).dot(tangent) > REL_TOL * self.size else "interior"
        elif at_start or at_end:
            # an inner vertex: mean tangent of the two segments
            j = i - 1 if at_start else i + 1
            where, tangent = "vertex", _unit(self.tangents[i] + self.tangents[j], "tangent at a vertex")
            p = self.points[i if at_start else i + 1]
        return Closest(p, tangent, self.cumulative[i] + tau, where)


CURVES = {"circle": Circle, "parabola": Parabola, "polyline": Polyline}


def make_curve(spec, name: str) -> Curve:
    """The curve of an arch entry (``spec`` the ``"curve"`` dict); errors name the arch."""
    if not isinstance(spec, dict):
        raise ArchError(f"curve of '{name}' must be an object with a 'type'")
    kind = spec.get("type")
    if kind not in CURVES:
        raise ArchError(f"curve of '{name}': type {kind!r} is not one of {', '.join(CURVES)}")
    return CURVES[kind](spec, name)


def _label(node: int, a: np.ndarray) -> str:
    return f"node {node} at ({a[0]:.6g}, {a[1]:.6g}, {a[2]:.6g})"


@dataclass
class Gap:
    """One generated gap (film node index in the caller's numbering)."""

    film_node: int
    support_point: np.ndarray
    frame: np.ndarray  # rows x, y, z
    initial_gap: float
    parameter: float  # position along the curve (orders the gaps)


def gap_for_node(curve: Curve, node: int, a: np.ndarray, offset: float = 0.0,
                 node_label: str | None = None) -> tuple[Gap | None, str]:
    """The gap of film node ``node`` at ``a`` over ``curve``, or ``(None, reason)`` when the
    node lies beyond an end of the curve. Raises :class:`ArchError` (naming the node) when the
    film node is inside the support or on its axis."""
    label = node_label or _label(node, a)
    tol = REL_TOL * curve.size
    off = float((a - curve.origin).dot(curve.normal))
    q = a - off * curve.normal
    try:
        c = curve.closest(q)
    except ArchError as e:
        raise ArchError(f"arch '{curve.name}': film {label} {e}") from None
    d = q - c.point
    if c.where in ("start", "end"):
        return None, f"lies beyond the {c.where} of the curve (its closest point is the {c.where})"
    z = curve.outward(c)
    x = c.tangent
    distance = float(np.linalg.norm(d))
    if c.where == "vertex" and distance > tol and d.dot(z) > 0:
        z = d / distance  # the wedge beyond a convex vertex: a rounded corner of zero radius
        x = np.cross(curve.normal, z)
    g0 = float(d.dot(z)) - offset
    if g0 < -tol:
        raise ArchError(
            f"arch '{curve.name}': film {label} lies {-g0:.6g} m inside "
            f"the support (initial gap {g0:.6g} m < 0): the film must start outside the support, "
            "on its z side"
        )
    # orthonormal right-handed frame with y = z × x, cleaned to rounding
    z = z / np.linalg.norm(z)
    x = x - x.dot(z) * z
    x = x / np.linalg.norm(x)
    y = np.cross(z, x)
    support = c.point + off * curve.normal + offset * z
    g0 = max(float(z.dot(a - support)), 0.0)
    return Gap(node, support, np.array([x, y, z]), g0, c.parameter), ""


def gaps_on_curve(curve: Curve, nodes: np.ndarray, candidates, *, offset: float = 0.0,
                  max_gap: float | None = None, plane_tolerance: float | None = None,
                  labels=None) -> list[Gap]:
    """Gaps of the film nodes ``candidates`` (indices into ``nodes``) over ``curve``, ordered
    along the curve.

    Without ``max_gap`` and ``plane_tolerance`` every candidate must lie over the curve (an
    error names a node beyond its ends). With either, the candidates are a pool: a node is kept
    when it lies over the curve, within ``plane_tolerance`` of its plane and with an initial gap
    ``≤ max_gap`` (a distance band); a node in the band but inside the support is still an
    error.
    """
    band = max_gap is not None or plane_tolerance is not None
    gaps = []
    for node in candidates:
        a = nodes[node]
        label = labels(node) if labels else None
        if band:
            off = abs(float((a - curve.origin).dot(curve.normal)))
            limit = plane_tolerance if plane_tolerance is not None else 1e-6 * curve.size
            if off > limit:
                continue
            if max_gap is not None:
                # cheap rejection before the full construction (which raises inside the support)
                q = a - (a - curve.origin).dot(curve.normal) * curve.normal
                try:
                    c = curve.closest(q)
                except ArchError:
                    continue
                if c.where in ("start", "end"):
                    continue
                signed = float((q - c.point).dot(curve.outward(c))) - offset
                if abs(signed) > max_gap:
                    continue
        gap, reason = gap_for_node(curve, node, a, offset, label)
        if gap is None:
            if band:
                continue
            raise ArchError(f"arch '{curve.name}': film {label or _label(node, a)} {reason}: "
                            "it has no support point")
        gaps.append(gap)
    gaps.sort(key=lambda g: g.parameter)
    return gaps
