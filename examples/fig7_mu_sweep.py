"""Paper Fig. 7: slip along the arch at G1..G9 of the 300 mm specimen for mu = 0.1 ... 0.5.

Each mu is one FMU instance (fmpy): parameters archHeight = 0.3, input mu, then frame.dz
stepped to its target -H/2 = -0.15 m in --steps communication steps. Writes
fig7_mu_sweep.png and fig7_mu_sweep.csv (one row per mu and gap, slips in mm) into --out.

    .venv/bin/python examples/fig7_mu_sweep.py [--steps 20] [--out DIR] [--fmu PATH]
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import archfmu  # noqa: E402

MUS = [0.1, 0.2, 0.3, 0.4, 0.5]
HEIGHT = 0.3


def run(mus, steps, backend, fmu_path, height=HEIGHT):
    """{mu: final snapshot} (see archfmu.ramp)."""
    return {mu: archfmu.ramp(height, mu, steps, backend=backend, fmu_path=fmu_path)[-1]
            for mu in mus}


def plot(final, height, path):
    plt = archfmu.use_agg()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.4), gridspec_kw={"width_ratios": [3, 2]})
    idx = list(range(1, 10))
    mus = sorted(final)
    colors = plt.cm.viridis([i / max(1, len(mus) - 1) * 0.9 for i in range(len(mus))])
    for mu, c in zip(mus, colors):
        gaps = final[mu]["gaps"]
        slip = [gaps[g]["slip"] * 1e3 for g in archfmu.GAPS]
        closed = [gaps[g]["status"] != 0 for g in archfmu.GAPS]
        ax.plot(idx, slip, "-", color=c, label=f"μ = {mu:g}")
        ax.plot([i for i, k in zip(idx, closed) if k], [s for s, k in zip(slip, closed) if k],
                "o", color=c)
        ax.plot([i for i, k in zip(idx, closed) if not k],
                [s for s, k in zip(slip, closed) if not k], "o", mfc="white", color=c)
    ax.plot([], [], "ko", label="gap in contact (stick/slip)")
    ax.plot([], [], "ko", mfc="white", label="gap open (film off the arch)")
    ax.set_xticks(idx, archfmu.GAPS)
    ax.set_xlabel("gap element (crown G1 → foot G9)")
    ax.set_ylabel("slip along the arch x (mm)")
    ax.set_title(f"Slip along the arch, {height * 1e3:.0f} mm specimen, frame dz = "
                 f"{-height / 2 * 1e3:.0f} mm (the μ curves overlap at this scale)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)

    # The effect of mu is a fraction of a millimetre: show it against the smallest mu.
    ref = final[mus[0]]["gaps"]
    in_contact = [g for g in archfmu.GAPS[1:]
                  if all(final[mu]["gaps"][g]["status"] != 0 for mu in mus)]
    for g, c in zip(in_contact, plt.cm.tab10.colors):
        d = [(final[mu]["gaps"][g]["slip"] - ref[g]["slip"]) * 1e3 for mu in mus]
        bx.plot(mus, d, "o-", color=c, label=g)
    bx.axhline(0, color="k", lw=0.6)
    bx.set_xlabel("friction coefficient μ")
    bx.set_ylabel(f"slip − slip(μ = {mus[0]:g}) (mm)")
    bx.set_title("Larger μ, smaller slip (gaps in contact)", fontsize=10)
    bx.grid(alpha=0.3)
    bx.legend(fontsize=8)
    fig.tight_layout()
    archfmu.save_png(fig, path)
    plt.close(fig)


def main(argv=None):
    p = archfmu.example_parser(__doc__.splitlines()[0], steps=20)
    p.add_argument("--mu", type=float, nargs="+", default=MUS, help="friction coefficients")
    p.add_argument("--backend", choices=["fmu", "cli"], default="fmu",
                   help="fmu (default) or cli: the same core without FMI, as a cross-check")
    a = p.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    final = run(a.mu, a.steps, a.backend, a.fmu)
    rows = [[mu, g, final[mu]["gaps"][g]["slip"] * 1e3, final[mu]["gaps"][g]["slipY"] * 1e3,
             final[mu]["gaps"][g]["N"], final[mu]["gaps"][g]["T"],
             archfmu.STATUS[final[mu]["gaps"][g]["status"]]]
            for mu in a.mu for g in archfmu.GAPS]
    csv_path = archfmu.write_csv(out / "fig7_mu_sweep.csv",
                                 ["mu", "gap", "slip_mm", "slip_y_mm", "normal_force_N",
                                  "friction_force_N", "status"], rows)
    png = out / "fig7_mu_sweep.png"
    plot(final, HEIGHT, png)
    print(f"slip along the arch (mm), {HEIGHT * 1e3:.0f} mm specimen, {a.steps} steps "
          f"({a.backend}); * = open gap")
    print("mu    " + "".join(f"{g:>8}" for g in archfmu.GAPS))
    for mu in a.mu:
        gaps = final[mu]["gaps"]
        print(f"{mu:<6g}" + "".join(
            f"{gaps[g]['slip'] * 1e3:7.2f}{'*' if gaps[g]['status'] == 0 else ' '}"
            for g in archfmu.GAPS))
    print(f"wrote {png} and {csv_path}")
    return final


if __name__ == "__main__":
    main()
