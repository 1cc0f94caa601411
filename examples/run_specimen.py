"""The main job: the paper's 300 mm parallel-arch specimen stepped to its target through the FMU.

Loads target/fmu/ParallelArch.fmu with fmpy, sets the arch height and the friction coefficient,
lowers the outside frame (``frame.dz``) to its target in equal communication steps, and prints
the slip of every gap beside the paper's Table 1 (observed points 1-5 = G1, G2, G4, G6, G8).

    .venv/bin/python examples/run_specimen.py [--height 300] [--mu 0.2] [--steps 20]
"""

import argparse
import csv
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
try:
    from membrane_contact import Film
except ImportError:  # run from a checkout without the package installed (pip install ./python)
    sys.path.insert(0, str(ROOT / "python"))
    from membrane_contact import Film
OBSERVED = ["G1", "G2", "G4", "G6", "G8"]
STATUS = {0: "open", 1: "stick", 2: "slip"}


def table1(height_mm):
    """Measured sliding (mm) at observed points 1-5 for one specimen, or None."""
    rows = (ROOT / "data" / "table1_sliding.csv").read_text().splitlines()
    for row in csv.DictReader(line for line in rows if not line.startswith("#")):
        if abs(float(row["arch_height_mm"]) - height_mm) < 1e-9:
            return [float(row[f"p{i}"]) for i in range(1, 6)]
    return None


def run(fmu, height_mm, mu, steps):
    """Steps frame.dz to -H/2 in `steps` communication steps; returns {gap: (slip mm, status)}."""
    target = -0.5 * height_mm / 1000.0
    with Film(fmu, name="specimen") as film:
        film.initialize(parameters={"archHeight": height_mm / 1000.0}, inputs={"mu": mu})
        times = [k / steps for k in range(1, steps + 1)]
        results = film.run({"time": times, "frame.dz": [target * t for t in times]})
        gaps = film.gaps
        slips = [results[f"{g}.slip"][-1] for g in gaps]
        status = [int(results[f"{g}.status"][-1]) for g in gaps]
        reaction, stress = results["frame.Rz"][-1], results["film.maxEquivalentStress"][-1]
    return {g: (1000.0 * s, STATUS.get(st, st)) for g, s, st in zip(gaps, slips, status)}, reaction, stress


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fmu", default=str(ROOT / "target" / "fmu" / "ParallelArch.fmu"))
    p.add_argument("--height", type=float, default=300.0, help="arch height in mm")
    p.add_argument("--mu", type=float, default=0.2)
    p.add_argument("--steps", type=int, default=20)
    a = p.parse_args(argv)
    result, reaction, stress = run(pathlib.Path(a.fmu), a.height, a.mu, a.steps)
    print(f"ParallelArch FMU, arch height {a.height:.0f} mm, mu = {a.mu}, frame.dz = {-a.height / 2:.0f} mm "
          f"in {a.steps} steps")
    print(f"\n{'gap':<5}{'slip (mm)':>11}  status")
    for g, (s, st) in result.items():
        print(f"{g:<5}{s:>11.2f}  {st}")
    print(f"\nframe reaction Rz = {reaction:.1f} N, max equivalent stress = {stress / 1e6:.2f} MPa")
    measured = table1(a.height)
    print("\nobserved point  gap   analysis (mm)  Table 1 (mm)  difference (mm)")
    for i, g in enumerate(OBSERVED):
        s, st = result[g]
        m = f"{measured[i]:>12.1f}  {s - measured[i]:>15.2f}" if measured else f"{'-':>12}  {'-':>15}"
        print(f"{i + 1:<15} {g:<4}{s:>14.2f}  {m}   ({st})")
    print("\nGaps that are open at the end do not touch the arch: their 'slip' is film movement "
          "relative to the arch point. The specimen's dimensions are assumptions "
          "(src/specimens/parallel_arch.rs), so the comparison is qualitative.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
