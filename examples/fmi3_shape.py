"""The film's shape through FMI 3.0: the displacement array of the FMI 3.0 FMU, plotted.

Lowers the specimen's frame in steps through ``fmpy.fmi3`` (the FMU packed with
``fmu-pack --fmi-version 3``), reads ``film.displacement`` (nodeCount × 3, sized by the
structural parameter ``film.nodeCount``) after the last step, adds it to the node positions of
the model (``resources/parallel_arch.json`` rebuilt by ``membrane-contact export-specimen``) and
plots the deformed film seen from the side. Writes ``<out>/fmi3_shape.png`` and
``<out>/fmi3_shape.csv`` (x, y, z of every deformed node).

    .venv/bin/python examples/fmi3_shape.py [--fmu target/fmu/ParallelArch_fmi3.fmu] [--out out/fmi3]
"""

import argparse
import json
import os
import pathlib
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi3 import FMU3Slave  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
CLI = os.environ.get("MEMBRANE_CONTACT_CLI", str(ROOT / "target" / "release" / "membrane-contact"))


def deformed_film(fmu, steps, depth):
    """The node positions plus the displacement array after lowering the frame by ``depth``."""
    d = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in d.modelVariables}
    film = FMU3Slave(guid=d.instantiationToken, unzipDirectory=extract(fmu),
                     modelIdentifier=d.coSimulation.modelIdentifier, instanceName="film")
    film.instantiate()
    film.enterInitializationMode(startTime=0.0)
    film.exitInitializationMode()
    h = 1.0 / steps
    for k in range(steps):
        film.setFloat64([vr["frame.dz"]], [-depth * (k + 1) / steps])
        film.doStep(k * h, h)
    (n,) = film.getUInt64([vr["film.nodeCount"]])
    u = np.reshape(film.getFloat64([vr["film.displacement"]], 3 * n), (n, 3))
    film.terminate()
    film.freeInstance()
    model = json.loads(subprocess.run([CLI, "export-specimen"], check=True, capture_output=True,
                                      text=True).stdout)
    return np.array(model["nodes"]) + u


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fmu", default=str(ROOT / "target" / "fmu" / "ParallelArch_fmi3.fmu"))
    p.add_argument("--out", default=str(ROOT / "out" / "fmi3"))
    p.add_argument("--steps", type=int, default=10)
    p.add_argument("--depth", type=float, default=0.015, help="how far the frame is lowered (m)")
    a = p.parse_args(argv)
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    x = deformed_film(a.fmu, a.steps, a.depth)
    np.savetxt(out / "fmi3_shape.csv", x, delimiter=",", header="x,y,z", comments="")
    fig, ax = plt.subplots(figsize=(7, 3))
    ax.scatter(x[:, 0], x[:, 2], s=6)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_title(f"film after lowering the frame by {a.depth * 1000:g} mm (FMI 3.0 array)")
    fig.tight_layout()
    fig.savefig(out / "fmi3_shape.png", dpi=120)
    print(f"{out / 'fmi3_shape.png'}: {len(x)} nodes, lowest z = {x[:, 2].min():.6f} m")


if __name__ == "__main__":
    main()
