"""Fig. 8, crown to foot: the specimens wrapped over the arch and extended, both contact models.

The crown-to-foot reconstruction of issue 10 (``specimen.rs``, ``FramePath::Wrapped``): every
frame node follows the film wound onto the arch down to its foot (first half of the path) and
then extended by the strain ``eps`` (second half), so that all nine arch nodes touch the arch at
the end. The measured boundary movements of the paper's ref. [6] are not available, so ``eps``,
the boundary extension, is the reconstruction's unknown: it is identified per specimen and per
contact model by least squares on Table 1's points 2-5 (slips are linear in ``eps``: two runs
give the line, a third run at the fitted value checks it), and reported as such.

Each run goes through an FMU: ``export-specimen --wrap EPS --path-out`` writes the model (one
boundary group per frame node) and the staged table of its 63 inputs, the model is packed with
``build_fmu`` and the table stepped with :class:`membrane_contact.Film`. Gaps report the paper's
local-x displacement from the start; curved supports the arc length slid along the arch while in
contact (what the experiment's marks measured).

Writes fig8_wrapped.png and fig8_wrapped.csv into --out and prints the fits. ``--heights``
runs some of the three specimens only (the test suite runs one, on few steps).

    .venv/bin/python examples/fig8_wrapped.py [--steps 40] [--heights 200 300 400] [--out DIR]
"""

from __future__ import annotations

import csv
import json
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import archfmu  # noqa: E402

HEIGHTS_MM = [200, 300, 400]
MODELS = ["gaps", "curved-support"]
MU = 0.2
FIT_POINTS = [2, 3, 4, 5]
PROBES = (0.01, 0.03)


def export(height_mm, contact, eps, steps, work, plastic=False):
    """Model dict and staged table (dict of columns) of a wrapped specimen (files in work);
    ``plastic``: ETFE's elasto-plastic film (``--plastic``) instead of the linear one."""
    film = "_plastic" if plastic else ""
    table = Path(work) / f"wrap_{height_mm}_{contact}{film}_{eps:.6f}.csv"
    text = subprocess.run([str(archfmu.CLI), "export-specimen", "--height", str(height_mm),
                           "--contact", contact, "--wrap", repr(eps), "--path-out", str(table),
                           "--steps", str(steps)] + (["--plastic"] if plastic else []),
                          check=True, capture_output=True, text=True).stdout
    with open(table) as f:
        rows = list(csv.DictReader(f))
    columns = {k: [float(r[k]) for r in rows] for k in rows[0]}
    return json.loads(text), columns


class Specimen:
    """One packed FMU per specimen and contact model; any eps is a table for it."""

    def __init__(self, height_mm, contact, steps, work, plastic=False, mu=MU):
        from membrane_contact import build_fmu

        self.height_mm, self.contact, self.steps, self.work = height_mm, contact, steps, work
        self.plastic, self.mu = plastic, mu
        # Every output's value at the end of the last run of slips() (stress, statuses, ...).
        self.final = {}
        model, _ = export(height_mm, contact, PROBES[-1], steps, work, plastic)
        model["name"] = (f"ParallelArchWrapped{height_mm}{'Curved' if contact != 'gaps' else 'Gaps'}"
                         + ("Plastic" if plastic else ""))
        self.model = model
        self.fmu = build_fmu(model, out_dir=Path(work) / "wrapped-fmu")

    def slips(self, eps):
        """({point: (slip mm, status)}, eps reached) at the end of the wrapped path extended by
        eps, or where the FMU stopped when a step stays refused (the state it keeps)."""
        from membrane_contact import Film, StepRefused

        _, table = export(self.height_mm, self.contact, eps, self.steps, self.work, self.plastic)
        with Film(self.fmu, logging=False) as film:
            film.initialize(inputs={"mu": self.mu})
            try:
                film.run(table, outputs=[])
                reached = eps
            except StepRefused as e:
                # The second half of the path extends the boundary: eps grows linearly with t.
                reached = eps * min(max(2.0 * e.time - 1.0, 0.0), 1.0)
                print(f"  {self.height_mm} mm {self.contact}: stalled at t = {e.time:.4f} "
                      f"(eps {100 * reached:.2f} % of {100 * eps:.2f} %)")
            result = {}
            for p, g in archfmu.OBSERVED.items():
                if self.contact == "gaps":
                    name = g
                else:
                    node = self.model["curved_supports"][0]["nodes"][int(g[1:]) - 1]
                    name = f"arch.node{node}"
                result[p] = (film[f"{name}.slip"] * 1e3, archfmu.STATUS[int(film[f"{name}.status"])])
            self.final = film.values()
            return result, reached


def fit(specimen, measured):
    """Least-squares eps on FIT_POINTS from two probe runs (slip = a + b eps), clamped to
    [0, 0.1], and the run at it: (eps, slips, rms misfit mm, eps reached)."""
    (lo, _), (hi, _) = (specimen.slips(e) for e in PROBES)
    b = {p: (hi[p][0] - lo[p][0]) / (PROBES[1] - PROBES[0]) for p in FIT_POINTS}
    a = {p: lo[p][0] - b[p] * PROBES[0] for p in FIT_POINTS}
    eps = sum(b[p] * (measured[p] - a[p]) for p in FIT_POINTS) / sum(b[p] ** 2 for p in FIT_POINTS)
    eps = min(max(eps, 0.0), 0.1)
    at, reached = specimen.slips(eps)
    rms = (sum((at[p][0] - measured[p]) ** 2 for p in FIT_POINTS) / len(FIT_POINTS)) ** 0.5
    return eps, at, rms, reached


def plot(results, table1, steps, path):
    plt = archfmu.use_agg()
    heights = list(results)
    # At least as wide as the title's first line.
    fig, axes = plt.subplots(1, len(heights), figsize=(max(4.4 * len(heights), 7.5), 4.6), sharey=True,
                             squeeze=False)
    axes = axes[0]
    style = {"gaps": ("-", "o", "tab:blue", "gaps (paper), local x"),
             "curved-support": ("-.", "^", "tab:green", "curved support, slid along the arch")}
    for ax, h in zip(axes, heights):
        ax.plot(FIT_POINTS, [table1[h][p] for p in FIT_POINTS], "s--", color="tab:red",
                label="experiment (Table 1)")
        for contact in MODELS:
            eps, at, rms, reached = results[h][contact]
            line, marker, color, label = style[contact]
            stalled = "" if reached == eps else f" (stalls at {100 * reached:.2f} %)"
            ax.plot(FIT_POINTS, [at[p][0] for p in FIT_POINTS], line, marker=marker, color=color,
                    label=f"{label}: ε = {100 * eps:.2f} %{stalled}, RMS {rms:.1f} mm")
        ax.set_xticks(FIT_POINTS, [f"{p}\n({archfmu.OBSERVED[p]})" for p in FIT_POINTS])
        ax.set_title(f"{h} mm arch (all nine nodes touch)", fontsize=10)
        ax.set_xlabel("observed point (arch node)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[0].set_ylabel("slip (mm)")
    fig.suptitle(f"Fig. 8, crown to foot: film wound onto the arch, then the boundary extended by ε\n"
                 f"(ε fitted per model; μ = {MU:g}, {steps} steps, specimen.rs)", fontsize=9)
    fig.tight_layout()
    archfmu.save_png(fig, path)
    plt.close(fig)


def parser(description):
    """The example options (40 steps by default) and --heights."""
    p = archfmu.example_parser(description, steps=40)
    p.add_argument("--heights", type=int, nargs="+", default=HEIGHTS_MM, choices=HEIGHTS_MM,
                   help="arch heights (mm) of the specimens to fit (default: all three)")
    return p


def main(argv=None):
    a = parser(__doc__.splitlines()[0]).parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    table1 = archfmu.read_table1()
    # Models, tables and FMUs of the runs are intermediate: kept out of --out (docs/figures).
    with tempfile.TemporaryDirectory(prefix="fig8-wrapped-") as work:
        results = {h: {c: fit(Specimen(h, c, a.steps, work), table1[h]) for c in MODELS}
                   for h in a.heights}
    header = ["arch_height_mm", "contact", "eps", "eps_reached", "rms_mm", "point", "slip_mm", "status",
              "experiment_mm"]
    rows = [[h, c, eps, reached, rms, p, at[p][0], at[p][1], table1[h][p]]
            for h in a.heights for c, (eps, at, rms, reached) in results[h].items() for p in archfmu.OBSERVED]
    csv_path = archfmu.write_csv(out / "fig8_wrapped.csv", header, rows)
    png = out / "fig8_wrapped.png"
    plot(results, table1, a.steps, png)
    print("wrapped specimens: boundary extension eps fitted on points 2-5 (slips mm, points 1-5)")
    for h in a.heights:
        print(f"{h} mm  Table 1: " + " ".join(f"{table1[h][p]:6.1f}" for p in archfmu.OBSERVED))
        for c, (eps, at, rms, reached) in results[h].items():
            touching = sum(s != "open" for _, s in at.values())
            stalled = "" if reached == eps else f" (stalls at {100 * reached:.2f} %)"
            print(f"  {c:<15} eps = {100 * eps:5.2f} %{stalled}  RMS {rms:5.2f} mm  "
                  + " ".join(f"{at[p][0]:6.2f}" for p in archfmu.OBSERVED) + f"  ({touching}/5 touching)")
    print(f"wrote {png} and {csv_path}")
    return results


if __name__ == "__main__":
    main()
