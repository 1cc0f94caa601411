"""Construction stage: a hydraulic jack lowers the outside frame and stalls at its relief force,
two FMUs coupled to convergence every communication step.

The coupled erection system (``membrane_contact.ssp``: the same two FMUs and parameters as the
``.ssp`` archive that fmpy and libcosim run):

* the film, the ParallelArch FMU (300 mm arch, μ = 0.2, 1/4 model): input ``frame.dz``, output
  ``frame.Rz``, the film's reaction, with the slips and gap statuses;
* the jack, the HydraulicJack FMU (``fmu/jack``): a constant-flow pump lowers the piston at
  ``rate``; a relief valve starts to open at 0.85 x ``relief`` and bypasses all the flow at
  ``relief`` (the jack stalls); the cylinder's ``stiffness`` links piston and frame
  (``dz = piston − force / stiffness``); the stroke ends at ``stroke``.

The master (``membrane_contact.coupling``, scheme ``--scheme``) steps the film to a frame
position, the jack under the film's reaction, compares the jack's frame position with the one
assumed, and repeats from the step's start (both FMUs rolled back with fmi2SetFMUstate) until
they agree to 1e-7 (relative). Default: interface Newton with both FMUs' directional
derivatives, the film linearized and the jack solved exactly for it (its valve law is piecewise
linear): in the sweep of docs/benchmarks.md it converged at every stiffness ratio and step size
in at most 3 film steps per coupling step, fewest of all schemes (Gauss–Seidel alone fails once
the valve's band makes the jack softer than the film; Aitken's relaxation converges everywhere
too, without derivatives, at 2.8–13.5 film steps per coupling step on average: ``--scheme
aitken`` for an FMU without fmi2GetDirectionalDerivative).

Writes erection_sequence.png and erection_sequence.csv (one row per coupling step) into --out.

    .venv/bin/python examples/erection_sequence.py [--steps 40] [--out DIR] [--relief 600]
        [--stiffness 1e5] [--scheme newton|aitken|iqn-ils|gauss-seidel]
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import archfmu  # noqa: E402

from membrane_contact.coupling import SCHEMES, closing, erection_system  # noqa: E402

HEIGHT = 0.3
MU = 0.2
CRACK = 0.85
WATCHED = ["G1", "G2", "G3", "G4", "G6", "G8"]
TIGHT = {"solver.displacementTolerance": 1e-10, "solver.residualTolerance": 1e-10}


def phase(force: float, piston: float, relief: float, stroke: float) -> str:
    """What the jack does under the pull ``-force`` with its piston at ``piston``."""
    if piston <= -stroke + 1e-12:
        return "end of stroke"
    if -force >= CRACK * relief:
        return "relief valve open"
    return "pumping"


def simulate(duration: float, steps: int, fmu_path=None, scheme: str = "newton", relief: float = 600.0,
             stiffness: float = 1e5, rate: float = 0.5e-3, stroke: float = 0.15):
    """Run the coupled FMUs over ``duration`` seconds in ``steps`` steps; one record per step
    (the first: the initial state). The jack FMU is packed from the repository into a temporary
    directory. Returns ``(records, report)``."""
    film_parameters = {"archHeight": HEIGHT, "mu": MU, **TIGHT}
    jack_parameters = {"stiffness": stiffness, "relief": relief, "rate": rate, "stroke": stroke}
    records = []
    with closing(erection_system(fmu_path, None, film_parameters, jack_parameters)) as system:
        film, jack = system.film, system.structure

        def record(rec=None):
            gaps = {g: {"slip": film[f"{g}.slip"], "status": film[f"{g}.status"]} for g in archfmu.GAPS}
            force, piston = jack["force"], jack["piston"]
            records.append({"time_s": film.time, "step_s": rec.step if rec else 0.0,
                            "dz_mm": film["frame.dz"] * 1e3, "piston_mm": piston * 1e3,
                            "Rz_N": film["frame.Rz"], "jack_speed_mm_s": jack["speed"] * 1e3,
                            "jack_phase": phase(force, piston, relief, stroke),
                            "coupling_iterations": rec.iterations if rec else 0,
                            "rollbacks": rec.rollbacks if rec else 0,
                            "residuals": rec.residuals if rec else [], "gaps": gaps})

        record()
        report = system.run(duration, duration / steps, scheme, on_step=record)
    if report.failure is not None:
        raise RuntimeError(f"the coupling failed: {report.summary()}")
    return records, report


def plot(records, report, relief, stroke, path):
    plt = archfmu.use_agg()
    t = [r["time_s"] for r in records]
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.2))
    (a, b), (c, d) = axes
    a.plot(t, [r["dz_mm"] for r in records], "-", color="k", label="frame (film's frame.dz)")
    a.plot(t, [r["piston_mm"] for r in records], "--", color="0.5", label="piston")
    a.axhline(-stroke * 1e3, ls=":", color="0.5", label="end of stroke")
    for name, col in [("pumping", "tab:green"), ("relief valve open", "tab:orange"), ("end of stroke", "tab:red")]:
        pts = [(r["time_s"], r["dz_mm"]) for r in records if r["jack_phase"] == name]
        if pts:
            a.plot(*zip(*pts), ".", color=col, label=name)
    a.set_ylabel("position (mm)")
    a.set_title("jack FMU: frame and piston", fontsize=10)
    a.legend(fontsize=8)

    b.plot(t, [abs(r["Rz_N"]) for r in records], ".-", color="tab:blue", label="|frame.Rz| (film FMU)")
    b.axhline(relief, ls="--", color="tab:red", label="relief setting")
    b.axhline(CRACK * relief, ls=":", color="tab:orange", label="valve cracks open")
    b.set_ylabel("force on the frame, 1/4 model (N)")
    b.set_title("film reaction = jack force", fontsize=10)
    b.legend(fontsize=8)

    for g, col in zip(WATCHED, plt.cm.tab10.colors):
        slip = [r["gaps"][g]["slip"] * 1e3 for r in records]
        c.plot(t, slip, "-", color=col, label=g)
        closed = [(ti, s) for ti, s, r in zip(t, slip, records) if r["gaps"][g]["status"] != 0]
        if closed:
            c.plot(*zip(*closed), ".", color=col, ms=4)
    c.set_xlabel("time (s)")
    c.set_ylabel("slip along the arch (mm)")
    c.set_title("slip history (dots: gap in contact, line only: open)", fontsize=10)
    c.legend(fontsize=8, ncol=2)

    d.bar(t[1:], [r["coupling_iterations"] for r in records[1:]], width=0.7 * (t[1] - t[0]), color="tab:purple")
    d.set_xlabel("time (s)")
    d.set_ylabel("coupling iterations per step")
    d.set_title(f"{report.scheme}: {report.rollbacks} rollbacks of both FMUs in all", fontsize=10)
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    fig.suptitle(f"Erection sequence: jack FMU lowering the frame of the {HEIGHT * 1e3:.0f} mm specimen "
                 f"(μ = {MU:g}), film FMU ⇄ jack FMU iterated to convergence every step", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    archfmu.save_png(fig, path)
    plt.close(fig)


def main(argv=None):
    p = archfmu.example_parser(__doc__.splitlines()[0], steps=40)
    p.add_argument("--duration", type=float, default=400.0, help="seconds (default 400)")
    p.add_argument("--rate", type=float, default=0.5, help="pump lowering rate, mm/s (0.5)")
    p.add_argument("--relief", type=float, default=600.0, help="relief force on the 1/4 frame, N (default 600)")
    p.add_argument("--stroke", type=float, default=150.0, help="jack stroke, mm (150)")
    p.add_argument("--stiffness", type=float, default=1e5, help="jack cylinder stiffness, N/m (1e5)")
    p.add_argument("--scheme", default="newton", choices=[s for s in SCHEMES if s not in ("jacobi", "staggered")],
                   help="coupling scheme (default newton)")
    a = p.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    records, report = simulate(a.duration, a.steps, a.fmu, a.scheme, a.relief, a.stiffness, a.rate * 1e-3,
                               a.stroke * 1e-3)
    header = ["time_s", "step_s", "dz_mm", "piston_mm", "Rz_N", "jack_speed_mm_s", "jack_phase",
              "coupling_iterations", "rollbacks"]
    header_gaps = [f"{g}_{q}" for g in archfmu.GAPS for q in ("slip_mm", "status")]
    rows = [[r[k] for k in header]
            + [v for g in archfmu.GAPS
               for v in (r["gaps"][g]["slip"] * 1e3, archfmu.STATUS[r["gaps"][g]["status"]])]
            for r in records]
    csv_path = archfmu.write_csv(out / "erection_sequence.csv", header + header_gaps, rows)
    png = out / "erection_sequence.png"
    plot(records, report, a.relief, a.stroke * 1e-3, png)
    last = records[-1]
    opened = next((r["time_s"] for r in records if r["jack_phase"] != "pumping"), None)
    print(report.summary())
    opened = "never" if opened is None else f"t = {opened:.1f} s"
    print(f"jack left 'pumping' at {opened}; final: dz = {last['dz_mm']:.2f} mm, "
          f"|Rz| = {abs(last['Rz_N']):.1f} N (relief {a.relief:g} N), {last['jack_phase']}")
    print("final slips (mm): " + ", ".join(
        f"{g} {last['gaps'][g]['slip'] * 1e3:.2f}{'' if last['gaps'][g]['status'] else ' (open)'}"
        for g in archfmu.GAPS))
    print(f"wrote {png} and {csv_path}")
    return records


if __name__ == "__main__":
    main()
