"""The vault bay of issue 46: an ETFE film over five tube arches and a ridge tube, 6 m x 3 m.

Builds the model (arches: rings of radius 3.75 m in the planes y = 0, 0.75, ..., 3 m, rise 1.5 m
over the 6 m span, tube radius 30 mm; a ridge tube along the crown; rails along both feet; bay
ends on symmetry planes; ETFE 250 um, E = 1 GPa, nu = 0.43, data-sheet hardening; mu = 0.3),
finds its shape against the supports for 1.5 MPa isotropic (frictionless while found), cuts it
into eight strips 0.375 m wide across the arches, and erects each compensation with the
analysis: the prestress compensation corrected per strip, and per element. Prints the prestress
error per erection (away from the rails), the triangles outside 1.5 MPa +- 5 %, and the yielded
ones, for three erection paths: the cut laid at its fitted reference on the supports and the
rails drawn straight to their places; the issue's: the rails start 0.10 m higher and 0.03 m
inward and are pulled down and out (40 increments); and the issue's path settled (``SETTLE``):
the rails then pass their places by 1 mm and come back short of them by 0.7 mm, and so on, 12
waypoints shrinking by 0.7, before they end at their places. On the first two every contact
node off the crown ends sliding towards its rail and the prestress falls from the rails to the
crown by the capstan's e^(-mu theta), whatever the cut; settled, the contact nodes stick and
every element away from the rails is within 1.5 MPa +- 5 %. Prints the contact nodes' end
census (sticking, sliding) per path too. The tubes' penalties are per metre of contact line
(3.4e7 and 3.4e6 N/m per m: the design loop gives each node that times its spacing, 0.292 m on
24 x 8 cells; docs/mechanics.md "Contact stiffness in the design loop"). ``SETTLE`` may be
"auto": the loop then chooses the amplitude (2.99 mm here). Run: python examples/vault_bay.py
[N_PHI N_Y] (about 20 s; the mesh table is in docs/mechanics.md "Settling")."""

SETTLE = (0.001, 0.7, 12)

import json
import math
import sys

from membrane_contact.design import form_find, pattern

R, TUBE, CENTRE_Z, SPAN, BAY, MU = 3.75, 0.03, -2.25, 6.0, 3.0, 0.3


def vault_bay(n_phi=24, n_y=8, mu=MU):
    """The model as a dict: the film on the arches' cylinder, rails at the feet."""
    phi0 = math.asin(0.5 * SPAN / R)
    idx = lambda i, j: j * (n_phi + 1) + i
    nodes = [[(R + TUBE) * math.sin(-phi0 + 2 * phi0 * i / n_phi), BAY * j / n_y,
              CENTRE_Z + (R + TUBE) * math.cos(-phi0 + 2 * phi0 * i / n_phi)]
             for j in range(n_y + 1) for i in range(n_phi + 1)]
    triangles = []
    for j in range(n_y):
        for i in range(n_phi):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            triangles += [[a, b, c], [a, c, d]] if (i < n_phi // 2) == (j % 2 == 0) else [[a, b, d], [b, c, d]]
    arch_rows = [j for j in range(n_y + 1) if (4 * j) % n_y == 0]
    inner = range(1, n_phi)
    contact = {"normal_stiffness": 3.4e7, "tangential_stiffness": 3.4e6, "friction": mu, "tube_radius": TUBE}
    supports = [dict(name=f"arch{k}", nodes=[idx(i, j) for i in inner], **contact,
                     centreline={"circle": {"centre": [0, BAY * j / n_y, CENTRE_Z], "axis": [0, 1, 0], "radius": R}})
                for k, j in enumerate(arch_rows)]
    supports.append(dict(name="ridge", nodes=[idx(n_phi // 2, j) for j in range(n_y + 1) if j not in arch_rows],
                         centreline={"line": {"point": [0, 0, CENTRE_Z + R], "axis": [0, 1, 0]}}, **contact))
    return {
        "name": "VaultBay", "description": "Issue 46: a film over five tube arches and a ridge tube",
        "nodes": nodes, "triangles": triangles,
        "material": {"youngs_modulus": 1e9, "poisson_ratio": 0.43, "thickness": 250e-6,
                     "prestress": [1.5e6, 1.5e6, 0.0], "wrinkling": "none",
                     "plasticity": {"hardening": "etfe-23C"}},
        "supports": [], "gaps": [],
        "symmetry": [{"name": n, "normal": "y", "nodes": [idx(i, j) for i in inner]} for n, j in (("south", 0), ("north", n_y))],
        "groups": [{"name": n, "nodes": [idx(i, j) for j in range(n_y + 1)], "target": [0, 0, 0]}
                   for n, i in (("railW", 0), ("railE", n_phi))],
        "curved_supports": supports,
    }


def main(n_phi=24, n_y=8, mu=MU, paths=((None, 10, None), ((0.10, 0.03), 40, None), ((0.10, 0.03), 40, SETTLE))):
    found = form_find(vault_bay(n_phi, n_y, mu), on_supports=True)
    seams = [(0, BAY * k / n_y, 0, 0, 1, 0) for k in range(1, n_y)]
    reports = []
    for rail_path, increments, settle in paths:
        print("rails drawn straight to their places" if rail_path is None
              else f"rails from {rail_path[0]} m up and {rail_path[1]} m in, pulled down and out"
              + ("" if settle is None else ", settled (amplitude chosen by the loop)" if settle == "auto"
                 else f", settled ({settle[0]} m past, shrinking by {settle[1]}, {settle[2]} waypoints)"))
        for name, by_element in (("prestress compensation, per strip", False), ("per element", True)):
            report = pattern(found, seam_planes=seams, erect=4, erect_tolerance=5.0, by_element=by_element,
                             rail_path=rail_path, erect_increments=increments, settle=settle)
            reports.append(report)
            print(" ", name)
            for k, e in enumerate(report["erections"]):
                print(f"    erection {k}: mean error {100 * e['mean_error']:.2f} %, max {100 * e['max_error']:.2f} %"
                      + (f", {e['outside_tolerance']} triangles outside 1.5 MPa +- 5 %, {e['yielded']} yielded,"
                         f" contact nodes {census(e['contacts'])}" if by_element else ""))
            if by_element:
                print(f"    not reached: {len(report['stalled'])} triangles, {len(report['held_by_friction'])}"
                      " held by friction" if report["stalled"] else "    reached")
    return found, reports


def census(contacts):
    """How many contact nodes stick, slide, or are open at the end."""
    counts = {}
    for c in contacts:
        counts[c["status"]] = counts.get(c["status"], 0) + 1
    return ", ".join(f"{n} {s.lower()}" for s, n in sorted(counts.items()))


if __name__ == "__main__":
    main(*map(int, sys.argv[1:3]))
