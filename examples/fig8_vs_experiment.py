"""Paper Fig. 8: analysis (mu = 0.2) against the measured slips of Table 1, three specimens.

For each arch height (200, 300, 400 mm) one FMU instance lowers the frame to dz = -H/2 in
--steps communication steps; the slips at the observed points 2-5 (gaps G2, G4, G6, G8,
paper §4.4) are plotted beside Table 1: experiment dashed, analysis solid, one panel per
specimen. A gap whose status is *open* at the end is not in contact: its "slip" is the film's
movement relative to the arch point below it, not sliding on the arch; it is drawn hollow.

The same specimens with the nine arch nodes in node-to-surface contact with the arch pipe
(``export-specimen --contact curved-support``, packed as an FMU of its own; issue 10) are drawn
beside them (dash-dot): their slip is the arc length slid along the arch while in contact (the
approach of a node that lands late is not sliding; an open node has slid 0), where the gaps give
the displacement along the arch's starting tangent since the start.

Writes fig8_vs_experiment.png and fig8_vs_experiment.csv into --out and prints the table of
differences (analysis - experiment, mm) for points 1-5.

    .venv/bin/python examples/fig8_vs_experiment.py [--steps 20] [--out DIR] [--fmu PATH]
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import archfmu  # noqa: E402

HEIGHTS_MM = [200, 300, 400]
MU = 0.2
PLOTTED_POINTS = [2, 3, 4, 5]


def rows_of(final, table1, curved):
    """One row per specimen and observed point 1..5."""
    rows = []
    for h, snap in final.items():
        for p, g in archfmu.OBSERVED.items():
            r = snap["gaps"][g]
            a, e = r["slip"] * 1e3, table1[h][p]
            c_slip, c_status = curved[h][g]
            rows.append({"specimen": f"{h}_Spec", "arch_height_mm": h, "point": p, "gap": g,
                         "analysis_mm": a, "experiment_mm": e, "difference_mm": a - e,
                         "status": archfmu.STATUS[r["status"]],
                         "curved_support_mm": c_slip * 1e3, "curved_support_difference_mm": c_slip * 1e3 - e,
                         "curved_support_status": archfmu.STATUS[c_status]})
    return rows


def curved_support_run(height_mm, steps, out):
    """The specimen with curved-support contact, exported by the CLI, packed and stepped through
    its own FMU: {G<k>: (slip along the arch (m), status)} at dz = -H/2."""
    import json
    import subprocess

    from membrane_contact import Film, build_fmu

    text = subprocess.run([str(archfmu.CLI), "export-specimen", "--height", str(height_mm),
                           "--contact", "curved-support"], check=True, capture_output=True, text=True).stdout
    model = json.loads(text)
    model["name"] = f"ParallelArchCurved{height_mm}"
    fmu = build_fmu(model, out_dir=Path(out) / "curved-fmu")
    nodes = model["curved_supports"][0]["nodes"]
    times = [k / steps for k in range(1, steps + 1)]
    with Film(fmu, logging=False) as film:
        film.initialize(inputs={"mu": MU})
        film.run({"time": times, "frame.dz": [-0.5 * height_mm / 1e3 * t for t in times]}, outputs=[])
        return {f"G{k + 1}": (film[f"arch.node{v}.slip"], int(film[f"arch.node{v}.status"]))
                for k, v in enumerate(nodes)}


def plot(rows, steps, path):
    plt = archfmu.use_agg()
    heights = sorted({r["arch_height_mm"] for r in rows})
    fig, axes = plt.subplots(1, len(heights), figsize=(4.2 * len(heights), 4.4), sharey=True)
    axes = list(axes) if len(heights) > 1 else [axes]
    for ax, h in zip(axes, heights):
        rs = [r for r in rows if r["arch_height_mm"] == h and r["point"] in PLOTTED_POINTS]
        pts = [r["point"] for r in rs]
        ax.plot(pts, [r["experiment_mm"] for r in rs], "s--", color="tab:red",
                label="experiment (Table 1)")
        ax.plot(pts, [r["analysis_mm"] for r in rs], "-", color="tab:blue",
                label=f"analysis, gaps (paper), μ = {MU:g}")
        ax.plot(pts, [r["curved_support_mm"] for r in rs], "-.", color="tab:green", marker="^",
                label="analysis, curved support (slid along the arch in contact)")
        for r in rs:
            is_open = r["status"] == "open"
            ax.plot(r["point"], r["analysis_mm"], "o", color="tab:blue",
                    mfc="white" if is_open else "tab:blue")
            if is_open:
                ax.annotate("open", (r["point"], r["analysis_mm"]), textcoords="offset points",
                            xytext=(-8, 7), fontsize=7, color="tab:blue")
        ax.set_xticks(pts, [f"{r['point']}\n({r['gap']})" for r in rs])
        ax.set_title(f"{h} mm arch", fontsize=10)
        ax.margins(y=0.12)
        ax.set_xlabel("observed point (gap element)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("slip along the arch (mm)")
    axes[0].plot([], [], "o", color="tab:blue", mfc="white",
                 label="gap open at the end: film movement\nabove the arch, not sliding on it")
    axes[0].legend(fontsize=7, loc="upper left")
    fig.suptitle(f"Fig. 8: slip at the final step, frame lowered to dz = −H/2 in {steps} steps "
                 "(assumed dimensions, src/specimens/parallel_arch.rs)", fontsize=9)
    fig.tight_layout()
    archfmu.save_png(fig, path)
    plt.close(fig)


def print_table(rows):
    print("slip along the arch at the observed points (mm); difference = analysis - experiment")
    print(f"{'specimen':<10}{'point':>6}{'gap':>5}{'analysis':>10}{'Table 1':>9}"
          f"{'diff':>8}  status   {'curved':>8}{'diff':>8}  status")
    for r in rows:
        print(f"{r['specimen']:<10}{r['point']:>6}{r['gap']:>5}{r['analysis_mm']:>10.2f}"
              f"{r['experiment_mm']:>9.1f}{r['difference_mm']:>8.2f}  {r['status']:<7}"
              f"{r['curved_support_mm']:>9.2f}{r['curved_support_difference_mm']:>8.2f}  {r['curved_support_status']}")


def main(argv=None):
    p = archfmu.example_parser(__doc__.splitlines()[0], steps=20)
    p.add_argument("--backend", choices=["fmu", "cli"], default="fmu",
                   help="fmu (default) or cli: the same core without FMI, as a cross-check")
    a = p.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    table1 = archfmu.read_table1()
    final = {h: archfmu.ramp(h / 1e3, MU, a.steps, backend=a.backend, fmu_path=a.fmu)[-1]
             for h in HEIGHTS_MM}
    # The curved specimens' models and FMUs are intermediate: kept out of --out (docs/figures).
    with tempfile.TemporaryDirectory(prefix="fig8-curved-") as work:
        curved = {h: curved_support_run(h, a.steps, work) for h in HEIGHTS_MM}
    rows = rows_of(final, table1, curved)
    header = list(rows[0])
    csv_path = archfmu.write_csv(out / "fig8_vs_experiment.csv", header,
                                 [[r[k] for k in header] for r in rows])
    png = out / "fig8_vs_experiment.png"
    plot(rows, a.steps, png)
    print_table(rows)
    print(f"wrote {png} and {csv_path}")
    return rows


if __name__ == "__main__":
    main()
