"""Your own model through the FMU: a Python master for the film imported from gmsh.

The README's "your own model" path: ``python -m membrane_contact.mesh`` made ``out/film.json``
from a gmsh mesh and a mapping, ``fmu-pack`` made ``target/fmu/FilmOverTwoArches.fmu`` from it;
this master lowers the frame in a staged path, tries a stiffer friction from the mid-point and
rolls back, writes VTK for ParaView and a slip plot.

    .venv/bin/python examples/own_model.py [--fmu target/fmu/FilmOverTwoArches.fmu] [--out out/own_model]
"""

import argparse
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
try:
    from membrane_contact import Film, plot
except ImportError:  # run from a checkout without the package installed (pip install ./python)
    sys.path.insert(0, str(ROOT / "python"))
    from membrane_contact import Film, plot


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fmu", default=str(ROOT / "target" / "fmu" / "FilmOverTwoArches.fmu"))
    p.add_argument("--out", default=str(ROOT / "out" / "own_model"))
    p.add_argument("--steps", type=int, default=6)
    p.add_argument("--depth", type=float, default=0.15, help="how far the frame is lowered (m)")
    a = p.parse_args(argv)
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    times = [(k + 1) / a.steps for k in range(a.steps)]
    with Film(a.fmu) as film:
        film.initialize(parameters={"results.directory": str(out / "vtk")})
        half = a.steps // 2
        first = film.run({"time": times[:half], "frame.dz": [-a.depth * t for t in times[:half]]})
        state = film.save()                                    # the mid-point
        trial = film.run({"time": times[half:], "frame.dz": [-a.depth * t for t in times[half:]],
                          "mu": [0.5] * (a.steps - half)})
        film.restore(state)                                    # back: keep the model's friction
        rest = film.run({"time": times[half:], "frame.dz": [-a.depth * t for t in times[half:]]})
        print(f"{film.md.modelName}: frame lowered {a.depth * 1e3:.0f} mm in {a.steps} steps "
              f"({first.halvings + rest.halvings} halved)")
        names, slips = rest.slips()
        _, trial_slips = trial.slips()
        for n, s, s5 in zip(names, slips[-1], trial_slips[-1]):
            print(f"{n:>5}: slip {s * 1e3:7.2f} mm (with mu = 0.5: {s5 * 1e3:7.2f} mm), "
                  f"N = {rest[n + '.normalForce'][-1]:7.1f} N")
        print(f"frame reaction Rz = {rest['frame.Rz'][-1]:.1f} N, centre uz = {rest['centre.uz'][-1] * 1e3:.2f} mm")
    import matplotlib

    matplotlib.use("Agg")
    ax = plot.slip_along_support(rest)
    ax.figure.savefig(out / "slip.png", dpi=100)
    print(f"VTK for ParaView: {out / 'vtk' / 'FilmOverTwoArches_film.pvd'}; plot: {out / 'slip.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
