"""Mesh import: a gmsh (or any meshio-readable) mesh plus a mapping file → a model dict.

``import_mesh(path, mapping)`` reads the mesh with meshio (gmsh 2.2 and 4.1, ASCII and binary,
and every format meshio knows), takes its triangles as the film, renumbers the nodes compactly,
and turns the named groups of the mesh (gmsh physical groups; ``cell_sets`` and
``point_sets`` of other formats) into model items through the mapping: element sets, pressure
and force sets, supports, boundary groups, symmetry planes, output points, cables, friction
gaps over arches (``arches.py``) and curved supports, tubes around a physical curve whose
centreline is fitted to its points (``tubes.py``). The result is a dict in the model format of
``docs/model-format.md``, ready for ``json.dump`` and for ``membrane-contact model`` /
``fmu-pack``. The mapping file format is documented in ``python/README-import.md``.

Command line::

    python -m membrane_contact.mesh mesh.msh mapping.json -o model.json

Every error is a :class:`MeshImportError` (or :class:`~membrane_contact.arches.ArchError`)
whose message names the bad item: the physical group, the node (model index and
coordinates), the mapping key. Things done on the user's behalf (quads split, physical groups
left unmapped) are reported as :class:`MeshImportWarning`.
"""

from __future__ import annotations

import argparse
import contextlib
import copy
import io
import json
import math
import re
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

# A module of the package (``python -m membrane_contact.mesh``, or the console script
# ``membrane-contact-import`` of [project.scripts]), not a script that patches sys.path.
from .arches import ArchError, gaps_on_curve, make_curve
from .fmu import CLI_VARIABLE, cli_program
from .tubes import DEFAULT_TOLERANCE_SHARE, TubeError, fit_centreline, tube_nodes


class MeshImportError(ValueError):
    """The mesh or the mapping cannot be turned into a model; the message names the item."""


class MeshImportWarning(UserWarning):
    """Something the importer did on the user's behalf (quads split, groups left unmapped)."""


IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
#: Top-level FMU variable names no item may take (``RESERVED_NAMES`` in src/fmi2/variables.rs;
#: ``fmu-pack`` refuses them, the CLI does not: checked here so that every imported model packs).
RESERVED_NAMES = ("time", "reactions", "gravity", "mu", "frictionLaw", "archHeight", "film", "solver", "results")
AXES = ("x", "y", "z")

# topological dimension of meshio cell types (meshio._mesh.topological_dimension as fallback)
_DIM = {"vertex": 0, "line": 1, "line3": 1, "line4": 1, "triangle": 2, "triangle6": 2, "triangle7": 2,
        "quad": 2, "quad8": 2, "quad9": 2, "polygon": 2, "tetra": 3, "tetra10": 3, "hexahedron": 3,
        "hexahedron20": 3, "hexahedron27": 3, "wedge": 3, "wedge15": 3, "pyramid": 3, "pyramid13": 3}


def cell_dim(cell_type: str) -> int:
    if cell_type in _DIM:
        return _DIM[cell_type]
    try:
        from meshio._mesh import topological_dimension
        return topological_dimension[cell_type]
    except (ImportError, KeyError):
        return 3 if cell_type.startswith(("tetra", "hexa", "wedge", "pyramid")) else 2


# ----------------------------------------------------------------------------- mapping format

TOP_KEYS = {"name", "description", "material", "physical_groups", "gap_defaults", "arches", "loads",
            "quads", "film"}

GAP_KEYS = {"curve", "prefix", "offset", "max_gap", "plane_tolerance", "normal_stiffness",
            "tangential_stiffness", "friction", "friction_law"}
#: The contact constants a curved support takes from ``gap_defaults``.
CONTACT_KEYS = {"normal_stiffness", "tangential_stiffness", "friction", "friction_law"}

# role → (required keys, optional keys)
ROLES: dict[str, tuple[set[str], set[str]]] = {
    "element_set": (set(), {"name"}),
    "pressure": ({"pressure"}, {"name", "towards", "kind"}),
    "force": ({"force"}, {"name"}),
    "support": (set(), {"fixed", "set"}),
    "boundary": (set(), {"name", "target", "components"}),
    "symmetry": ({"normal"}, {"name"}),
    "output_point": (set(), {"name"}),
    "cable": ({"area", "youngs_modulus"}, {"name", "prestress_force"}),
    "gaps": ({"curve"}, GAP_KEYS - {"curve"}),
    "curved_support": ({"tube_radius", "nodes"}, {"name", "shape", "fit_tolerance", "normal_stiffness",
                                                  "tangential_stiffness", "friction", "friction_law"}),
    "ignore": (set(), set()),
}


def load_mapping(mapping) -> dict:
    """The mapping as a dict: a dict (copied), or a path to a JSON file."""
    if isinstance(mapping, dict):
        return copy.deepcopy(mapping)
    path = Path(mapping)
    try:
        text = path.read_text()
    except OSError as e:
        raise MeshImportError(f"mapping file {path}: {e.strerror or e}") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as e:
        raise MeshImportError(f"mapping file {path}: not valid JSON: {e}") from None
    if not isinstance(data, dict):
        raise MeshImportError(f"mapping file {path}: must hold a JSON object")
    return data


def _fail(message: str):
    raise MeshImportError(message)


def _identifier(name, what: str) -> str:
    if not isinstance(name, str) or not IDENTIFIER.match(name):
        _fail(f"{what}: name {name!r} is not an identifier [A-Za-z_][A-Za-z0-9_]* "
              "(it becomes an FMU variable prefix): give \"name\" in the mapping")
    return name


def _number(value, what: str, *, positive=False, non_negative=False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        _fail(f"{what} = {value!r} must be a finite number")
    if positive and not value > 0:
        _fail(f"{what} = {value!r} must be > 0")
    if non_negative and not value >= 0:
        _fail(f"{what} = {value!r} must be ≥ 0")
    return float(value)


def _vector(value, what: str) -> list[float]:
    if not isinstance(value, list) or len(value) != 3:
        _fail(f"{what} = {value!r} must be a vector [x, y, z]")
    return [_number(v, what) for v in value]


def _components(value, what: str) -> list[str]:
    if not isinstance(value, list) or not value or any(v not in AXES for v in value) or len(set(value)) != len(value):
        _fail(f"{what} = {value!r} must list some of \"x\", \"y\", \"z\", each at most once")
    return list(value)


# ----------------------------------------------------------------------------- mesh groups


@dataclass
class Group:
    """A named group of the mesh: cells per block (row indices) and/or bare points."""

    name: str
    blocks: dict[int, np.ndarray] = field(default_factory=dict)
    points: np.ndarray | None = None


def mesh_groups(mesh) -> dict[str, Group]:
    """Named groups: gmsh physical groups (``cell_data["gmsh:physical"]`` + ``field_data``),
    else ``cell_sets`` (newer meshio, other formats), plus ``point_sets``."""
    groups: dict[str, Group] = {}
    physical = mesh.cell_data.get("gmsh:physical")
    if physical is not None and mesh.field_data:
        for name, value in mesh.field_data.items():
            value = np.asarray(value).ravel()
            if len(value) < 2:
                continue
            tag, dim = int(value[0]), int(value[1])
            g = groups.setdefault(name, Group(name))
            for i, block in enumerate(mesh.cells):
                if cell_dim(block.type) != dim:
                    continue
                rows = np.nonzero(np.asarray(physical[i]) == tag)[0]
                if len(rows):
                    g.blocks[i] = np.union1d(g.blocks.get(i, rows), rows)
    else:
        for name, per_block in (mesh.cell_sets or {}).items():
            if name.startswith("gmsh:"):
                continue
            g = groups.setdefault(name, Group(name))
            for i, rows in enumerate(per_block):
                if rows is not None and len(rows):
                    g.blocks[i] = np.asarray(rows, dtype=int)
    for name, pts in (mesh.point_sets or {}).items():
        g = groups.setdefault(name, Group(name))
        g.points = np.asarray(pts, dtype=int)
    return groups


# ----------------------------------------------------------------------------- the importer


def _chain(segments: list[tuple[int, int]], where: str, label) -> list[int]:
    """The nodes of 2-node segments as one chain, from a free end that its segments leave (gmsh's
    curve direction); a closed loop starts at the first segment's first node and lists it again
    at the end. Branches and several chains are errors naming ``where`` (``label(node)``)."""
    neighbours: dict[int, list[int]] = {}
    for a, b in segments:
        neighbours.setdefault(a, []).append(b)
        neighbours.setdefault(b, []).append(a)
    for v, adj in neighbours.items():
        if len(adj) > 2:
            _fail(f"{where}: branches at {label(v)} ({len(adj)} segments meet): "
                  "a chain cannot branch; split it into several physical groups")
    ends = [v for v, adj in neighbours.items() if len(adj) == 1]
    firsts = {a for a, _ in segments}
    start = min(ends, key=lambda v: (v not in firsts, v)) if ends else segments[0][0]
    chain, previous = [start], None
    while len(chain) <= len(segments):
        options = [w for w in neighbours[chain[-1]] if w != previous]
        if not options:
            break
        previous = chain[-1]
        chain.append(options[0])
        if chain[-1] == start:
            break
    visited = set(chain)
    if len(visited) != len(neighbours):
        _fail(f"{where}: its line elements form several separate chains "
              f"({len(visited)} of {len(neighbours)} nodes in the first): one chain per physical group")
    return chain


class _Importer:
    def __init__(self, path, mapping):
        import meshio

        self.path = Path(path)
        self.map = load_mapping(mapping)
        if not self.path.is_file():
            _fail(f"mesh file {self.path}: no such file")
        # meshio 5.3.5 tries every format of the extension (".msh": ansys, then gmsh), prints each
        # failure on stdout and calls sys.exit(1) when none reads: name gmsh for .msh, keep
        # stdout clean (the model may go there) and turn the exit into an error
        file_format = "gmsh" if self.path.suffix.lower() == ".msh" else None
        chatter = io.StringIO()
        try:
            with contextlib.redirect_stdout(chatter), contextlib.redirect_stderr(chatter):
                self.mesh = meshio.read(str(self.path), file_format=file_format)
        except (Exception, SystemExit) as e:  # ReadError, KeyError, ValueError … on bad files
            said = " ".join(chatter.getvalue().split())
            reason = f"{type(e).__name__}: {e}" if not isinstance(e, SystemExit) else said
            raise MeshImportError(
                f"mesh file {self.path}: meshio cannot read it ({reason or 'no reason given'})") from None
        self.groups = mesh_groups(self.mesh)
        #: The centreline fit of each curved support (by item name).
        self.fits: dict = {}

    # --------------------------------------------------------------- helpers

    def node_label(self, model_node: int) -> str:
        x = self.nodes[model_node]
        return f"node {model_node} at ({x[0]:.6g}, {x[1]:.6g}, {x[2]:.6g})"

    def group_nodes(self, g: Group) -> np.ndarray:
        """Mesh point indices of a group (sorted, unique)."""
        parts = [self.mesh.cells[i].data[rows].ravel() for i, rows in g.blocks.items()]
        if g.points is not None:
            parts.append(g.points)
        return np.unique(np.concatenate(parts)) if parts else np.zeros(0, dtype=int)

    def unnamed_hint(self) -> str:
        """Physical tags without a name (gmsh `Physical Surface(1) = …`): the mapping cannot name them."""
        physical = self.mesh.cell_data.get("gmsh:physical")
        if physical is None:
            return ""
        named = {(int(np.ravel(v)[0]), int(np.ravel(v)[1])) for v in self.mesh.field_data.values() if np.size(v) >= 2}
        unnamed = sorted({(cell_dim(b.type), int(t)) for b, tags in zip(self.mesh.cells, physical)
                          for t in np.unique(tags)} - {(d, t) for t, d in named})
        if not unnamed:
            return ""
        listing = ", ".join(f"tag {t} (dimension {d})" for d, t in unnamed)
        return (f"; the mesh has physical groups without a name: {listing}: name them in gmsh, "
                "e.g. Physical Surface(\"film\") = {1};")

    def where(self, name: str, role: str) -> str:
        return f"physical group '{name}' (role {role})"

    # --------------------------------------------------------------- steps

    def check_mapping(self):
        m = self.map
        unknown = sorted(set(m) - TOP_KEYS)
        if unknown:
            _fail(f"mapping: unknown key(s) {', '.join(map(repr, unknown))} (allowed: {', '.join(sorted(TOP_KEYS))})")
        for key in ("name", "material", "physical_groups"):
            if key not in m:
                _fail(f"mapping: '{key}' is missing")
        _identifier(m["name"], "mapping 'name' (the model's name)")
        if not isinstance(m["material"], dict):
            _fail("mapping: 'material' must be an object (the model's material, docs/model-format.md)")
        if not isinstance(m["physical_groups"], dict):
            _fail("mapping: 'physical_groups' must be an object: physical group name → role")
        defaults = m.get("gap_defaults", {})
        if not isinstance(defaults, dict):
            _fail("mapping: 'gap_defaults' must be an object")
        extra = sorted(set(defaults) - (GAP_KEYS - {"curve"}))
        if extra:
            _fail(f"mapping 'gap_defaults': unknown key(s) {', '.join(map(repr, extra))} "
                  f"(allowed: {', '.join(sorted(GAP_KEYS - {'curve'}))})")
        if m.get("quads", "refuse") not in ("refuse", "split"):
            _fail(f"mapping: 'quads' = {m['quads']!r} must be \"refuse\" or \"split\"")
        self.entries: list[tuple[str, dict]] = []
        for name, value in m["physical_groups"].items():
            roles = value if isinstance(value, list) else [value]
            for k, entry in enumerate(roles):
                what = f"mapping of physical group '{name}'" + (f" (entry {k})" if isinstance(value, list) else "")
                if not isinstance(entry, dict) or "role" not in entry:
                    _fail(f"{what}: must be an object with a \"role\" (one of {', '.join(ROLES)})")
                role = entry["role"]
                if role not in ROLES:
                    _fail(f"{what}: unknown role {role!r} (one of {', '.join(ROLES)})")
                required, optional = ROLES[role]
                if role == "gaps":
                    entry = {**m.get("gap_defaults", {}), **entry}
                    required = required | {"normal_stiffness", "tangential_stiffness", "friction"}
                elif role == "curved_support":
                    entry = {**{k: v for k, v in m.get("gap_defaults", {}).items() if k in CONTACT_KEYS}, **entry}
                    required = required | {"normal_stiffness", "tangential_stiffness", "friction"}
                missing = sorted(required - set(entry))
                if missing:
                    _fail(f"{what} (role {role}): {', '.join(map(repr, missing))} missing")
                extra = sorted(set(entry) - required - optional - {"role"})
                if extra:
                    _fail(f"{what} (role {role}): unknown key(s) {', '.join(map(repr, extra))} "
                          f"(allowed: {', '.join(sorted(required | optional))})")
                if name not in self.groups:
                    known = ", ".join(f"'{g}'" for g in self.groups) or "none"
                    _fail(f"mapping names physical group '{name}', which the mesh {self.path.name} does not "
                          f"have (its groups: {known}){self.unnamed_hint()}")
                self.entries.append((name, entry))
        for name in self.groups:
            if name not in m["physical_groups"] and name not in (m.get("film") or []):
                warnings.warn(f"physical group '{name}' is not in the mapping: ignored "
                              "(map it with {\"role\": \"ignore\"} to silence this)", MeshImportWarning, stacklevel=3)

    def build_film(self):
        """Triangles (quads split on request), compact node numbering."""
        mesh, split = self.mesh, self.map.get("quads", "refuse") == "split"
        film_groups = self.map.get("film")
        allowed_rows = None
        if film_groups is not None:
            if not isinstance(film_groups, list) or not film_groups:
                _fail("mapping: 'film' must list the physical groups whose surface cells form the film")
            allowed_rows = {}
            for name in film_groups:
                if name not in self.groups:
                    _fail(f"mapping 'film' names physical group '{name}', which the mesh does not have")
                for i, rows in self.groups[name].blocks.items():
                    allowed_rows[i] = np.union1d(allowed_rows.get(i, rows), rows)
        bad = []
        triangles, origin = [], []  # origin: (block, row) of each model triangle
        quads = 0
        for i, block in enumerate(mesh.cells):
            dim = cell_dim(block.type)
            rows = np.arange(len(block.data)) if allowed_rows is None else allowed_rows.get(i, np.zeros(0, int))
            if dim == 3:
                bad.append((block.type, len(block.data), i))
                continue
            if dim != 2 or not len(rows):
                continue
            if block.type == "triangle":
                for r in rows:
                    triangles.append(block.data[r].tolist())
                    origin.append((i, int(r)))
            elif block.type == "quad" and split:
                for r in rows:
                    a, b, c, d = block.data[r].tolist()
                    pa, pb, pc, pd = (mesh.points[v] for v in (a, b, c, d))
                    if np.linalg.norm(pa - pc) <= np.linalg.norm(pb - pd):
                        halves = [[a, b, c], [a, c, d]]
                    else:
                        halves = [[a, b, d], [b, c, d]]
                    for t in halves:
                        triangles.append(t)
                        origin.append((i, int(r)))
                quads += len(rows)
            else:
                bad.append((block.type, len(rows), i))
        if bad:
            kinds: dict[str, int] = {}
            owners: dict[str, set[str]] = {}
            for kind, count, i in bad:
                kinds[kind] = kinds.get(kind, 0) + count
                owners.setdefault(kind, set()).update(
                    g.name for g in self.groups.values() if i in g.blocks)
            listing = "; ".join(
                f"{count} {kind} cells" + (f" (physical group {', '.join(sorted(owners[kind]))})" if owners[kind] else "")
                for kind, count in kinds.items())
            hint = (" Quads can be split into two triangles each with \"quads\": \"split\" in the mapping."
                    if "quad" in kinds else "")
            _fail(f"mesh {self.path.name}: the film takes 3-node triangles only, and the mesh has {listing}. "
                  "Mesh the surface with first-order triangles (gmsh: Mesh.ElementOrder = 1, no Recombine)."
                  + hint)
        if not triangles:
            _fail(f"mesh {self.path.name}: no triangles (cell type \"triangle\") found: "
                  f"the mesh has {', '.join(sorted({c.type for c in mesh.cells})) or 'no cells'}")
        if quads:
            warnings.warn(f"{quads} quad cells split into two triangles each (along the shorter diagonal)",
                          MeshImportWarning, stacklevel=3)
        self.mesh_triangles = np.array(triangles, dtype=int)
        self.triangle_origin = origin
        # nodes: those of the triangles and of every mapped group that names nodes
        used = [self.mesh_triangles.ravel()]
        for name, entry in self.entries:
            if entry["role"] not in ("element_set", "pressure", "ignore", "curved_support"):
                used.append(self.group_nodes(self.groups[name]))
        used = np.unique(np.concatenate(used))
        self.new_index = np.full(len(mesh.points), -1, dtype=int)
        self.new_index[used] = np.arange(len(used))
        points = np.asarray(mesh.points, dtype=float)
        if points.shape[1] == 2:
            points = np.column_stack([points, np.zeros(len(points))])
        self.nodes = points[used]
        self.triangles = self.new_index[self.mesh_triangles]

    def group_triangles(self, name: str, role: str) -> list[int] | str:
        g = self.groups[name]
        wanted = {(i, int(r)) for i, rows in g.blocks.items() for r in rows}
        elements = [t for t, o in enumerate(self.triangle_origin) if o in wanted]
        if not elements:
            _fail(f"{self.where(name, role)}: has no film triangles (it holds "
                  f"{self.describe_group(g)}): an element set or pressure needs a surface group")
        return "all" if len(elements) == len(self.triangles) else elements

    def describe_group(self, g: Group) -> str:
        parts = [f"{len(rows)} {self.mesh.cells[i].type}" for i, rows in g.blocks.items()]
        if g.points is not None:
            parts.append(f"{len(g.points)} points")
        return ", ".join(parts) or "nothing"

    def nodes_of(self, name: str, role: str) -> list[int]:
        g = self.groups[name]
        mesh_nodes = self.group_nodes(g)
        if not len(mesh_nodes):
            _fail(f"{self.where(name, role)}: the group has no nodes in the mesh {self.path.name} "
                  "(no elements were saved for it)")
        return sorted(int(v) for v in self.new_index[mesh_nodes])

    def cable_chain(self, name: str) -> list[int]:
        return _chain(self.line_segments(name, "cable"), self.where(name, "cable"), self.node_label)

    def line_segments(self, name: str, role: str, index=None) -> list[tuple[int, int]]:
        """The 2-node line elements of a group (``index``: node numbering, default the model's)."""
        index = self.new_index if index is None else index
        g = self.groups[name]
        segments = []
        for i, rows in g.blocks.items():
            kind = self.mesh.cells[i].type
            if kind == "vertex":
                continue
            if kind != "line":
                _fail(f"{self.where(name, role)}: holds {kind} cells; a {role} is a chain of 2-node line elements")
            segments += [tuple(int(v) for v in index[row]) for row in self.mesh.cells[i].data[rows]]
        if not segments:
            _fail(f"{self.where(name, role)}: has no line elements (it holds {self.describe_group(g)})")
        return segments

    def leave_prescribed_nodes_out_of_planes(self, symmetry: list, plane_of: dict, prescribed: list) -> None:
        """A node that a boundary group prescribes along a symmetry plane's normal (a rail's end
        point on the plane) leaves the plane: the group's motion governs it. Where the group's
        target along the normal is 0 the two are the same constraint (a note says so); else the
        group moves the node off the plane, which the warning says. One MeshImportWarning per
        plane and group."""
        left: dict[tuple[int, str], list[int]] = {}
        for group, nodes, comps, target in prescribed:
            for v in nodes:
                for a in comps:
                    if (v, a) in plane_of:
                        left.setdefault((plane_of[(v, a)], group), []).append(v)
        for (k, group), nodes in left.items():
            plane = symmetry[k]
            out = set(nodes)
            plane["nodes"] = [v for v in plane["nodes"] if v not in out]
            a = plane["normal"]
            target = next(t for g, _, _, t in prescribed if g == group)[AXES.index(a)]
            shown = ", ".join(str(v) for v in sorted(out)[:6]) + (" …" if len(out) > 6 else "")
            verdict = ("the same constraint: the group holds them at 0 along it" if target == 0.0 else
                       f"the group moves them by {target:g} m along {a}, off the plane, and its motion is kept")
            warnings.warn(f"symmetry plane '{plane['name']}' (normal {a}): {len(out)} nodes left out ({shown}), "
                          f"prescribed along {a} by boundary group '{group}': {verdict}",
                          MeshImportWarning, stacklevel=3)

    def curved_support(self, name: str, entry: dict) -> dict:
        """The ``curved_supports`` item of a ``curved_support`` role: the centreline fitted to the
        group's line chain (a note reports the fit), and its film nodes."""
        where = self.where(name, "curved_support")
        role = "curved_support"
        identity = np.arange(len(self.mesh.points))
        points = np.asarray(self.mesh.points, dtype=float)
        if points.shape[1] == 2:
            points = np.column_stack([points, np.zeros(len(points))])
        point_label = lambda v: f"mesh point {v} at ({points[v][0]:.6g}, {points[v][1]:.6g}, {points[v][2]:.6g})"  # noqa: E731
        chain = _chain(self.line_segments(name, role, identity), where, point_label)
        radius = _number(entry["tube_radius"], f"{where}: tube_radius", positive=True)
        tolerance = _number(entry.get("fit_tolerance", DEFAULT_TOLERANCE_SHARE * radius), f"{where}: fit_tolerance",
                            positive=True)
        fit = fit_centreline(points[chain], tolerance, entry.get("shape", "auto"), name)
        spec = entry["nodes"]
        film = sorted(int(v) for v in np.unique(self.triangles))
        if isinstance(spec, str):
            if spec not in self.groups:
                _fail(f"{where}: 'nodes' names physical group {spec!r}, which the mesh does not have")
            pool, band = self.nodes_of(spec, role), None
            strays = sorted(set(pool) - set(film))
            if strays:
                _fail(f"{where}: {self.node_label(strays[0])} of group {spec!r} belongs to no film triangle")
        elif isinstance(spec, dict) and "band" in spec and set(spec) <= {"band", "group"}:
            band = _number(spec["band"], f"{where}: nodes band", non_negative=True)
            pool = film
            if "group" in spec:
                if spec["group"] not in self.groups:
                    _fail(f"{where}: 'nodes' group {spec['group']!r} is not a physical group of the mesh")
                pool = sorted(set(film) & set(self.nodes_of(spec["group"], role)))
        else:
            _fail(f"{where}: 'nodes' = {spec!r} must be a physical group's name or "
                  "{\"band\": metres from the tube surface, optional \"group\": a physical group}")
        label = _identifier(entry.get("name", name), where)
        nodes = tube_nodes(fit.centreline, radius, self.nodes, pool, band, label, self.node_label)
        if not nodes:
            _fail(f"{where}: no film node lies within the band {band} m of the tube: no contact nodes")
        item = {"name": label, "centreline": fit.centreline,
                "tube_radius": radius, "nodes": nodes,
                "normal_stiffness": _number(entry["normal_stiffness"], f"{where}: normal_stiffness", positive=True),
                "tangential_stiffness": _number(entry["tangential_stiffness"], f"{where}: tangential_stiffness",
                                                positive=True),
                "friction": _number(entry["friction"], f"{where}: friction", non_negative=True)}
        if "friction_law" in entry:
            if entry["friction_law"] not in ("isotropic", "sliding-direction"):
                _fail(f"{where}: friction_law {entry['friction_law']!r} must be \"isotropic\" or \"sliding-direction\"")
            item["friction_law"] = entry["friction_law"]
        self.fits[item["name"]] = fit
        warnings.warn(f"curved support '{item['name']}' from the {len(chain)} points of physical group '{name}': "
                      f"{fit.describe()}; {len(nodes)} film nodes", MeshImportWarning, stacklevel=3)
        return item

    # --------------------------------------------------------------- assembly of the model

    def build(self) -> dict:
        self.check_mapping()
        self.build_film()
        m = self.map
        supports: dict[int, dict] = {}
        support_owner: dict[int, str] = {}
        symmetry, groups, gaps, cables = [], [], [], []
        pressures, forces, points, element_sets = [], [], [], []
        in_boundary: dict[int, str] = {}
        fixed_by: dict[tuple[int, str], str] = {}
        plane_of: dict[tuple[int, str], int] = {}  # (node, normal) → its symmetry plane
        prescribed: list[tuple[str, list[int], list[str], list[float]]] = []
        arch_entries, tube_entries = [], []
        for name, entry in self.entries:
            role = entry["role"]
            where = self.where(name, role)
            label = lambda key: entry.get(key, name)  # noqa: E731
            if role == "ignore":
                continue
            if role == "element_set":
                element_sets.append({"name": _identifier(label("name"), where),
                                     "elements": self.group_triangles(name, role)})
            elif role == "pressure":
                pressures.append({"name": _identifier(label("name"), where),
                                  "elements": self.group_triangles(name, role),
                                  "pressure": _number(entry["pressure"], f"{where}: pressure"),
                                  **_towards(entry, where), **_pressure_kind(entry, where)})
            elif role == "force":
                forces.append({"name": _identifier(label("name"), where), "nodes": self.nodes_of(name, role),
                               "force": _vector(entry["force"], f"{where}: force")})
            elif role == "support":
                fixed = _components(entry.get("fixed", list(AXES)), f"{where}: fixed")
                set_name = entry.get("set")
                if set_name is not None:
                    _identifier(set_name, f"{where}: set")
                for v in self.nodes_of(name, role):
                    s = supports.setdefault(v, {"node": v, "fixed": []})
                    if set_name is not None:
                        if s.get("name", set_name) != set_name:
                            _fail(f"{self.node_label(v)} is in support groups '{support_owner[v]}' (set "
                                  f"'{s['name']}') and '{name}' (set '{set_name}'): its reaction can "
                                  "belong to one support set only")
                        s["name"] = set_name
                    s["fixed"] = [a for a in AXES if a in s["fixed"] or a in fixed]
                    support_owner.setdefault(v, name)
                    for a in fixed:
                        fixed_by.setdefault((v, a), f"support group '{name}'")
            elif role == "symmetry":
                normal = entry["normal"]
                if normal not in AXES:
                    _fail(f"{where}: normal {normal!r} must be \"x\", \"y\" or \"z\"")
                nodes = self.nodes_of(name, role)
                symmetry.append({"name": label("name"), "normal": normal, "nodes": nodes})
                for v in nodes:
                    fixed_by.setdefault((v, normal), f"symmetry group '{name}'")
                    plane_of.setdefault((v, normal), len(symmetry) - 1)
            elif role == "boundary":
                group_name = _identifier(label("name"), where)
                target = _vector(entry.get("target", [0.0, 0.0, 0.0]), f"{where}: target")
                comps = _components(entry["components"], f"{where}: components") if "components" in entry else None
                nodes = self.nodes_of(name, role)
                for v in nodes:
                    if v in in_boundary:
                        _fail(f"{self.node_label(v)} is in boundary groups '{in_boundary[v]}' and '{name}': a node "
                              "moves with one group only (give shared corners to one of the physical groups, or "
                              "merge them into one)")
                    in_boundary[v] = name
                g = {"name": group_name, "nodes": nodes, "target": target}
                if comps is not None:
                    g["components"] = comps
                groups.append(g)
                prescribed.append((name, nodes, comps or list(AXES), target))
            elif role == "output_point":
                nodes = self.nodes_of(name, role)
                if len(nodes) != 1:
                    _fail(f"{where}: has {len(nodes)} nodes, an output point needs exactly one "
                          "(a gmsh Physical Point)")
                points.append({"name": _identifier(label("name"), where), "node": nodes[0]})
            elif role == "cable":
                cable = {"name": _identifier(label("name"), where), "nodes": self.cable_chain(name),
                         "area": _number(entry["area"], f"{where}: area", positive=True),
                         "youngs_modulus": _number(entry["youngs_modulus"], f"{where}: youngs_modulus", positive=True)}
                if "prestress_force" in entry:
                    cable["prestress_force"] = _number(entry["prestress_force"], f"{where}: prestress_force",
                                                       non_negative=True)
                cables.append(cable)
            elif role == "gaps":
                arch_entries.append((name, {**m.get("gap_defaults", {}), **entry}, self.nodes_of(name, role)))
            elif role == "curved_support":
                tube_entries.append((name, entry))
        for k, entry in enumerate(m.get("arches", [])):
            if not isinstance(entry, dict):
                _fail(f"mapping 'arches'[{k}] must be an object")
            entry = {**m.get("gap_defaults", {}), **entry}
            name = entry.get("name", f"arches[{k}]")
            extra = sorted(set(entry) - GAP_KEYS - {"name", "nodes"})
            if extra:
                _fail(f"mapping arch '{name}': unknown key(s) {', '.join(map(repr, extra))} "
                      f"(allowed: {', '.join(sorted(GAP_KEYS | {'name', 'nodes'}))})")
            for key in ("curve", "normal_stiffness", "tangential_stiffness", "friction"):
                if key not in entry:
                    _fail(f"mapping arch '{name}': '{key}' is missing")
            if "nodes" in entry:
                if entry["nodes"] not in self.groups:
                    _fail(f"mapping arch '{name}': 'nodes' names physical group {entry['nodes']!r}, which the "
                          "mesh does not have")
                pool = self.nodes_of(entry["nodes"], "gaps")
            else:
                pool = sorted(int(v) for v in np.unique(self.triangles))
            if "max_gap" not in entry and "plane_tolerance" not in entry:
                _fail(f"mapping arch '{name}': give 'max_gap' (m) and/or 'plane_tolerance' (m): the band of film "
                      "nodes around the curve that get gaps")
            arch_entries.append((name, entry, pool))

        # ---------------------------------------------------------------- conflicts
        for group, nodes, comps, target in prescribed:
            for v in nodes:
                for a in comps:
                    if (v, a) in plane_of:
                        continue  # resolved below: the group's motion governs the node
                    if (v, a) in fixed_by:
                        _fail(f"{self.node_label(v)} is prescribed in {a} by boundary group '{group}' and also "
                              f"fixed in {a} by {fixed_by[(v, a)]}: remove it from one of them")
        self.leave_prescribed_nodes_out_of_planes(symmetry, plane_of, prescribed)

        # ---------------------------------------------------------------- gaps over arches
        counters: dict[str, int] = {}
        gap_owner: dict[int, str] = {}
        for name, entry, pool in arch_entries:
            where = f"arch '{name}'"
            curve = make_curve(entry["curve"], name)
            offset = _number(entry.get("offset", 0.0), f"{where}: offset", non_negative=True)
            max_gap = entry.get("max_gap")
            if max_gap is not None:
                max_gap = _number(max_gap, f"{where}: max_gap", non_negative=True)
            plane_tol = entry.get("plane_tolerance")
            if plane_tol is not None:
                plane_tol = _number(plane_tol, f"{where}: plane_tolerance", non_negative=True)
            constants = {
                "normal_stiffness": _number(entry["normal_stiffness"], f"{where}: normal_stiffness", positive=True),
                "tangential_stiffness": _number(entry["tangential_stiffness"], f"{where}: tangential_stiffness",
                                                positive=True),
                "friction": _number(entry["friction"], f"{where}: friction", non_negative=True),
            }
            if "friction_law" in entry:
                if entry["friction_law"] not in ("isotropic", "sliding-direction"):
                    _fail(f"{where}: friction_law {entry['friction_law']!r} must be \"isotropic\" or "
                          "\"sliding-direction\"")
                constants["friction_law"] = entry["friction_law"]
            prefix = entry.get("prefix", "G")
            if not isinstance(prefix, str) or not IDENTIFIER.match(prefix + "1"):
                _fail(f"{where}: prefix {prefix!r} must start an identifier (letters, digits, _)")
            found = gaps_on_curve(curve, self.nodes, pool, offset=offset, max_gap=max_gap,
                                  plane_tolerance=plane_tol, labels=self.node_label)
            if not found:
                _fail(f"{where}: no film node lies over the curve within the band "
                      f"(max_gap {max_gap}, plane_tolerance {plane_tol}): no gaps")
            for gap in found:
                if gap.film_node in gap_owner:
                    _fail(f"{self.node_label(gap.film_node)} gets a gap from arch '{gap_owner[gap.film_node]}' and "
                          f"from arch '{name}': one gap per film node (narrow the bands or the groups)")
                gap_owner[gap.film_node] = name
                counters[prefix] = counters.get(prefix, 0) + 1
                x, y, z = ((row + 0.0).tolist() for row in gap.frame)  # + 0.0: no "-0.0" in the file
                gaps.append({"name": f"{prefix}{counters[prefix]}", "film_node": gap.film_node,
                             "support": {"point": (gap.support_point + 0.0).tolist()},
                             "frame": {"x": x, "y": y, "z": z}, "initial_gap": gap.initial_gap, **constants})

        curved = [self.curved_support(name, entry) for name, entry in tube_entries]

        # ---------------------------------------------------------------- names unique
        seen: dict[str, str] = {}
        named = ([(g["name"], "gap") for g in gaps] + [(c["name"], "curved support") for c in curved] + [(g["name"], "boundary group") for g in groups]
                 + [(p["name"], "pressure set") for p in pressures] + [(f["name"], "force set") for f in forces]
                 + [(p["name"], "output point") for p in points] + [(s["name"], "element set") for s in element_sets]
                 + [(c["name"], "cable") for c in cables]
                 + [(n, "support set") for n in sorted({s["name"] for s in supports.values() if "name" in s})])
        for n, kind in named:
            if n in RESERVED_NAMES:
                _fail(f"{kind} '{n}': the name is reserved for an FMU variable ({', '.join(RESERVED_NAMES)}): "
                      "give the item another \"name\" in the mapping")
            if n in seen:
                _fail(f"name '{n}' is used twice: by the {seen[n]} '{n}' and by the {kind} '{n}' (names share one "
                      "namespace: the FMU's variables are <name>.…)")
            seen[n] = kind

        # ---------------------------------------------------------------- the model dict
        model = {
            "name": m["name"],
            "description": m.get("description", f"imported from {self.path.name} by membrane_contact.mesh"),
            "nodes": [[float(c) for c in p] for p in self.nodes],
            "triangles": [[int(v) for v in t] for t in self.triangles],
            "material": copy.deepcopy(m["material"]),
            "supports": [supports[v] for v in sorted(supports)],
            "symmetry": symmetry,
            "gaps": gaps,
            "groups": groups,
        }
        loads = copy.deepcopy(m.get("loads", {}))
        if not isinstance(loads, dict):
            _fail("mapping: 'loads' must be an object")
        if pressures:
            loads["pressures"] = loads.get("pressures", []) + pressures
        if forces:
            loads["forces"] = loads.get("forces", []) + forces
        if loads:
            model["loads"] = loads
        if points or element_sets:
            model["outputs"] = {"points": points, "element_sets": element_sets}
        if cables:
            model["cables"] = cables
        if curved:
            model["curved_supports"] = curved
        return model


def _towards(entry: dict, where: str) -> dict:
    """A pressure entry's ``towards`` (a direction or ``"+x"`` … ``"-z"``), as the model takes it."""
    if "towards" not in entry:
        return {}
    t = entry["towards"]
    if isinstance(t, str):
        if t not in SIDES:
            _fail(f"{where}: towards '{t}' is not one of {', '.join(SIDES)} or a direction [x, y, z]")
        return {"towards": t}
    return {"towards": _vector(t, f"{where}: towards")}


SIDES = ("+x", "-x", "+y", "-y", "+z", "-z")


def _pressure_kind(entry: dict, where: str) -> dict:
    """A pressure entry's ``kind``: ``"follower"`` (the default, left out) or ``"plan"`` (a load
    per plan area, snow)."""
    kind = entry.get("kind", "follower")
    if kind not in ("follower", "plan"):
        _fail(f"{where}: kind '{kind}' is not 'follower' or 'plan'")
    return {} if kind == "follower" else {"kind": kind}
#: The solver's command line, run by :func:`solver_check` (default: the one installed with this
#: package from the wheel, else the checkout's ``target/release/membrane-contact``, else
#: ``membrane-contact`` on the PATH: the order in which ``build_fmu`` finds ``fmu-pack``).


@dataclass
class SolverCheck:
    """What ``membrane-contact check`` says of a model: its warnings (the CLI's, ``fmu-pack``'s
    and the FMU's check: E that looks like MPa, pressure triangles pushed against their
    neighbours, …) and one line per pressure set on the side it pushes to."""
    warnings: list[str]
    report: list[str]


def solver_check(model: dict) -> SolverCheck | None:
    """Runs the solver's own check of ``model`` (``membrane-contact check``, the one function the
    CLI, ``fmu-pack`` and the FMU use), or None when the program is not found (set
    ``$MEMBRANE_CONTACT_CLI`` or build the checkout) or cannot be run (a
    :class:`MeshImportWarning` says so: a wrong ``$MEMBRANE_CONTACT_CLI``)."""
    import os
    import subprocess
    import tempfile

    given = os.environ.get(CLI_VARIABLE)
    program = cli_program()
    if not program:
        return None
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "model.json"
        path.write_text(json.dumps(model))
        try:
            r = subprocess.run([program, "check", str(path)], capture_output=True, text=True)
        except OSError as e:  # not there, not executable, not a program
            where = f"${CLI_VARIABLE} = {given}" if given else program
            warnings.warn(f"the solver's check is skipped: {where} cannot be run ({e.strerror or e}); "
                          f"set ${CLI_VARIABLE} to the membrane-contact program, or unset it",
                          MeshImportWarning, stacklevel=3)
            return None
    found = SolverCheck([], [])
    for line in r.stderr.splitlines():
        if line.startswith("warning: "):
            found.warnings.append(line[len("warning: "):])
        elif line.startswith("error: "):
            reason = line[len("error: "):].removeprefix(f"{path}: ")
            found.warnings.append(f"the solver refuses the model: {reason}")
    found.report = [line for line in r.stdout.splitlines() if line.startswith("pressure set ")]
    return found


def import_mesh(path, mapping, report: list | None = None) -> dict:
    """The model dict (docs/model-format.md) of the mesh at ``path`` mapped by ``mapping`` (a
    dict or the path of a JSON file; format in python/README-import.md).

    Raises :class:`MeshImportError` or :class:`~membrane_contact.arches.ArchError` naming the bad
    item; warns :class:`MeshImportWarning` about what it did on the user's behalf and about what
    the solver's check (:func:`solver_check`) finds wrong, E in MPa and flipped pressure triangles
    among them. ``report``: a list that receives the check's line on each pressure set (the side
    it pushes to, the triangles turned or pushed against their neighbours)."""
    model = _Importer(path, mapping).build()
    found = solver_check(model)
    for line in found.warnings if found else []:
        warnings.warn(line, MeshImportWarning, stacklevel=2)
    if found and report is not None:
        report.extend(found.report)
    return model


def summary(model: dict) -> str:
    """One line per item kind, for the command line."""
    lines = [f"model {model['name']}: {len(model['nodes'])} nodes, {len(model['triangles'])} triangles"]
    if model["gaps"]:
        g0 = [g["initial_gap"] for g in model["gaps"]]
        lines.append(f"  {len(model['gaps'])} gaps ({model['gaps'][0]['name']} … {model['gaps'][-1]['name']}), "
                     f"initial gap {min(g0):.4g} … {max(g0):.4g} m")
    for g in model["groups"]:
        lines.append(f"  boundary group {g['name']}: {len(g['nodes'])} nodes, target {g['target']}")
    if model["supports"]:
        lines.append(f"  {len(model['supports'])} supported nodes")
    for s in model["symmetry"]:
        lines.append(f"  symmetry plane {s['name']} (normal {s['normal']}): {len(s['nodes'])} nodes")
    for c in model.get("cables", []):
        lines.append(f"  cable {c['name']}: {len(c['nodes'])} nodes")
    for c in model.get("curved_supports", []):
        lines.append(f"  curved support {c['name']}: {next(iter(c['centreline']))} centreline, tube radius "
                     f"{c['tube_radius']} m, {len(c['nodes'])} film nodes")
    for p in model.get("outputs", {}).get("points", []):
        lines.append(f"  output point {p['name']}: node {p['node']}")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m membrane_contact.mesh",
        description="Turns a gmsh (or other meshio-readable) mesh and a mapping file into a membrane-contact "
                    "model file (docs/model-format.md; mapping format: python/README-import.md).")
    parser.add_argument("mesh", help="the mesh file (.msh 2.2 or 4.1, ASCII or binary, or any meshio format)")
    parser.add_argument("mapping", help="the mapping JSON file: physical group names → roles")
    parser.add_argument("-o", "--output", help="the model JSON file to write (default: standard output)")
    parser.add_argument("-q", "--quiet", action="store_true", help="no summary on standard error")
    args = parser.parse_args(argv)
    report: list[str] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MeshImportWarning)
        try:
            model = import_mesh(args.mesh, args.mapping, report)
        except (MeshImportError, ArchError, TubeError) as e:
            print(f"error: {e}", file=sys.stderr)
            return 1
    for w in caught:
        print(f"note: {w.message}", file=sys.stderr)
    text = json.dumps(model, indent=1)
    if args.output:
        Path(args.output).write_text(text + "\n")
    else:
        sys.stdout.write(text + "\n")
    if not args.quiet:
        print(summary(model), file=sys.stderr)
        for line in report:
            print(f"  {line}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
