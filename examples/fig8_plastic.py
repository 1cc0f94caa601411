"""Fig. 8 with ETFE's elasto-plastic film beside the linear one: the crown-to-foot specimens
refitted, the frame released, and the lowered-frame runs (issue 20 item 4).

1. **Crown to foot, refitted.** For each arch height and each film (the linear tension-field
   film of ``fig8_wrapped.py`` and the same film with ``--plastic``: finite-strain J2 with the
   data-sheet curve, docs/mechanics.md), the boundary extension ``eps`` is identified by exactly
   the procedure of ``fig8_wrapped.py`` (its :func:`fit`: two FMU runs at ``eps`` = 1 % and 3 %
   give the line ``slip = a + b eps`` on Table 1's points 2-5, a third run at the least-squares
   ``eps`` gives the slips and the RMS misfit). Curved supports only: the fixed-frame gaps cannot
   be fitted on this path at any ``eps`` (``fig8_wrapped.py``).
2. **Released.** At the fitted ``eps`` the same path is run with the CLI (``model --path``, the
   same core) and then retraced, the extension first and then the winding, back to the flat
   start, as far as the run converges: a plastic film that has flowed is longer than the frame
   that is released, goes slack and leaves the arch, and a slack film has no equilibrium to
   converge to (the run stops there, which the figure says). The residual (plastic) strain is
   what an installer measures: the equivalent plastic strain of every element at the last
   converged released state, drawn on the flat film, and averaged over the elements around
   each observed point. Elastic unloading leaves it where the loading took it.
3. **Lowered frame.** ``specimen --target-dz-per-height`` -0.5 and -1, both contact models,
   both films, 40 steps: slips at points 1-5 and the von Mises range.

Writes fig8_plastic.png, fig8_plastic.csv (fits), fig8_plastic_residual.csv (per element) and
fig8_plastic_lowered.csv into --out, and prints the tables of docs/mechanics.md.

    .venv/bin/python examples/fig8_plastic.py [--steps 40] [--heights 200 300 400] [--out DIR]
"""

from __future__ import annotations

import csv
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import archfmu  # noqa: E402
import fig8_wrapped  # noqa: E402

HEIGHTS_MM = fig8_wrapped.HEIGHTS_MM
FILMS = {"linear": False, "plastic": True}
CONTACT = "curved-support"
LOWERED = [(-0.5, "gaps"), (-0.5, "curved-support"), (-1.0, "gaps"), (-1.0, "curved-support")]


def cli(args, cwd):
    """(stdout, stderr, exit status) of the core's CLI."""
    r = subprocess.run([str(archfmu.CLI)] + [str(a) for a in args], capture_output=True, text=True,
                       cwd=cwd)
    return r.stdout, r.stderr, r.returncode


def observed(stdout):
    """{point: slip mm} of the CLI's observed-points table (its last one)."""
    points = {}
    for m in re.finditer(r"^(\d)\s+G\d\s+(-?[\d.]+)\s", stdout, re.M):
        points[int(m.group(1))] = float(m.group(2))
    return points


def read_elements(path):
    """{step: [row dict]} of an elements CSV."""
    steps = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            steps.setdefault(int(row["step"]), []).append(row)
    return steps


def released(height_mm, plastic, eps, steps, work):
    """The wrapped path at ``eps``, then retraced to the flat start as far as it converges.

    Returns a dict: von Mises range (MPa) at the end of loading; at the last converged released
    state the time reached on the path (1 = fully extended, 0 = flat start), the elements (ε̄p,
    principal strains, von Mises), the slips of the arch nodes, and the stop message."""
    tag = f"{height_mm}_{'plastic' if plastic else 'linear'}"
    model_path, table = Path(work) / f"{tag}.json", Path(work) / f"{tag}.csv"
    text, _, _ = cli(["export-specimen", "--height", height_mm, "--contact", CONTACT, "--wrap", repr(eps),
                      "--path-out", table, "--steps", steps] + (["--plastic"] if plastic else []), work)
    model_path.write_text(text)
    model = json.loads(text)
    with open(table) as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    n = len(body)
    # Retraced: the rows in reverse, then the flat start; the path time runs back from 1 to 0.
    back = [body[n - 1 - k][1:] if k < n else ["0"] * (len(header) - 1) for k in range(1, n + 1)]
    with open(table, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(header)
        w.writerows(body)
        w.writerows([[repr(1.0 + k / n)] + r for k, r in enumerate(back, start=1)])
    elements = Path(work) / f"{tag}_elements.csv"
    stdout, stderr, status = cli(["model", model_path, "--path", table, "--elements-csv", elements], work)
    by_step = read_elements(elements)
    last = max(by_step)
    stop = "" if status == 0 else stderr.strip().splitlines()[-1].split(": step did not")[0]
    slips = {}
    for m in re.finditer(r"^arch\.node(\d+)\s+(-?[\d.]+)\s", stdout, re.M):
        slips[int(m.group(1))] = float(m.group(2))
    loaded = by_step[n]
    return {
        "model": model,
        "loaded_mpa": (min(float(r["von_mises_Pa"]) for r in loaded) / 1e6,
                       max(float(r["von_mises_Pa"]) for r in loaded) / 1e6),
        "time": 1.0 - (last - n) / n if last > n else 1.0,
        "released_mpa": max(float(r["von_mises_Pa"]) for r in by_step[last]) / 1e6,
        "states": {state: sum(r["state"] == state for r in by_step[last]) for state in ("Taut", "Wrinkled", "Slack")},
        "elements": by_step[last],
        "slips": slips,
        "stop": stop,
    }


def point_plastic_strain(model, elements, node):
    """Mean equivalent plastic strain of the elements around ``node`` (0 for the linear film)."""
    around = [r for r in elements if node in (int(r["node1"]), int(r["node2"]), int(r["node3"]))]
    return sum(float(r.get("equivalent_plastic_strain", 0.0)) for r in around) / len(around)


def lowered(height_mm, per_height, contact, plastic, steps, work):
    """(slips at points 1-5 or None, von Mises range MPa, failure text) of a lowered-frame run."""
    stdout, stderr, status = cli(["specimen", "--height", height_mm, "--contact", contact,
                                  "--target-dz-per-height", per_height, "--steps", steps]
                                 + (["--plastic"] if plastic else []), work)
    m = re.search(r"von Mises\) stress: ([\d.]+) … ([\d.]+) MPa", stdout)
    failure = "" if status == 0 else stderr.strip().splitlines()[-1].split(" after ")[0]
    return observed(stdout), (float(m.group(1)), float(m.group(2))), failure


def plot(fits, releases, table1, steps, path):
    plt = archfmu.use_agg()
    heights = list(fits)
    fig, axes = plt.subplots(2, len(heights), figsize=(max(4.6 * len(heights), 7.5), 8.4), squeeze=False)
    points = fig8_wrapped.FIT_POINTS
    style = {"linear": ("-.", "^", "tab:green"), "plastic": ("-", "o", "tab:purple")}
    for ax, h in zip(axes[0], heights):
        ax.plot(points, [table1[h][p] for p in points], "s--", color="tab:red", label="experiment (Table 1)")
        for film, (eps, at, rms, reached) in fits[h].items():
            line, marker, color = style[film]
            lo, hi = releases[h][film]["loaded_mpa"]
            ax.plot(points, [at[p][0] for p in points], line, marker=marker, color=color,
                    label=f"{film} film: ε = {100 * eps:.2f} %, RMS {rms:.1f} mm, σvM {lo:.0f}–{hi:.0f} MPa")
        ax.set_xticks(points, [f"{p}\n({archfmu.OBSERVED[p]})" for p in points])
        ax.set_title(f"{h} mm arch, crown to foot, ε refitted per film", fontsize=9)
        ax.set_ylabel("slip along the arch (mm)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
    top = max(100 * float(e["equivalent_plastic_strain"]) for h in heights for e in releases[h]["plastic"]["elements"])
    for ax, h in zip(axes[1], heights):
        r = releases[h]["plastic"]
        nodes = r["model"]["nodes"]
        tris = [[int(e["node1"]), int(e["node2"]), int(e["node3"])] for e in r["elements"]]
        ep = [100 * float(e["equivalent_plastic_strain"]) for e in r["elements"]]
        tpc = ax.tripcolor([p[0] for p in nodes], [p[1] for p in nodes], tris, facecolors=ep, cmap="viridis",
                           vmin=0.0, vmax=max(top, 1e-3))
        fig.colorbar(tpc, ax=ax, label="residual ε̄p, plastic film (%)")
        arch = r["model"]["curved_supports"][0]["nodes"]
        ax.plot([nodes[v][0] for v in arch], [nodes[v][1] for v in arch], "w.", ms=4)
        ax.set_aspect("equal")
        ax.set_xlabel("X of the flat film (m)")
        ax.set_ylabel("Y (m)")
        reached = "flat start" if r["time"] == 0.0 else f"path time {r['time']:.2f}, then slack"
        ax.set_title(f"{h} mm: frame released to {reached}\n(path time 1: extended, 0.5: wound, 0: flat)",
                     fontsize=8)
    fig.suptitle(f"Fig. 8 with ETFE's elasto-plastic film: crown to foot (μ = {fig8_wrapped.MU:g}, "
                 f"{steps} steps), then the frame released (arch nodes: white)", fontsize=9)
    fig.tight_layout()
    archfmu.save_png(fig, path)
    plt.close(fig)


def main(argv=None):
    p = fig8_wrapped.parser(__doc__.splitlines()[0])
    p.add_argument("--no-lowered", action="store_true", help="skip the lowered-frame runs")
    a = p.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    table1 = archfmu.read_table1()
    fits, releases, lowered_runs = {}, {}, []
    with tempfile.TemporaryDirectory(prefix="fig8-plastic-") as work:
        for h in a.heights:
            fits[h] = {film: fig8_wrapped.fit(fig8_wrapped.Specimen(h, CONTACT, a.steps, work, plastic), table1[h])
                       for film, plastic in FILMS.items()}
            releases[h] = {film: released(h, plastic, fits[h][film][0], a.steps, work)
                           for film, plastic in FILMS.items()}
        if not a.no_lowered:
            for h in a.heights:
                for per_height, contact in LOWERED:
                    for film, plastic in FILMS.items():
                        slips, mpa, failure = lowered(h, per_height, contact, plastic, a.steps, work)
                        lowered_runs.append((h, per_height, contact, film, slips, mpa, failure))
    fit_rows = []
    for h in a.heights:
        for film, (eps, at, rms, reached) in fits[h].items():
            r = releases[h][film]
            arch = r["model"]["curved_supports"][0]["nodes"]
            for pt, g in archfmu.OBSERVED.items():
                node = arch[int(g[1:]) - 1]
                fit_rows.append([h, film, eps, reached, rms, r["loaded_mpa"][0], r["loaded_mpa"][1], pt, at[pt][0],
                                 table1[h][pt], r["time"], r["slips"].get(node, float("nan")),
                                 point_plastic_strain(r["model"], r["elements"], node)])
    csv_path = archfmu.write_csv(
        out / "fig8_plastic.csv",
        ["arch_height_mm", "film", "eps", "eps_reached", "rms_mm", "von_mises_min_MPa", "von_mises_max_MPa",
         "point", "slip_mm", "experiment_mm", "released_to_time", "slip_released_mm",
         "residual_plastic_strain"], fit_rows)
    residual_rows = [[h, int(e["element"]), int(e["node1"]), int(e["node2"]), int(e["node3"]), releases[h]["plastic"]["time"],
                      float(e["equivalent_plastic_strain"]), float(e["thickness_m"]), float(e["principal_strain_1"]),
                      float(e["principal_strain_2"]), float(e["von_mises_Pa"])]
                     for h in a.heights for e in releases[h]["plastic"]["elements"]]
    residual_path = archfmu.write_csv(
        out / "fig8_plastic_residual.csv",
        ["arch_height_mm", "element", "node1", "node2", "node3", "released_to_time", "equivalent_plastic_strain",
         "thickness_m", "principal_strain_1", "principal_strain_2", "von_mises_Pa"], residual_rows)
    png = out / "fig8_plastic.png"
    plot(fits, releases, table1, a.steps, png)
    print("crown to foot, eps refitted per film (curved supports; slips mm at points 1-5)")
    for h in a.heights:
        print(f"{h} mm  Table 1: " + " ".join(f"{table1[h][p]:6.1f}" for p in archfmu.OBSERVED))
        for film, (eps, at, rms, reached) in fits[h].items():
            r = releases[h][film]
            stalled = "" if reached == eps else f" (stalls at {100 * reached:.2f} %)"
            ep = [e.get("equivalent_plastic_strain") for e in r["elements"]]
            ep = max(float(x) for x in ep) if ep[0] is not None else 0.0
            print(f"  {film:<8} eps = {100 * eps:5.2f} %{stalled}  RMS {rms:5.2f} mm  "
                  + " ".join(f"{at[p][0]:6.2f}" for p in archfmu.OBSERVED)
                  + f"  von Mises {r['loaded_mpa'][0]:.1f}-{r['loaded_mpa'][1]:.1f} MPa;"
                  f" released to t = {r['time']:.3f} (von Mises <= {r['released_mpa']:.2f} MPa, {r['states']}),"
                  f" residual eps_p <= {ep:.4f}"
                  + (f" (stopped: {r['stop']})" if r["stop"] else ""))
    if lowered_runs:
        rows = [[h, ph, c, film] + [slips.get(p, float("nan")) for p in archfmu.OBSERVED] + [mpa[0], mpa[1], failure]
                for h, ph, c, film, slips, mpa, failure in lowered_runs]
        archfmu.write_csv(out / "fig8_plastic_lowered.csv",
                          ["arch_height_mm", "target_dz_per_height", "contact", "film", "p1_mm", "p2_mm", "p3_mm",
                           "p4_mm", "p5_mm", "von_mises_min_MPa", "von_mises_max_MPa", "failure"], rows)
        print("lowered frame (40 steps; slips mm at points 1-5, von Mises MPa)")
        for r in rows:
            print("  " + " ".join(str(archfmu.fmt(x)) for x in r))
    print(f"wrote {png}, {csv_path}, {residual_path}")
    return fits, releases, lowered_runs


if __name__ == "__main__":
    main()
