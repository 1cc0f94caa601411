"""Stiffness sweep of the coupled erection system (issue 21 item 4): iterations per coupling
step of each scheme of ``membrane_contact.coupling`` over the structure/film stiffness ratio
(four decades) and the communication step (two decades), and where each fails.

The film: the 300 mm ParallelArch specimen, μ = 0.2, tight Newton tolerances (1e-10). The
structure: the hydraulic jack FMU (fmu/jack), relief 600 N, pumping 0.5 mm/s, over 400 s. The
film's stiffness ``K_f = dRz/ddz`` is measured once (central difference of two film steps,
rolled back) where its reaction reaches the relief setting; the jack's stiffness is
``ratio · K_f``. Writes a Markdown table to stdout (docs/benchmarks.md holds one).

    .venv/bin/python benches/coupling_sweep.py [--ratios 0.01 0.1 1 10 100] [--steps 1 10 100]
        [--schemes gauss-seidel aitken iqn-ils newton newton-linearized]
        [--derivatives fmu|finite-differences]

``newton``: interface Newton with the jack solved exactly for the film's local model (the
default of ``membrane_contact.coupling``); ``newton-linearized``: both FMUs linearized, damped
(``structure_solve="linearized"``). The column "jack steps" counts the jack's extra steps of
the exact solves per coupling step (the jack is the cheap FMU; film steps are what costs).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))

from membrane_contact import Film  # noqa: E402
from membrane_contact.coupling import closing, erection_system  # noqa: E402
from membrane_contact.ssp import FILM_PARAMETERS, pack_jack_fmu  # noqa: E402

TIGHT = {"solver.displacementTolerance": 1e-10, "solver.residualTolerance": 1e-10}
DURATION = 400.0


def film_stiffness(relief: float = 600.0) -> tuple[float, float]:
    """``(dz, dRz/ddz)`` of the film where ``|Rz|`` first exceeds ``relief`` (1 mm steps)."""
    with Film(logging=False, quiet=True) as f:
        f.initialize({**FILM_PARAMETERS, **TIGHT})
        dz = 0.0
        while abs(f["frame.Rz"]) < relief:
            dz -= 1e-3
            f.set({"frame.dz": dz})
            f.step(1.0)
        s = f.save()
        ends = []
        for d in (1e-6, -1e-6):
            f.restore(s)
            f.set({"frame.dz": dz + d})
            f.step(1.0)
            ends.append(f["frame.Rz"])
        f.free(s)
        return dz, (ends[0] - ends[1]) / 2e-6


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--ratios", type=float, nargs="+", default=[0.01, 0.1, 1.0, 10.0, 100.0])
    p.add_argument("--steps", type=float, nargs="+", default=[1.0, 10.0, 100.0])
    p.add_argument("--schemes", nargs="+", default=["gauss-seidel", "aitken", "iqn-ils", "newton",
                                                    "newton-linearized"])
    p.add_argument("--derivatives", default="fmu", choices=["fmu", "finite-differences"],
                   help="the film's derivatives for 'newton' (fmu: fmi2GetDirectionalDerivative)")
    a = p.parse_args(argv)
    jack = pack_jack_fmu(ROOT / "target" / "fmu" / "HydraulicJack.fmu")
    dz, kf = film_stiffness()
    print(f"film stiffness K_f = dRz/ddz = {kf:.4g} N/m at dz = {dz * 1e3:.0f} mm (|Rz| = 600 N); "
          f"Newton's film derivatives: {a.derivatives}\n")
    print("| k_jack / K_f | h (s) | scheme | steps | iterations per step: mean | max | rollbacks | "
          "jack steps per step | fails at | time (s) |")
    print("|---:|---:|---|---:|---:|---:|---:|---:|---|---:|")
    for ratio in a.ratios:
        for h in a.steps:
            for scheme in a.schemes:
                t0 = time.perf_counter()
                with closing(erection_system(jack_fmu=jack, film_parameters=TIGHT,
                                             jack_parameters={"stiffness": ratio * kf})) as system:
                    options = {"derivatives": a.derivatives} if scheme.startswith("newton") else {}
                    if scheme == "newton-linearized":
                        options["structure_solve"] = "linearized"
                    try:
                        report = system.run(DURATION, h, scheme.split("-linearized")[0], **options)
                        fails = "—" if report.failure is None else (
                            f"t = {report.failure.time:g} s: {report.failure.reason}")
                    except RuntimeError as e:  # e.g. the film provides no derivatives
                        print(f"| {ratio:g} | {h:g} | {scheme} | — | — | — | — | — | {e} | — |")
                        continue
                it = report.iterations
                mean = f"{it.mean():.2f}" if len(it) else "—"
                top = f"{it.max()}" if len(it) else "—"
                extra = f"{sum(s.structure_steps for s in report.steps) / len(it):.1f}" if len(it) else "—"
                print(f"| {ratio:g} | {h:g} | {scheme} | {len(it)} | {mean} | {top} | {report.rollbacks} | "
                      f"{extra} | {fails} | {time.perf_counter() - t0:.1f} |", flush=True)


if __name__ == "__main__":
    main()
