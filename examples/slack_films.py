"""Slack starts of issue 19: films that hold no load in their initial shape.

* :func:`disc`: a flat, unstressed clamped disc (radius 0.5 m, ETFE 250 µm, no prestress) under
  its own weight only (``material.density``, default gravity): Hencky's problem for a dead load.
  Meshed in rings (the centre, then ``6k`` nodes on ring ``k``: 8 rings, 217 nodes); the rim is
  the group ``rim`` held at zero. ``sag`` > 0 starts it from the curved shape
  ``z = −sag (1 − r²/R²)`` instead of the flat one (the reference computation).
* :func:`strip`: a flat, unstressed strip (2 m × 0.1 m) clamped at both ends whose middle line
  (group ``lift``) is raised 0.1 m.

Run: ``python examples/slack_films.py --out DIR`` writes ``SlackDisc.json``, ``SlackDiscCurved.json``
and ``SlackStrip.json``.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

ETFE = {"youngs_modulus": 800e6, "poisson_ratio": 0.45, "thickness": 250e-6}


def ring_mesh(radius: float, rings: int):
    """Nodes ``[x, y, 0]`` and counter-clockwise triangles of a disc meshed in rings; the index of
    the first rim node."""
    nodes, first = [[0.0, 0.0, 0.0]], [0]
    for k in range(1, rings + 1):
        first.append(len(nodes))
        for i in range(6 * k):
            a = 2 * math.pi * i / (6 * k)
            nodes.append([radius * k / rings * math.cos(a), radius * k / rings * math.sin(a), 0.0])
    triangles = []
    for k in range(1, rings + 1):
        inner = [first[k - 1] + i for i in range(max(1, 6 * (k - 1)))]
        outer = [first[k] + i for i in range(6 * k)]
        if k == 1:
            triangles += [[0, outer[i], outer[(i + 1) % 6]] for i in range(6)]
            continue
        # zipper: advance along the ring whose next node comes first in angle
        i = j = 0
        ni, no = len(inner), len(outer)
        while i < ni or j < no:
            ai = (i + 1) / ni
            ao = (j + 1) / no
            if j < no and (i >= ni or ao <= ai):
                triangles.append([inner[i % ni], outer[j], outer[(j + 1) % no]])
                j += 1
            else:
                triangles.append([inner[i % ni], outer[(j) % no], inner[(i + 1) % ni]])
                i += 1
    return nodes, triangles, first[rings]


def disc(radius: float = 0.5, rings: int = 8, sag: float = 0.0, density: float = 1750.0,
         wrinkling: str | None = None) -> dict:
    """The clamped disc under self-weight (see the module doc)."""
    nodes, triangles, rim = ring_mesh(radius, rings)
    for p in nodes:
        p[2] = -sag * (1 - (p[0] ** 2 + p[1] ** 2) / radius ** 2)
    material = dict(ETFE, density=density)
    if wrinkling is not None:
        material["wrinkling"] = wrinkling
    return {
        "name": "SlackDiscCurved" if sag else "SlackDisc",
        "description": "flat unstressed clamped disc under its own weight (issue 19)",
        "nodes": nodes, "triangles": triangles, "material": material,
        "groups": [{"name": "rim", "nodes": list(range(rim, len(nodes))), "target": [0.0, 0.0, 0.0]}],
        "outputs": {"points": [{"name": "centre", "node": 0}],
                    "element_sets": [{"name": "disc", "elements": "all"},
                                     {"name": "middle", "elements": list(range(6))}]},
    }


def strip(length: float = 2.0, width: float = 0.1, nx: int = 41, ny: int = 3, lift: float = 0.1,
          wrinkling: str | None = None) -> dict:
    """The slack strip lifted at its middle (see the module doc); ``nx`` odd."""
    nid = lambda i, j: j * nx + i  # noqa: E731
    nodes = [[length * i / (nx - 1), width * j / (ny - 1), 0.0] for j in range(ny) for i in range(nx)]
    triangles = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            a, b, c, d = nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1)
            triangles += [[a, b, c], [a, c, d]]
    material = dict(ETFE)
    if wrinkling is not None:
        material["wrinkling"] = wrinkling
    mid = (nx - 1) // 2
    return {
        "name": "SlackStrip",
        "description": "flat unstressed strip clamped at both ends, lifted at its middle (issue 19)",
        "nodes": nodes, "triangles": triangles, "material": material,
        "groups": [{"name": "ends", "nodes": [nid(i, j) for j in range(ny) for i in (0, nx - 1)],
                    "target": [0.0, 0.0, 0.0]},
                   {"name": "lift", "nodes": [nid(mid, j) for j in range(ny)], "target": [0.0, 0.0, lift]}],
        "outputs": {"points": [{"name": "quarter", "node": nid(mid // 2, ny // 2)}]},
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default=".")
    a = p.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    for m in (disc(), disc(sag=0.01), strip()):
        (out / f"{m['name']}.json").write_text(json.dumps(m))
        print(out / f"{m['name']}.json")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
