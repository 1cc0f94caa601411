"""fmi-sim's FMI 3.0 output CSV against fmpy's FMI 3.0 and FMI 2.0 runs on the same inputs.

    python tests/fmi_sim/compare.py FMU2 FMU3 INPUT.csv FMISIM3.csv STOP INTERVAL [FMISIM2.csv]

Runs ``fmpy.simulate_fmu`` on the FMI 2.0 FMU and on the FMI 3.0 FMU of the same model with the
inputs of INPUT.csv (a ``time`` column and one column per input, a row at every communication
point, so that no interpolation rule of either importer decides a value), from 0 to STOP every
INTERVAL, and compares every column of fmi-sim's CSV (time and each output it recorded) with the
same column of both fmpy runs, bit for bit: the CSV's numbers parsed as float64 (fmi-sim writes
the shortest text that reads back as the same double) and compared as bytes (so -0.0 and 0.0
differ). With FMISIM2.csv (fmi-sim's run of the FMI 2.0 FMU) that one too. Exits 1 on a difference.
"""

from __future__ import annotations

import csv
import sys

import numpy as np
from fmpy import read_model_description, simulate_fmu


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    parse = lambda s: 1.0 if s == "true" else 0.0 if s == "false" else float(s)
    return {name: np.array([parse(r[i]) for r in body], dtype=np.float64) for i, name in enumerate(header)}


def main(fmu2, fmu3, input_csv, sim3_csv, stop, interval, sim2_csv=None):
    stop, interval = float(stop), float(interval)
    given = read_csv(input_csv)
    inputs = np.array(list(zip(*given.values())), dtype=[(n, np.float64) for n in given])
    run = lambda fmu: simulate_fmu(fmu, start_time=0.0, stop_time=stop, output_interval=interval,
                                   input=inputs)
    ref = {"fmpy FMI 2.0": run(fmu2), "fmpy FMI 3.0": run(fmu3)}
    sims = {"fmi-sim FMI 3.0": read_csv(sim3_csv)}
    if sim2_csv:
        sims["fmi-sim FMI 2.0"] = read_csv(sim2_csv)
    outputs = [v.name for v in read_model_description(fmu3).modelVariables if v.causality == "output"]
    arrays = [v.name for v in read_model_description(fmu3).modelVariables
              if v.causality == "output" and v.dimensions]
    ok = True
    for sim_name, sim in sims.items():
        columns = [c for c in sim if c == "time" or c in outputs]
        missing = [o for o in outputs if o not in sim and o not in arrays]
        if missing:
            print(f"{sim_name}: scalar outputs not in its CSV: {missing}")
            ok = False
        for ref_name, r in ref.items():
            differ = []
            for c in columns:
                a = np.ascontiguousarray(r[c], dtype=np.float64)
                b = sim[c]
                if a.shape != b.shape or a.tobytes() != b.tobytes():
                    diff = np.max(np.abs(a - b)) if a.shape == b.shape else "rows differ"
                    differ.append(f"{c} ({diff})")
            rows = len(sim["time"])
            if differ:
                ok = False
                print(f"{sim_name} vs {ref_name}: {len(differ)} of {len(columns)} columns differ: {differ}")
            else:
                print(f"{sim_name} vs {ref_name}: {len(columns)} columns (time and {len(columns) - 1} "
                      f"outputs) x {rows} rows bit-identical")
    # the two fmpy runs agree with each other on every output (arrays: FMI 3.0 only)
    a2, a3 = ref["fmpy FMI 2.0"], ref["fmpy FMI 3.0"]
    same = all(np.ascontiguousarray(a2[c], dtype=np.float64).tobytes() ==
               np.ascontiguousarray(a3[c], dtype=np.float64).tobytes() for c in a2.dtype.names)
    print(f"fmpy FMI 3.0 vs fmpy FMI 2.0: {len(a2.dtype.names)} columns "
          f"{'bit-identical' if same else 'DIFFER'}")
    ok &= same
    loaded = [c for c in a2.dtype.names if c.endswith(".Rz") and a2[c][-1] != 0.0]
    if not loaded:
        print("no reaction Rz is nonzero at the end: the film was not loaded")
        ok = False
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
