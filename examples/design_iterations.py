"""Figure of issue 46: the prestress error per erection of the friction-aware compensation.

Left: the drum of ``examples/drum.json`` (a film wrapped +-60 deg over a 0.5 m drum between two
rails), cut in one piece: frictionless from the uncompensated cut (one correction brings it to
0.375 %), and with mu = 0.3 from the prestress compensation (friction holds the crown: the
corrections do not bring it down). Right: the vault bay of ``examples/vault_bay.py`` (mu = 0.3),
eight strips, the prestress compensation corrected per strip and per element, on the two
erection paths. Writes ``docs/figures/design_iterations.csv`` and ``.png``.
Run: PYTHONPATH=python python examples/design_iterations.py (about 20 s)."""

import csv
import json
from pathlib import Path

from membrane_contact.design import pattern

ROOT = Path(__file__).resolve().parents[1]


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


def vault_rows():
    """The same for the vault bay's four runs."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("vault_bay", ROOT / "examples" / "vault_bay.py")
    bay = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bay)
    _, reports = bay.main()
    names = ["vault, rails drawn, per strip", "vault, rails drawn, per element",
             "vault, rails down and out, per strip", "vault, rails down and out, per element"]
    return [(name, k, e["mean_error"], e["max_error"])
            for name, report in zip(names, reports) for k, e in enumerate(report["erections"])]


def main(out=ROOT / "docs" / "figures" / "design_iterations"):
    rows = drum_rows() + vault_rows()
    with open(f"{out}.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "erection", "mean_error", "max_error"])
        w.writerows(rows)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for ax, prefix in zip(axes, ("drum", "vault")):
        for case in dict.fromkeys(r[0] for r in rows if r[0].startswith(prefix)):
            pts = [(r[1], 100 * r[3]) for r in rows if r[0] == case]
            ax.plot(*zip(*pts), marker="o", label=case)
        ax.set_yscale("log")
        ax.set_xlabel("erection")
        ax.set_ylabel("largest prestress error (%)")
        ax.set_title("per element: away from the rails; per strip: every triangle", fontsize=8)
        ax.axhline(5.0, color="grey", lw=0.8, ls="--")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(f"{out}.png", dpi=120)
    return rows


if __name__ == "__main__":
    for row in main():
        print(*row)
