"""The main job: the paper's parallel-arch specimen through the FMU, the project's reconstruction
beside the paper's literal gap model, both against Table 1.

1. **The reconstruction** (the project's answer; README "Crown to foot", docs/mechanics.md): the
   film wound onto the arch down to its foot, then the boundary extended by the strain ``eps``
   (``FramePath::Wrapped``), slip measured along the arch by the curved-support contact, ETFE's
   elasto-plastic film. The shipped ``ParallelArch.fmu`` cannot express it: its one specimen
   parameter is ``archHeight`` (the frame lowered, fixed-frame gaps, the linear film). So the model
   is exported with ``membrane-contact export-specimen --contact curved-support --wrap EPS
   --plastic --path-out TABLE``, packed into its own FMU (``build_fmu``) and stepped along that
   staged table of its 63 frame-node inputs with :class:`membrane_contact.Film`
   (``fig8_wrapped.Specimen``). ``eps`` stands for the paper's measured boundary movements (its
   ref. [6], not available): by default the value ``fig8_plastic.py`` fitted on Table 1's points
   2-5 for the plastic film (``docs/figures/fig8_plastic.csv``); ``--fit`` refits it here through
   the FMU (three runs), ``--eps`` sets it.
2. **The literal gap model** (the paper's §4): ``target/fmu/ParallelArch.fmu``, the outside frame
   (``frame.dz``) lowered to -H/2 in ``--steps`` equal communication steps, the linear film.

Prints observed points 1-5 (G1, G2, G4, G6, G8) of both beside Table 1, the RMS misfit on
points 2-5 (the points ``eps`` is fitted on; point 1 is the crown), the largest von Mises stress
at the end, and why the two differ.

    .venv/bin/python examples/run_specimen.py [--height 300] [--mu 0.2] [--steps 20]
                                              [--wrap-steps 40] [--eps EPS | --fit]
"""

from __future__ import annotations

import argparse
import csv
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import archfmu  # noqa: E402
import fig8_wrapped  # noqa: E402

ROOT = archfmu.ROOT
FITTED = ROOT / "docs" / "figures" / "fig8_plastic.csv"
FIT_POINTS = fig8_wrapped.FIT_POINTS
CONTACT = "curved-support"


def documented_eps(height_mm):
    """The plastic film's boundary extension fitted by fig8_plastic.py for this height, or None."""
    with open(FITTED) as f:
        for row in csv.DictReader(f):
            if row["film"] == "plastic" and float(row["arch_height_mm"]) == height_mm:
                return float(row["eps"])
    return None


def rms(points, measured):
    """RMS misfit (mm) of {point: slip mm} against Table 1 on points 2-5."""
    return (sum((points[p] - measured[p]) ** 2 for p in FIT_POINTS) / len(FIT_POINTS)) ** 0.5


def literal(fmu, height_mm, mu, steps):
    """The paper's gap model: frame.dz stepped to -H/2 through the ParallelArch FMU. Returns
    {"points": {point: (slip mm, status)}, "gaps": {gap: (slip mm, status)}, "stress": Pa,
    "reaction": frame.Rz N}."""
    target = -0.5 * height_mm / 1000.0
    with archfmu.Film(fmu, name="specimen", logging=False) as film:
        film.initialize(parameters={"archHeight": height_mm / 1000.0}, inputs={"mu": mu})
        times = [k / steps for k in range(1, steps + 1)]
        results = film.run({"time": times, "frame.dz": [target * t for t in times]}, quiet=True)
        gaps = {g: (1000.0 * results[f"{g}.slip"][-1], archfmu.STATUS[int(results[f"{g}.status"][-1])])
                for g in film.gaps}
        stress, reaction = results["film.maxEquivalentStress"][-1], results["frame.Rz"][-1]
    return {"points": {p: gaps[g] for p, g in archfmu.OBSERVED.items()}, "gaps": gaps, "stress": stress,
            "reaction": reaction}


def reconstruction(height_mm, mu, steps, eps=None, fit=False, work=None):
    """Crown to foot on curved supports with the plastic film, through its own packed FMU. ``eps``:
    the boundary extension (default: :func:`documented_eps`); ``fit``: refit it on Table 1 first.
    Returns {"eps", "source" ("fitted" or "given"), "reached" (eps reached), "points": {point:
    (slip mm, status)}, "stress": largest von Mises Pa, "fmu": the packed FMU's file name,
    "touching": (arch nodes in contact, of), "yielded": film elements with plastic strain,
    "elements": of}."""
    given = eps is not None and not fit
    with tempfile.TemporaryDirectory(prefix="run-specimen-") as tmp:
        specimen = fig8_wrapped.Specimen(height_mm, CONTACT, steps, work or tmp, plastic=True, mu=mu)
        if fit:
            if height_mm not in archfmu.read_table1():
                raise SystemExit(f"Table 1 has no {height_mm} mm specimen to fit eps on: give --eps")
            eps, points, _, reached = fig8_wrapped.fit(specimen, archfmu.read_table1()[height_mm])
        else:
            eps = documented_eps(height_mm) if eps is None else eps
            if eps is None:
                raise SystemExit(f"no fitted eps for {height_mm:g} mm in {FITTED}: give --eps or --fit")
            points, reached = specimen.slips(eps)
        final, nodes = specimen.final, specimen.model["curved_supports"][0]["nodes"]
        statuses = [int(final[f"arch.node{n}.status"]) for n in nodes]
        return {"eps": eps, "source": "given" if given else "fitted", "reached": reached, "points": points,
                "stress": final["film.maxEquivalentStress"], "fmu": specimen.fmu.name,
                "touching": (sum(s != 0 for s in statuses), len(statuses)),
                "yielded": final["film.yieldedElements"], "elements": len(specimen.model["triangles"])}


def report(height_mm, mu, steps, wrap_steps, rec, lit, measured):
    """The printed comparison (a list of lines)."""
    lines = [
        f"The {height_mm} mm parallel-arch specimen through the FMU (mu = {mu:g}), beside the paper's Table 1",
        f"  reconstruction: {rec['fmu']}, packed from `membrane-contact export-specimen",
        f"                  --height {height_mm} --contact {CONTACT} --wrap {rec['eps']:.6f} --plastic --path-out`,",
        f"                  stepped along that table ({wrap_steps} rows): the film wound onto the arch to its foot,",
        f"                  then its boundary extended by eps = {100 * rec['eps']:.2f} %; ETFE's elasto-plastic film",
        f"  literal gaps:   ParallelArch.fmu, the frame lowered to {-height_mm / 2:g} mm in {steps} steps; linear film",
    ]
    if rec["reached"] != rec["eps"]:
        lines.append(f"  (the reconstruction stalled at eps = {100 * rec['reached']:.2f} %: its state there is shown)")
    lines += ["",
              "observed  Table 1 |    reconstruction, slip (mm) |     literal gaps, slip (mm)",
              "point        (mm) |    slip    diff  status      | gap    slip    diff  status"]
    for p, g in archfmu.OBSERVED.items():
        m = measured[p] if measured else None
        (rs, rst), (ls, lst) = rec["points"][p], lit["points"][p]
        diff = (lambda s: f"{s - m:+8.2f}") if m is not None else (lambda s: f"{'-':>8}")
        lines.append(f"{p:<9}{f'{m:.1f}' if m is not None else '-':>8} | {rs:7.2f}{diff(rs)}  {rst:<11} | "
                     f"{g:<3}{ls:8.2f}{diff(ls)}  {lst}")
    lit_touch = sum(s != "open" for _, s in lit["gaps"].values())
    summary = [("max von Mises at the end", f"{rec['stress'] / 1e6:.2f} MPa (plastic)",
                f"{lit['stress'] / 1e6:.2f} MPa (linear)"),
               ("in contact at the end", f"{rec['touching'][0]} of {rec['touching'][1]} arch nodes",
                f"{lit_touch} of {len(lit['gaps'])} gaps")]
    if measured:
        summary.insert(0, ("RMS misfit, points 2-5",
                           f"{rms({p: s for p, (s, _) in rec['points'].items()}, measured):.2f} mm",
                           f"{rms({p: s for p, (s, _) in lit['points'].items()}, measured):.2f} mm"))
    lines.append("")
    lines += [f"{what:<26}{r:>22}   {l:>22}" for what, r, l in summary]
    open_points = [str(p) for p, (_, st) in lit["points"].items() if st == "open"]
    opened = (f"points {', '.join(open_points)}: film movement above the arch, not sliding"
              if open_points else "none at points 1-5")
    yielded = f"{rec['yielded']} of {rec['elements']} elements yield" if rec["yielded"] else "the film stays elastic"
    lines += ["",
              f"Why they differ: the lowered frame leaves {len(lit['gaps']) - lit_touch} of {len(lit['gaps'])} "
              f"gaps open ({opened}), and the linear film never yields;",
              f"wound to the foot and extended by the {rec['source']} eps, {rec['touching'][0]} of "
              f"{rec['touching'][1]} arch nodes touch and slide along the arch, and {yielded}."]
    return lines


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fmu", default=str(archfmu.DEFAULT_FMU), help="the ParallelArch FMU (literal gap model)")
    p.add_argument("--height", type=int, default=300, help="arch height in mm")
    p.add_argument("--mu", type=float, default=0.2)
    p.add_argument("--steps", type=int, default=20, help="steps of the literal model's frame lowering")
    p.add_argument("--wrap-steps", type=int, default=40, help="rows of the reconstruction's path table")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--eps", type=float, help="boundary extension of the reconstruction (default: the documented fit)")
    g.add_argument("--fit", action="store_true", help="refit eps on Table 1's points 2-5 through the FMU")
    a = p.parse_args(argv)
    rec = reconstruction(a.height, a.mu, a.wrap_steps, a.eps, a.fit)
    lit = literal(Path(a.fmu), a.height, a.mu, a.steps)
    measured = archfmu.read_table1().get(a.height)
    print("\n".join(report(a.height, a.mu, a.steps, a.wrap_steps, rec, lit, measured)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
