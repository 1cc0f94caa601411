"""Figure of issue 46: the strips, the prestress map after erection, and the iterations of the
friction-aware compensation.

Top left: the prestress error per erection over the drum of ``examples/drum.json`` (a film wrapped
+-60 deg over a 0.5 m drum between two rails), cut in one piece: frictionless from the
uncompensated cut (one correction brings it to 0.375 %), and with mu = 0.3 from the prestress
compensation (friction holds the crown: the corrections do not bring it down). Top middle: the
same for the vault bay of ``examples/vault_bay.py`` (mu = 0.3), eight strips, the prestress
compensation corrected per strip and per element, on the three erection paths (the last the
issue's, settled: the rails pass their places by 1 mm and come back in 12 shrinking waypoints).
Top right: the vault bay's eight strips as cut (flat, compensated; the cut of the settled run).
Bottom: the vault bay's prestress map after erection (rails down 0.10 m and out 0.03 m), plan
view, the mean normal stress (sx + sy)/2 of each triangle: left the prestress compensation on the
issue's path alone, which ignores friction (every contact node off the crown slides: the stress
falls from the rails to the crown); middle the same cut on the settled path (every contact node
sticks, every triangle within 1.5 MPa +- 5 %); triangles outside 1.5 MPa +- 5 % away from the rails
outlined; right both against x. Writes ``docs/figures/design_iterations.csv`` (the iterations) and ``.png``.
Run: PYTHONPATH=python python examples/design_iterations.py (about 35 s)."""

import csv
import json
from pathlib import Path

from membrane_contact.design import pattern

ROOT = Path(__file__).resolve().parents[1]
TARGET, TOLERANCE = 1.5e6, 0.05


def drum_rows():
    """(case, erection, mean error, largest error) of the drum, element by element."""
    drum = json.loads((ROOT / "examples" / "drum.json").read_text())
    rows = []
    frictionless = json.loads(json.dumps(drum))
    frictionless["curved_supports"][0]["friction"] = 0.0
    for case, model, compensation in (("drum, mu = 0, uncompensated start", frictionless, 0),
                                      ("drum, mu = 0.3, prestress compensation", drum, "prestress")):
        report = pattern(model, compensation=compensation, erect=4, by_element=True, erect_tolerance=0.5)
        rows += [(case, k, e["mean_error"], e["max_error"]) for k, e in enumerate(report["erections"])]
    return rows


VAULT_RUNS = ["vault, rails drawn, per strip", "vault, rails drawn, per element",
              "vault, rails down and out, per strip", "vault, rails down and out, per element",
              "vault, rails down and out, settled, per strip", "vault, rails down and out, settled, per element"]


def vault_runs():
    """The vault bay's found model and its six runs' reports (``examples/vault_bay.py``)."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("vault_bay", ROOT / "examples" / "vault_bay.py")
    bay = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bay)
    return bay.main()


def vault_rows(reports):
    """(case, erection, mean error, largest error) of the vault bay's six runs."""
    return [(name, k, e["mean_error"], e["max_error"])
            for name, report in zip(VAULT_RUNS, reports) for k, e in enumerate(report["erections"])]


def errors_and_means(found, erection):
    """Per triangle: the error max(|sx - s*|, |sy - s*|)/s*, the mean normal stress (MPa) and
    whether it lies away from the rails (no node in a boundary group)."""
    rails = {v for g in found["groups"] for v in g["nodes"]}
    away = [not any(v in rails for v in t) for t in found["triangles"]]
    errors = [max(abs(s[0] - TARGET), abs(s[1] - TARGET)) / TARGET for s in erection["stress"]]
    means = [0.5 * (s[0] + s[1]) / 1e6 for s in erection["stress"]]
    return errors, means, away


def plot_iterations(ax, rows, prefix):
    for case in dict.fromkeys(r[0] for r in rows if r[0].startswith(prefix)):
        pts = [(r[1], 100 * r[3]) for r in rows if r[0] == case]
        ax.plot(*zip(*pts), marker="o", label=case)
    ax.set_yscale("log")
    ax.set_xlabel("erection")
    ax.set_ylabel("largest prestress error (%)")
    ax.set_title(f"{prefix}: per element away from the rails, per strip every triangle", fontsize=8)
    ax.axhline(100 * TOLERANCE, color="grey", lw=0.8, ls="--")
    ax.legend(fontsize=7)


def plot_strips(ax, strips):
    """The cut strips stacked, each outline as cut (m)."""
    top = 0.0
    for k, strip in enumerate(strips):
        ys = [p[1] for seg in strip["outline"] for p in seg]
        dy = top - max(ys)
        for (x0, y0), (x1, y1) in strip["outline"]:
            ax.plot([x0, x1], [y0 + dy, y1 + dy], color="black", lw=0.6)
        ax.text(min(p[0] for seg in strip["outline"] for p in seg), top + 0.02,
                f"strip {k}: {strip['size'][0]:.4f} x {strip['size'][1]:.4f} m", fontsize=6)
        top -= max(ys) - min(ys) + 0.15
    ax.set_aspect("equal")
    ax.set_xlabel("m")
    ax.set_title("vault bay: the eight strips as cut (prestress compensation)", fontsize=8)


def plot_map(ax, found, erection, title, norm):
    import matplotlib.tri as mtri
    errors, means, away = errors_and_means(found, erection)
    x = [p[0] for p in found["nodes"]]
    y = [p[1] for p in found["nodes"]]
    tri = mtri.Triangulation(x, y, found["triangles"])
    image = ax.tripcolor(tri, facecolors=means, cmap="coolwarm", norm=norm)
    outside = [t for t, (e, a) in enumerate(zip(errors, away)) if a and e > TOLERANCE]
    for t in outside:
        corners = found["triangles"][t] + found["triangles"][t][:1]
        ax.plot([x[v] for v in corners], [y[v] for v in corners], color="black", lw=0.4)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"{title}\n{len(outside)} of {sum(away)} triangles away from the rails outside "
                 "1.5 MPa +- 5 % (outlined)", fontsize=8)
    return image


def plot_profile(ax, found, erections):
    """(sx + sy)/2 of each triangle away from the rails against its centroid's x."""
    for k, label, marker in erections:
        _, means, away = errors_and_means(found, k)
        xs = [sum(found["nodes"][v][0] for v in t) / 3 for t in found["triangles"]]
        pts = [(x, m) for x, m, a in zip(xs, means, away) if a]
        ax.plot(*zip(*pts), marker, ms=3, ls="none", label=label)
    for edge in (1 - TOLERANCE, 1 + TOLERANCE):
        ax.axhline(TARGET / 1e6 * edge, color="grey", lw=0.8, ls="--")
    ax.set_xlabel("x of the triangle's centroid (m)")
    ax.set_ylabel("(sx + sy)/2 after erection (MPa)")
    ax.set_title("vault bay, rails down and out, mu = 0.3: the path alone lets the stress fall from\n"
                 "the rails to the crown (nodes slide at mu N); settled, the nodes stick at an even stress", fontsize=8)
    ax.legend(fontsize=7)


def main(out=ROOT / "docs" / "figures" / "design_iterations"):
    found, reports = vault_runs()
    rows = drum_rows() + vault_rows(reports)
    with open(f"{out}.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "erection", "mean_error", "max_error"])
        w.writerows(rows)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import TwoSlopeNorm
    issue, settled = reports[3]["erections"][0], reports[5]["erections"][0]
    fig, axes = plt.subplots(2, 3, figsize=(16, 8.5), layout="constrained")
    plot_iterations(axes[0, 0], rows, "drum")
    plot_iterations(axes[0, 1], rows, "vault")
    plot_strips(axes[0, 2], reports[5]["strips"])
    norm = TwoSlopeNorm(vcenter=TARGET / 1e6, vmin=1.1, vmax=1.9)
    plot_map(axes[1, 0], found, issue, "prestress compensation, the issue's path alone (ignores friction)", norm)
    image = plot_map(axes[1, 1], found, settled, "prestress compensation, the issue's path settled", norm)
    fig.colorbar(image, ax=axes[1, 1], label="(sx + sy)/2 after erection (MPa)", shrink=0.6)
    plot_profile(axes[1, 2], found, [(issue, "the issue's path alone", "o"), (settled, "settled", "x")])
    fig.savefig(f"{out}.png", dpi=110, bbox_inches="tight")
    return rows


if __name__ == "__main__":
    for row in main():
        print(*row)
