"""Construction stage: a hydraulic jack lowers the outside frame and stalls at its relief force.

A small co-simulation master couples two models every communication step:

* the film (the ParallelArch FMU, 300 mm arch, mu = 0.2, 1/4 model): input ``frame.dz``,
  output ``frame.Rz``, the film's reaction on the frame, with the slips and gap statuses;
* a hydraulic jack written here in Python (:class:`HydraulicJack`): a constant-flow pump
  lowers the frame at ``rate``; a pressure-relief valve starts to open at ``crack`` x
  ``relief`` and bypasses all the flow at ``relief`` (the jack stalls), and above it lets the
  jack yield back; the stroke ends at ``stroke``.

Exchange (explicit, Gauss-Seidel): the jack reads |Rz| at time t, moves the frame over
[t, t + h]; the FMU reaches that frame.dz at t + h and returns the new Rz.

Step control by the master (the FMU is asked not to cut back internally,
``solver.maxCutbacks = 0``):

* ``fmi2Discard`` (Newton did not converge): the master restores the state saved before the
  step (fmi2SetFMUstate; this FMU keeps its last converged state anyway), halves h and steps
  again from the same time;
* a step whose reaction changed by more than ``--max-force-change`` (the coupling would
  overshoot the valve's band) is rolled back with fmi2SetFMUstate and repeated with h / 2;
* after an accepted step h grows again (x 1.5, at most the nominal duration / --steps).

Writes erection_sequence.png and erection_sequence.csv (one row per accepted step) into --out.

    .venv/bin/python examples/erection_sequence.py [--steps 80] [--out DIR] [--relief 600]
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import archfmu  # noqa: E402

HEIGHT = 0.3
MU = 0.2
WATCHED = ["G1", "G2", "G3", "G4", "G6", "G8"]


@dataclass
class HydraulicJack:
    """Lowers the frame (dz < 0) at the pump's rate; the relief valve limits its force.

    Forces are those of the 1/4 model's frame group (the whole specimen carries 4 x).
    """

    rate: float = 0.5e-3        # m/s: pump flow / piston area
    relief: float = 600.0       # N: relief-valve setting, as a force on the frame
    crack: float = 0.85         # the valve starts to open at crack * relief
    back_rate: float = 0.5e-3   # m/s: fastest yielding through the open valve
    stroke: float = 0.15        # m: end of stroke (the standard target H/2)
    dz: float = 0.0             # m: frame position (negative: lowered)

    def velocity(self, force: float) -> float:
        """Lowering speed (m/s, > 0 lowering, < 0 yielding back) under the film's pull."""
        f_crack = self.crack * self.relief
        v = self.rate * (self.relief - force) / (self.relief - f_crack)
        return min(self.rate, max(-self.back_rate, v))

    def advance(self, force: float, h: float) -> float:
        """Frame position after h seconds at the force ``force`` (the stroke bounds it)."""
        return min(0.0, max(-self.stroke, self.dz - self.velocity(force) * h))

    def phase(self, force: float) -> str:
        if self.dz <= -self.stroke + 1e-12:
            return "end of stroke"
        if force >= self.crack * self.relief:
            return "relief valve open"
        return "pumping"


def simulate(jack: HydraulicJack, duration: float, steps: int, fmu_path=None,
             max_force_change: float = 40.0, increments: int = 1, max_cutbacks: int = 0,
             min_step: float = 1e-3):
    """Run the coupled models over ``duration`` seconds; one record per accepted step."""
    h_nominal = duration / steps
    params = {"archHeight": HEIGHT, "solver.incrementsPerStep": increments,
              "solver.maxCutbacks": max_cutbacks}
    records, rollbacks = [], 0
    with archfmu.ArchFMU(fmu_path, parameters=params, inputs={"mu": MU}, name="film") as fmu:

        def record(force, h):
            s = fmu.snapshot()
            records.append({"time_s": fmu.time, "dz_mm": jack.dz * 1e3, "Rz_N": s["R"][2],
                            "jack_force_N": force, "jack_speed_mm_s": jack.velocity(force) * 1e3,
                            "jack_phase": jack.phase(force), "step_s": h,
                            "newton_iterations": s["iterations"], "discards": fmu.discards,
                            "rollbacks": rollbacks, "gaps": s["gaps"]})

        force = abs(fmu.snapshot()["R"][2])
        record(force, 0.0)
        h = h_nominal
        while fmu.time < duration - 1e-9:
            h = min(h, duration - fmu.time)
            dz_new = jack.advance(force, h)
            saved = fmu.save()
            try:
                if not fmu.step(h, {"frame.dz": dz_new}):
                    # fmi2Discard: back to the state before the step (FMI 2.0; this FMU has
                    # kept it anyway), then a shorter step.
                    fmu.restore(saved)
                    if h / 2 < min_step:
                        raise RuntimeError(f"step refused at t = {fmu.time} s even with h = {h} s: "
                                           + fmu.log_tail(1))
                    h /= 2
                    continue
                new_force = abs(fmu.snapshot()["R"][2])
                if abs(new_force - force) > max_force_change and h / 2 >= min_step:
                    fmu.restore(saved)      # too big a change for an explicit exchange
                    rollbacks += 1
                    h /= 2
                    continue
            finally:
                fmu.free(saved)
            jack.dz = dz_new
            force = new_force
            record(force, h)
            h = min(1.5 * h, h_nominal)
    return records


def plot(records, jack, path):
    plt = archfmu.use_agg()
    t = [r["time_s"] for r in records]
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.2))
    (a, b), (c, d) = axes
    a.plot(t, [r["dz_mm"] for r in records], "-", color="k")
    a.axhline(-jack.stroke * 1e3, ls=":", color="0.5", label="end of stroke")
    for phase, col in [("pumping", "tab:green"), ("relief valve open", "tab:orange"),
                       ("end of stroke", "tab:red")]:
        pts = [(r["time_s"], r["dz_mm"]) for r in records if r["jack_phase"] == phase]
        if pts:
            a.plot(*zip(*pts), ".", color=col, label=phase)
    a.set_ylabel("frame dz (mm)")
    a.set_title("jack: frame position", fontsize=10)
    a.legend(fontsize=8)

    b.plot(t, [abs(r["Rz_N"]) for r in records], "-", color="tab:blue", label="|frame.Rz| (film)")
    b.axhline(jack.relief, ls="--", color="tab:red", label="relief setting")
    b.axhline(jack.crack * jack.relief, ls=":", color="tab:orange", label="valve cracks open")
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

    d.plot([-r["dz_mm"] for r in records], [abs(r["Rz_N"]) for r in records], ".-",
           color="tab:blue", label="film: |Rz| at the reached dz")
    d.axhspan(jack.crack * jack.relief, jack.relief, color="tab:orange", alpha=0.15,
              label="jack: valve opening band (speed → 0)")
    d.axhline(jack.relief, ls="--", color="tab:red", label="jack: relief force (stall)")
    d.axvline(jack.stroke * 1e3, ls=":", color="0.5", label="jack: end of stroke")
    d.set_xlabel("frame lowered −dz (mm)")
    d.set_ylabel("force (N)")
    d.set_title("where the two models meet: the stall point", fontsize=10)
    d.legend(fontsize=8)
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    fig.suptitle(f"Erection sequence: jack lowering the frame of the {HEIGHT * 1e3:.0f} mm "
                 f"specimen (μ = {MU:g}), FMU ⇄ jack every communication step", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    archfmu.save_png(fig, path)
    plt.close(fig)


def main(argv=None):
    p = archfmu.example_parser(__doc__.splitlines()[0], steps=80)
    p.add_argument("--duration", type=float, default=400.0, help="seconds (default 400)")
    p.add_argument("--rate", type=float, default=0.5, help="pump lowering rate, mm/s (0.5)")
    p.add_argument("--relief", type=float, default=600.0,
                   help="relief force on the 1/4 frame, N (default 600)")
    p.add_argument("--stroke", type=float, default=150.0, help="jack stroke, mm (150)")
    p.add_argument("--max-force-change", type=float, default=40.0,
                   help="largest change of |Rz| in one step before a rollback, N (40)")
    p.add_argument("--increments", type=int, default=1,
                   help="FMU parameter solver.incrementsPerStep (default 1)")
    p.add_argument("--max-cutbacks", type=int, default=0,
                   help="FMU parameter solver.maxCutbacks (default 0: the master halves)")
    a = p.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    jack = HydraulicJack(rate=a.rate * 1e-3, relief=a.relief, stroke=a.stroke * 1e-3)
    records = simulate(jack, a.duration, a.steps, a.fmu, a.max_force_change, a.increments,
                       a.max_cutbacks)
    header = ["time_s", "step_s", "dz_mm", "Rz_N", "jack_speed_mm_s", "jack_phase",
              "newton_iterations", "discards", "rollbacks"]
    header_gaps = [f"{g}_{q}" for g in archfmu.GAPS for q in ("slip_mm", "status")]
    rows = [[r[k] for k in header]
            + [v for g in archfmu.GAPS
               for v in (r["gaps"][g]["slip"] * 1e3, archfmu.STATUS[r["gaps"][g]["status"]])]
            for r in records]
    csv_path = archfmu.write_csv(out / "erection_sequence.csv", header + header_gaps, rows)
    png = out / "erection_sequence.png"
    plot(records, jack, png)
    last = records[-1]
    opened = next((r["time_s"] for r in records if r["jack_phase"] != "pumping"), None)
    print(f"{len(records) - 1} accepted steps, {last['rollbacks']} rollbacks, "
          f"{last['discards']} discarded steps")
    opened = "never" if opened is None else f"t = {opened:.1f} s"
    print(f"jack left 'pumping' at {opened}; final: dz = {last['dz_mm']:.2f} mm, "
          f"|Rz| = {abs(last['Rz_N']):.1f} N (relief {jack.relief:g} N), {last['jack_phase']}")
    print("final slips (mm): " + ", ".join(
        f"{g} {last['gaps'][g]['slip'] * 1e3:.2f}{'' if last['gaps'][g]['status'] else ' (open)'}"
        for g in archfmu.GAPS))
    print(f"wrote {png} and {csv_path}")
    return records


if __name__ == "__main__":
    main()
