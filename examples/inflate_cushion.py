"""Inflating an ETFE cushion through its FMU with fmpy's ``simulate_fmu``.

Packs nothing: run ``cargo run --release --bin fmu-pack -- examples/cushion.json`` first (it
writes ``target/fmu/Cushion.fmu``). The inside pressure ``inside.pressure`` is raised from 0 to
300 Pa over pseudo-time 0…1 in ``--steps`` communication steps; the crown rises, the film
stresses grow, the rim carries the weight (the pressure on a closed cushion has no resultant).

fmpy sets a step's inputs from the signal at the step's *start* time and the FMU reaches them at
the step's *end*, so the signal row at ``t_k`` holds the pressure wanted at ``t_k + h``.

    .venv/bin/python examples/inflate_cushion.py [--steps 10] [--pressure 300] [--out cushion.csv]
"""

import argparse
import csv
import pathlib

import numpy as np
from fmpy import simulate_fmu

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUTPUTS = ["crownTop.uz", "crownBottom.uz", "upper.maxEquivalentStress", "lower.maxEquivalentStress",
           "rim.Rz", "solver.iterations"]


def inflate(fmu, pressure, steps):
    """The outputs after each communication step (a numpy structured array, first row t = 0)."""
    h = 1.0 / steps
    times = [k * h for k in range(steps)] + [1.0]
    wanted = [pressure * min(k + 1, steps) / steps for k in range(steps + 1)]
    # Every input gets a column (fmpy warns about the others): the rim stays where it is.
    held = ["rim.dx", "rim.dy", "rim.dz"]
    signal = np.array([(t, p, 0.0, 0.0, 0.0) for t, p in zip(times, wanted)],
                      dtype=[("time", float), ("inside.pressure", float)] + [(n, float) for n in held])
    return simulate_fmu(str(fmu), stop_time=1.0, output_interval=h, input=signal, output=OUTPUTS)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fmu", default=str(ROOT / "target" / "fmu" / "Cushion.fmu"))
    p.add_argument("--steps", type=int, default=10)
    p.add_argument("--pressure", type=float, default=300.0)
    p.add_argument("--out", default=None, help="CSV file of the outputs per step")
    a = p.parse_args()
    result = inflate(a.fmu, a.pressure, a.steps)
    for row in result:
        print(f"t = {row['time']:.2f}: crowns {row['crownTop.uz'] * 1e3:+7.2f} / "
              f"{row['crownBottom.uz'] * 1e3:+7.2f} mm, von Mises ≤ "
              f"{max(row['upper.maxEquivalentStress'], row['lower.maxEquivalentStress']) / 1e6:.2f} MPa, "
              f"rim Rz {row['rim.Rz']:.2f} N")
    if a.out:
        with open(a.out, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(result.dtype.names)
            w.writerows(result.tolist())


if __name__ == "__main__":
    main()
