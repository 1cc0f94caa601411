"""An ETFE cushion kept up by its inflation unit, through a snow event and a gust (issue 43).

Two FMUs coupled by the project's co-simulation master (``membrane_contact.coupling``, the
``staggered`` scheme: the unit steps with the cushion's pressure, the film takes in the unit's
mass flow of the same step): the cushion (``examples/cushion_air.json`` shaped as two spherical
caps, its air sealed at 300 Pa: ``membrane_contact.inflation.cushion_model``) and the inflation
unit (``fmu/inflation``: fan curve, non-return valve, leakage, pressure switch 250/350 Pa with a
1.5 s start/stop delay, and a snow mode that raises the switch's band to 400/550 Pa). Quiet
until 60 s, then 0.5 kPa of snow (ramped over 10 s, lying for 50 s, melting over 10 s; the
unit's snow mode is on while it lies: ``membrane_contact.inflation.snow_lies``), then a gust of
0.4 kPa suction on the top layer at 170 s.

Writes a plot of the cushion's pressure, the fan's duty and the top layer's deflection
(``--out``, PNG) and the records (``--csv``), and prints the largest pressure during the snow
event (Pa, one decimal): the number ``tests/python/test_inflation.py`` checks.

    .venv/bin/python examples/inflation_unit.py [--out inflation_unit.png] [--csv run.csv] [--step 1]

Builds nothing but the two FMUs: run ``cargo build --release`` first (``fmu/prepare.sh`` does).
"""

import argparse
import csv
import pathlib
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "python"))

from membrane_contact.coupling import closing  # noqa: E402
from membrane_contact.inflation import (  # noqa: E402
    COLUMNS, cushion_system, pack_cushion_fmu, pack_unit_fmu, run_events, snow_lies)

#: The run's length (s): past the gust, the unit back at its cycle.
DURATION = 240.0


def plot(run, path):
    """Pressure with the switch's band (the snow band while snow mode is on), the fan's duty per
    step, the crowns' deflections."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = run["time"]
    fig, (a, b, c) = plt.subplots(3, 1, sharex=True, figsize=(8, 8))
    a.plot(t, run["pressure"], label="cushion")
    a.plot(t, run["snow"], "--", label="snow (plan)")
    a.plot(t, -run["wind"], ":", label="wind (suction < 0)")
    snow = run["snowMode"] > 0.0
    for normal, snowy in ((250.0, 400.0), (350.0, 550.0)):
        a.step(t, [snowy if s else normal for s in snow], where="pre", color="grey", lw=0.5)
    a.set_ylabel("pressure (Pa)")
    a.legend(loc="upper right")
    b.step(t, run["duty"], where="pre", label="duty of the step")
    b.plot(t, run["dutyTotal"], label="duty since the start")
    b.set_ylabel("fan duty")
    b.legend(loc="upper right")
    c.plot(t, run["top"] * 1e3, label="top crown")
    c.plot(t, run["bottom"] * 1e3, label="bottom crown")
    c.set_ylabel("deflection (mm)")
    c.set_xlabel("time (s)")
    c.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="inflation_unit.png", help="the plot (PNG)")
    p.add_argument("--csv", default=None, help="CSV of the records per step")
    p.add_argument("--step", type=float, default=1.0, help="communication step (s)")
    a = p.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        film_fmu, unit_fmu = pack_cushion_fmu(tmp, root=ROOT), pack_unit_fmu(tmp, root=ROOT)
        with closing(cushion_system(film_fmu, unit_fmu)) as system:
            run = run_events(system, DURATION, a.step, snow_mode=snow_lies)
    plot(run, a.out)
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(COLUMNS)
            w.writerows(zip(*(run[c] for c in COLUMNS)))
    snow = run["snow"] > 0.0
    gust = run["wind"] > 0.0
    print(f"quiet: pressure {run['pressure'][run['time'] <= 60].min():.1f}..{run['pressure'][run['time'] <= 60].max():.1f} Pa, "
          f"duty {run['dutyTotal'][run['time'] <= 60][-1]:.3f}")
    print(f"snow: top crown down to {run['top'][snow].min() * 1e3:.2f} mm, fan duty {run['duty'][snow].mean():.3f}")
    print(f"gust: pressure down to {run['pressure'][gust].min():.1f} Pa, fan duty {run['duty'][gust].mean():.3f}, "
          f"top crown up to {run['top'][gust].max() * 1e3:.2f} mm")
    print(f"air: {run['mass'][0]:.6f} kg at the start, {run['mass'][-1]:.6f} kg at {run['time'][-1]:g} s; "
          f"fan duty over the run {run['dutyTotal'][-1]:.3f}")
    print(f"largest pressure during the snow event: {run['pressure'][snow].max():.1f} Pa")


if __name__ == "__main__":
    main()
