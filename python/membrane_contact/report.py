"""A run report (Markdown) of a :meth:`Film.run <membrane_contact.film.Film.run>` from the FMU's
outputs, for a design calculation: the model (from the FMU's variables), the load steps (the
table's inputs as reached), the reactions of every group and support set at every step, the
extreme stresses, the wrinkled and slack elements and compressed areas, the slips along every
gap and curved-support contact (last step and largest over the run), the FMU's warnings and the
solver's statistics.

The CLI writes the same sections from the core (``membrane-contact model … --report FILE.md``),
with the reactions per unit length along each group (``--line-reactions``) that the FMU's
outputs do not carry; the VTK film files do (point data ``line_reaction``), and
:func:`line_reactions` reads them per group and support set; given to :func:`markdown` (or
:meth:`Results.report <membrane_contact.Results.report>`), they make the report's section
"Line reactions".
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

WARNING = 1


def num(x: float) -> str:
    """Six significant digits, as the CLI's report."""
    x = float(x)
    if x == 0.0:
        return "0"
    if not np.isfinite(x):
        return str(x)
    a = abs(x)
    if not 1e-3 <= a < 1e7:
        return f"{x:.5e}"
    decimals = max(5 - int(np.floor(np.log10(a))), 0)
    return f"{x:.{decimals}f}"


def _table(head: list[str], rows: list[list[str]], align: str = "---:") -> str:
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join(align for _ in head) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def _prefixes(names: list[str], suffix: str) -> list[str]:
    return [n[: -len(suffix)] for n in names if n.endswith(suffix)]


def markdown(results, *, title: str = "run", variables: dict | None = None, messages: list | None = None,
             line_reactions: dict[str, np.ndarray] | None = None) -> str:
    """The report text of ``results`` (a :class:`~membrane_contact.film.Results`).
    ``variables``: the FMU's ``{name: value}`` of its parameters (model summary);
    ``messages``: the FMU's log ``(status, category, text)`` (warnings); ``line_reactions``:
    the reactions per unit length along each group and support set at the step a film VTK file
    holds (:func:`line_reactions`), a section as the CLI's ``--line-reactions`` prints."""
    names = list(results.names)
    last = {n: results[n][-1] for n in names} if len(results) else {}
    out = [f"# Run report: {title}\n"]

    # -- model
    gaps = list(results.gap_names)
    groups = [g for g in _prefixes(names, ".Rx") if g != "reactions"]
    contacts = sorted({m[1] for n in names if (m := re.match(r"(\w+)\.node\d+\.slip$", n))})
    sets = _prefixes(names, ".maxEquivalentStress")
    rows = [["recorded points", str(len(results))], ["gaps", str(len(gaps))],
            ["curved supports", str(len(contacts))], ["groups and support sets", ", ".join(groups) or "none"],
            ["element sets", ", ".join(s for s in sets if s != "film") or "none"]]
    for name, value in (variables or {}).items():
        rows.append([name, num(value) if isinstance(value, float) else str(value)])
    out.append("## Model\n\n" + _table(["item", "value"], rows, "---"))

    # -- load steps
    head = ["point", "time"] + [f"{n}" for n in results.input_names]
    stats = [s for s in ("solver.iterations", "solver.cutbacks", "solver.stabilizedIncrements") if s in names]
    head += stats
    rows = []
    for k, t in enumerate(results.time):
        rows.append([str(k), num(t)] + [num(results[n][k]) for n in results.input_names]
                    + [str(int(results[s][k])) for s in stats])
    out.append("## Load steps\n\n" + _table(head, rows))

    # -- reactions
    parts = ["## Reactions\n"]
    for g in groups + (["reactions"] if "reactions.Rx" in names else []):
        r = results.reaction(g)
        rows = [[num(t)] + [num(v) for v in r[k]] for k, t in enumerate(results.time)]
        what = "all restraints (total)" if g == "reactions" else f"`{g}`"
        parts.append(f"### Reaction of {what} (N)\n\n" + _table(["time", "Rx", "Ry", "Rz"], rows))
    if len(parts) == 1:
        parts.append("No reaction outputs recorded.\n")
    out.append("\n".join(parts))

    # -- line reactions
    if line_reactions:
        out.append(line_reactions_markdown(line_reactions))

    # -- stresses
    rows = []
    for s in sets:
        for q, unit in (("maxPrincipalStress", "Pa"), ("minPrincipalStress", "Pa"), ("maxEquivalentStress", "Pa"),
                        ("maxStrain", ""), ("compressedArea", "m²")):
            if f"{s}.{q}" in last:
                rows.append([s, q, f"{num(last[f'{s}.{q}'])} {unit}".strip(),
                             f"{num(np.max(results[f'{s}.{q}']) if q != 'minPrincipalStress' else np.min(results[f'{s}.{q}']))} {unit}".strip()])
    for q in ("film.wrinkledElements", "film.slackElements"):
        if q in last:
            rows.append(["film", q.split(".")[1], str(int(last[q])), str(int(np.max(results[q])))])
    out.append("## Stresses and wrinkling\n\n"
               + (_table(["set", "quantity", "last step", "extreme over the run"], rows) if rows else "None recorded.\n"))

    # -- slips
    parts = ["## Slips along the supports\n"]
    if gaps:
        rows = []
        for g in gaps:
            slip = results[f"{g}.slip"]
            row = [g, num(slip[-1] * 1e3), num(np.max(np.abs(slip)) * 1e3)]
            for q in ("slipY", "normalForce", "frictionForce"):
                row.append(num(last[f"{g}.{q}"] * (1e3 if q == "slipY" else 1)) if f"{g}.{q}" in last else "–")
            row.append(_status(last.get(f"{g}.status")))
            rows.append(row)
        parts.append("### Gaps\n\n" + _table(["gap", "slip x (mm)", "largest \\|slip x\\| (mm)", "slip y (mm)", "N (N)",
                                              "\\|T\\| (N)", "status"], rows))
    for c in contacts:
        nodes = [n[len(c) + 1: -len(".slip")] for n in names if re.match(rf"{c}\.node\d+\.slip$", n)]
        rows = []
        for v in nodes:
            slip = results[f"{c}.{v}.slip"]
            rows.append([v, num(slip[-1] * 1e3), num(np.max(np.abs(slip)) * 1e3),
                         num(last.get(f"{c}.{v}.normalForce", np.nan)), num(last.get(f"{c}.{v}.frictionForce", np.nan)),
                         _status(last.get(f"{c}.{v}.status"))])
        parts.append(f"### Curved support `{c}`\n\n" + _table(
            ["contact", "slip (mm)", "largest \\|slip\\| (mm)", "N (N)", "\\|T\\| (N)", "status"], rows))
    if len(parts) == 1:
        parts.append("No gaps or curved supports recorded.\n")
    out.append("\n".join(parts))

    # -- warnings
    said = []
    for status, _, text in messages or []:
        if status >= WARNING and text not in said:
            said.append(text)
    out.append("## Warnings\n\n" + ("\n".join(f"- {w}" for w in said) + "\n" if said else "None.\n"))

    # -- solver
    rows = [["steps taken", str(results.steps)], ["steps halved after a refusal", str(results.halvings)],
            ["rollbacks", str(results.rollbacks)]]
    for s in stats:
        rows.append([f"{s} (sum)", str(int(np.nansum(results[s][1:])))])
    out.append("## Solver\n\n" + _table(["quantity", "value"], rows, "---"))
    return "\n".join(out)


def line_reactions(vtu_file, model: dict) -> dict[str, np.ndarray]:
    """Reactions per unit length (N/m) along each boundary group and named support set of
    ``model`` (the model dict or JSON file the FMU was packed from) in a film VTK file the FMU
    (``results.directory``) or the CLI (``--vtk``) wrote: ``{name: rows}``, one row per node of
    the group or set in the model's order, ``[node, x, y, z, qx, qy, qz]`` (reference
    coordinates). The core computes them (point data ``line_reaction``: each node's reaction over
    its tributary length, half its film edges along the line; ``src/mech/results/lines.rs``); a node on
    two lines carries their sum. Needs meshio."""
    import json

    import meshio

    if not isinstance(model, dict):
        model = json.loads(Path(model).read_text())
    field = meshio.read(str(vtu_file)).point_data.get("line_reaction")
    if field is None:
        raise KeyError(f"{vtu_file}: no point data 'line_reaction' (a film file of this version's FMU or CLI)")
    nodes = np.asarray(model["nodes"], dtype=float)
    owners: dict[str, list[int]] = {g["name"]: list(g["nodes"]) for g in model.get("groups", [])}
    for s in model.get("supports", []):
        if "name" in s and s["node"] not in owners.setdefault(s["name"], []):
            owners[s["name"]].append(s["node"])
    return {name: np.column_stack([np.asarray(vs, float), nodes[vs], field[vs]]) for name, vs in owners.items()}


def line_reactions_markdown(lines: dict[str, np.ndarray]) -> str:
    """The report's section on the reactions per unit length (``{name: rows}`` of
    :func:`line_reactions`): per group or support set, the largest ``|q|`` and where, then one row
    per node."""
    parts = ["## Line reactions (N/m)\n"]
    summary = []
    for name, rows in lines.items():
        rows = np.asarray(rows, dtype=float).reshape(-1, 7)
        if not len(rows):
            continue
        q = np.linalg.norm(rows[:, 4:7], axis=1)
        k = int(np.argmax(q))
        summary.append([f"`{name}`", str(len(rows)), num(q[k]), str(int(rows[k, 0])),
                        ", ".join(num(v) for v in rows[k, 1:4])])
    if not summary:
        return "## Line reactions (N/m)\n\nNone recorded.\n"
    parts.append(_table(["line", "nodes", "largest \\|q\\| (N/m)", "at node", "x, y, z (m)"], summary))
    for name, rows in lines.items():
        rows = np.asarray(rows, dtype=float).reshape(-1, 7)
        if not len(rows):
            continue
        body = [[str(int(r[0]))] + [num(v) for v in r[1:7]] + [num(np.linalg.norm(r[4:7]))] for r in rows]
        parts.append(f"### `{name}`\n\n" + _table(["node", "x (m)", "y (m)", "z (m)", "qx", "qy", "qz", "\\|q\\|"], body))
    return "\n".join(parts)


def _status(v) -> str:
    if v is None or not np.isfinite(v):
        return "–"
    return {0: "Open", 1: "Stick", 2: "Slip"}.get(int(v), str(v))


def write(results, path, **kwargs) -> Path:
    """Writes :func:`markdown` of ``results`` to ``path`` and returns it."""
    path = Path(path)
    path.write_text(markdown(results, **kwargs))
    return path
