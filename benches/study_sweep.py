"""A 200-case sweep through membrane_contact.study on LocalCluster with 1 and 2 workers (issue 22).

The paper's 300 mm specimen (ParallelArch) lowered to -H/2 in 10 steps, over a full factorial of
mu (10 levels) x film.prestressX = film.prestressY (5) x film.E (4) = 200 cases. Runs the study
in-process one case after another (no Dask: the cost of the runs alone), then on a LocalCluster
of 1 and of 2 single-threaded worker processes (cluster start-up included and reported apart),
checks that the three datasets are identical bit for bit, and prints a Markdown table of wall
time per case. Not a test: run it by hand on a quiet machine.

    .venv/bin/python benches/study_sweep.py [--fmu target/fmu/ParallelArch.fmu] [--cases-per-mu 20]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))

from membrane_contact.study import Study, cluster, factorial, run_case  # noqa: E402


def design():
    d = factorial({"mu": list(np.round(np.linspace(0.1, 0.55, 10), 3)),
                   "film.prestressX": [0.25e6, 0.5e6, 1.0e6, 1.5e6, 2.0e6],
                   "film.E": [0.6e9, 0.8e9, 1.0e9, 1.2e9]})
    d["film.prestressY"] = d["film.prestressX"].copy()
    return d


PATH = {"time": [k / 10 for k in range(1, 11)], "frame.dz": [-0.015 * k for k in range(1, 11)]}
OUTPUTS = ["G1.slip", "G2.slip", "G3.slip", "G4.slip", "G6.slip", "G8.slip", "frame.Rz", "film.maxEquivalentStress"]


def bits(ds) -> dict:
    return {v: ds[v].values.tobytes() for v in ds.data_vars}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fmu", default=str(Path(__file__).resolve().parents[1] / "target" / "fmu" / "ParallelArch.fmu"))
    a = p.parse_args(argv)
    d = design()
    n = len(d["mu"])
    load = os.getloadavg()[0]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        # In-process, no Dask: the runs alone.
        study = Study(a.fmu, d, PATH, OUTPUTS, directory=Path(tmp) / "serial")
        study._prepare_directory()
        from membrane_contact.study import write_case

        started = time.perf_counter()
        for k in range(n):
            write_case(study.directory, run_case(study.fmu, *study.case_arguments(k)), study.outputs, study.times)
        rows.append(("in-process, no Dask", time.perf_counter() - started, 0.0))
        reference = study.dataset()
        cpus = []
        for workers in (1, 2):
            started = time.perf_counter()
            with cluster(workers=workers) as client:
                up = time.perf_counter() - started
                ds = Study(a.fmu, d, PATH, OUTPUTS, directory=Path(tmp) / f"w{workers}").run(client, progress=False)
            total = time.perf_counter() - started
            if bits(ds) != bits(reference) or not ds.identical(reference):
                print(f"{workers} worker(s): the dataset differs from the in-process one", file=sys.stderr)
                return 1
            rows.append((f"LocalCluster, {workers} worker{'s' if workers > 1 else ''}", total - up, up))
            cpu = [r["cpu_seconds"] for r in Study(a.fmu, d, PATH, OUTPUTS, directory=Path(tmp) / f"w{workers}")
                   .results().values()]
            cpus.append(f"{workers} worker(s): {1000 * np.mean(cpu):.1f} ms CPU per case on the worker "
                        f"(median {1000 * np.median(cpu):.1f})")
    assert (reference.status == "ok").all(), reference.status.values
    print(f"{n} cases, {len(PATH['time'])} steps each, {len(OUTPUTS)} outputs; load average before: "
          f"{load:.2f} on {os.cpu_count()} cores\n")
    print("| run | wall time (s) | per case (ms) | speed-up | cluster start (s) |")
    print("|---|---|---|---|---|")
    base = rows[1][1]
    for name, seconds, up in rows:
        print(f"| {name} | {seconds:.2f} | {1000 * seconds / n:.1f} | "
              f"{base / seconds:.2f} | {up:.2f} |" if up else
              f"| {name} | {seconds:.2f} | {1000 * seconds / n:.1f} | {base / seconds:.2f} | — |")
    print("\n" + "; ".join(cpus) + ".")
    print("\nThe datasets of the three runs are identical bit for bit (every float of every output).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
