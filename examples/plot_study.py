"""Plots the sweep of examples/study_mu_prestress.toml (run it first):

    python -m membrane_contact.study examples/study_mu_prestress.toml
    .venv/bin/python examples/plot_study.py [target/studies/mu_prestress] [--out docs/figures/study_mu_prestress.png]

Left: the slip at G4 at the end of the erection path against mu, one line per prestress
and film temperature. Right: the frame's reaction over the erection path (frame.dz from 0 to
-0.15 m) for mu = 0.2, one line per prestress and film temperature.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from membrane_contact.study import open_study  # noqa: E402


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("directory", nargs="?", default=str(ROOT / "target" / "studies" / "mu_prestress"))
    p.add_argument("--out", default=str(ROOT / "docs" / "figures" / "study_mu_prestress.png"))
    a = p.parse_args(argv)
    ds = open_study(a.directory)
    ds = ds.where(ds.status == "ok", drop=True)
    prestresses = np.unique(ds["film.prestressX"].values)
    temperatures = np.unique(ds["film.temperature"].values)
    colours = plt.cm.viridis(np.linspace(0, 0.85, len(prestresses)))
    styles = ["-", "--", ":", "-."]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for c, s in zip(colours, prestresses):
        for ls, t in zip(styles, temperatures):
            sel = (ds["film.prestressX"] == s) & (ds["film.temperature"] == t)
            cases = ds.where(sel, drop=True).sortby("mu")
            label = f"{s / 1e6:g} MPa, {t:g} °C"
            left.plot(cases.mu, 1e3 * cases["G4.slip"].isel(step=-1), ls, marker="o", ms=3, color=c, label=label)
            at = cases.where(cases.mu == 0.2, drop=True)
            if at.sizes["case"]:
                right.plot(-0.15 * at.time * 1e3, at["frame.Rz"].isel(case=0), ls, color=c, label=label)
    left.set_xlabel("μ")
    left.set_ylabel("slip at G4 at the end of the path (mm)")
    left.set_title(f"{ds.sizes['case']} cases: μ × temperature × prestress")
    right.set_xlabel("frame.dz (mm)")
    right.set_ylabel("frame.Rz (N, 1/4 model)")
    right.set_title("erection path, μ = 0.2")
    right.legend(fontsize=7, title="prestress, temperature", title_fontsize=7)
    for ax in (left, right):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(a.out, dpi=110)
    print(a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
