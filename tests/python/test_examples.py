"""The examples in ``examples/`` run end to end, and their numbers say what the paper says.

Each script runs in a subprocess with this interpreter (the .venv of ``tests/run.sh``) on a
few communication steps, writing into a temporary ``--out``. Checked: the PNG and CSV files
exist and are not empty, every number is finite, and the physics of §4.4:

* the crown G1 does not slide (symmetry plane y = 0); the slip grows towards the foot,
  G1 < G2 < G3 < G4 (the gaps in contact at -H/2);
* a larger mu gives less slip at the gaps in contact (Fig. 7);
* a higher arch gives more slip at G2 and G4 (Fig. 8);
* the erection system (film FMU + jack FMU, coupled to convergence) keeps the film's reaction
  at the jack's relief force and stays inside the stroke, the frame where the jack holds it; a
  step refused by the FMU (fmi2Discard) is retried in halves and reaches the same answer as an
  unrefused path;
* README's quick start (``run_specimen.sh``, ``run_specimen.py``) prints the slips and statuses the
  FMU gives on the same path, Table 1 beside them, and its reconstruction (crown to foot, curved
  supports, plastic film, its own FMU) misses Table 1 by the documented 1.8 mm RMS;
* Fig. 8 crown to foot (``fig8_wrapped.py``, the 300 mm specimen only): wrapped over the arch and
  extended by the fitted ε, the curved supports explain Table 1 to a few mm with every observed
  point touching, the fixed-frame gaps miss it by more than 10 mm.
* Fig. 8 with ETFE (``fig8_plastic.py``, the 300 mm specimen only): both films refitted to a few
  mm; the plastic film's stress stays on its hardening curve while the linear film's does not;
  released, the linear film returns to the start with nothing left, the plastic film keeps its
  plastic strain and its slips.
* the rectangular three-layer cushion (``cushion_three_layer.py``): its gas-law and balance
  checks pass, the top lands on the middle layer under snow, the lower chamber's golden pressure.

Not checked: how the pictures look.
"""

from __future__ import annotations

import csv
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CLI, INSTALLED, NEEDS_CHECKOUT

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
STEPS = "4"


def run_example(script, out, *args, fmu=None):
    cmd = [sys.executable, str(EXAMPLES / script), "--steps", STEPS, "--out", str(out), *args]
    if fmu is not None:
        cmd += ["--fmu", str(fmu)]
    # The CLI under test (archfmu.CLI: the release build's by default, the wheel's when installed).
    env = {**os.environ, "MEMBRANE_CONTACT_CLI": str(CLI)}
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=120, env=env)
    assert r.returncode == 0, f"{script} failed:\n{r.stdout}\n{r.stderr}"
    return r.stdout


def read_csv(path):
    assert path.is_file() and path.stat().st_size > 0, path
    with open(path) as f:
        rows = list(csv.DictReader(f))
    assert rows, f"{path}: no rows"
    return rows


def assert_png(path):
    assert path.is_file() and path.stat().st_size > 1000, path
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"


def assert_finite(rows, columns):
    for r in rows:
        for c in columns:
            assert math.isfinite(float(r[c])), f"{c} = {r[c]} in {r}"


@pytest.fixture(scope="module")
def archfmu():
    sys.path.insert(0, str(EXAMPLES))
    try:
        import archfmu as module
        yield module
    finally:
        sys.path.remove(str(EXAMPLES))


def test_fig7_mu_sweep(tmp_path, fmu_path):
    run_example("fig7_mu_sweep.py", tmp_path, fmu=fmu_path)
    assert_png(tmp_path / "fig7_mu_sweep.png")
    rows = read_csv(tmp_path / "fig7_mu_sweep.csv")
    assert_finite(rows, ["mu", "slip_mm", "slip_y_mm", "normal_force_N", "friction_force_N"])
    mus = sorted({float(r["mu"]) for r in rows})
    assert mus == [0.1, 0.2, 0.3, 0.4, 0.5]
    slip = {(float(r["mu"]), r["gap"]): float(r["slip_mm"]) for r in rows}
    status = {(float(r["mu"]), r["gap"]): r["status"] for r in rows}
    for mu in mus:
        assert abs(slip[mu, "G1"]) < 0.05, f"the crown slides {slip[mu, 'G1']} mm at mu {mu}"
        g1_to_g4 = [slip[mu, f"G{i}"] for i in range(1, 5)]
        assert g1_to_g4 == sorted(g1_to_g4) and len(set(g1_to_g4)) == 4, (mu, g1_to_g4)
        for g in ("G1", "G2", "G3", "G4"):
            assert status[mu, g] in ("stick", "slip"), f"{g} open at mu {mu}"
    for g in ("G2", "G3", "G4"):
        by_mu = [slip[mu, g] for mu in mus]
        assert all(a > b for a, b in zip(by_mu, by_mu[1:])), f"{g}: {by_mu} not decreasing in mu"


def test_fig8_vs_experiment(tmp_path, fmu_path):
    out = run_example("fig8_vs_experiment.py", tmp_path, fmu=fmu_path)
    assert "difference" in out
    assert_png(tmp_path / "fig8_vs_experiment.png")
    rows = read_csv(tmp_path / "fig8_vs_experiment.csv")
    assert_finite(rows, ["analysis_mm", "experiment_mm", "difference_mm"])
    assert len(rows) == 3 * 5
    table1 = {}
    with open(ROOT / "data" / "table1_sliding.csv") as f:
        for r in csv.DictReader(l for l in f if not l.startswith("#")):
            table1[int(r["arch_height_mm"])] = [float(r[f"p{p}"]) for p in range(1, 6)]
    a = {}
    for r in rows:
        h, p = int(r["arch_height_mm"]), int(r["point"])
        assert float(r["experiment_mm"]) == table1[h][p - 1]
        assert float(r["difference_mm"]) == pytest.approx(
            float(r["analysis_mm"]) - float(r["experiment_mm"]), abs=1e-5)
        a[h, r["gap"]] = (float(r["analysis_mm"]), r["status"])
    for h in (200, 300, 400):
        assert abs(a[h, "G1"][0]) < 0.05
        assert 0 < a[h, "G2"][0] < a[h, "G4"][0] < a[h, "G6"][0] < a[h, "G8"][0]
        assert a[h, "G2"][1] != "open" and a[h, "G4"][1] != "open"
    for g in ("G2", "G4"):
        assert a[200, g][0] < a[300, g][0] < a[400, g][0], f"{g} not growing with the arch"
    # The curved-support specimens (issue 10): their slip is the arc length slid since each node
    # landed, so where the film touches the arch it is positive and below the gaps' local x,
    # which counts the approach too; an open node has slid nothing; every value finite.
    assert_finite(rows, ["curved_support_mm", "curved_support_difference_mm"])
    for r in rows:
        curved, gap = float(r["curved_support_mm"]), float(r["analysis_mm"])
        if r["gap"] in ("G2", "G4"):
            assert r["curved_support_status"] != "open" and 0 < curved < gap, r
        if r["curved_support_status"] == "open":
            assert curved == pytest.approx(0.0, abs=1e-9), r


def test_fig6_stress(tmp_path, fmu_path, archfmu):
    out = run_example("fig6_stress.py", tmp_path / "fmu", fmu=fmu_path)
    assert "FMU results.directory" in out  # the FMU writes the .vtu
    assert_png(tmp_path / "fmu" / "fig6_stress.png")
    rows = read_csv(tmp_path / "fmu" / "fig6_stress.csv")
    assert len(rows) == 200  # the 1/4 model's triangles
    columns = ["x_m", "y_m", "z_m", "von_mises_MPa", "principal_1_MPa", "principal_2_MPa"]
    assert_finite(rows, columns)
    vm = [float(r["von_mises_MPa"]) for r in rows]
    assert min(vm) > 0
    for r in rows:
        assert float(r["principal_1_MPa"]) >= float(r["principal_2_MPa"]) - 1e-9
    # The picture's stresses are the FMU's output film.maxEquivalentStress for the same path.
    final = archfmu.ramp(0.3, 0.2, int(STEPS), fmu_path=fmu_path)[-1]
    assert max(vm) * 1e6 == pytest.approx(final["max_von_mises"], rel=1e-6)
    # The CLI's --vtk gives the same film to print precision: it takes the FMU's default
    # increments per step (with one increment per step, the CLI's old default, the friction
    # history moved the stresses by 0.03 MPa of 33 MPa).
    out = run_example("fig6_stress.py", tmp_path / "cli", "--source", "cli", fmu=fmu_path)
    assert "CLI --vtk" in out
    cli_rows = read_csv(tmp_path / "cli" / "fig6_stress.csv")
    for r, c in zip(rows, cli_rows):
        for k in columns:
            tol = 1e-9 if k.endswith("_m") else 1e-6
            assert float(c[k]) == pytest.approx(float(r[k]), abs=tol), (k, r, c)


def test_read_vtu_mirror(tmp_path):
    """The .vtu reader on a two-cell file; the mirror gives the four quarters."""
    sys.path.insert(0, str(EXAMPLES))
    try:
        import fig6_stress
    finally:
        sys.path.remove(str(EXAMPLES))
    vtu = tmp_path / "t.vtu"
    vtu.write_text("""<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
<UnstructuredGrid><Piece NumberOfPoints="4" NumberOfCells="2">
<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">
0 0 1  1 0 1  0 1 1  0 0 0</DataArray></Points>
<Cells><DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 0 3</DataArray>
<DataArray type="Int64" Name="offsets" format="ascii">3 5</DataArray>
<DataArray type="UInt8" Name="types" format="ascii">5 3</DataArray></Cells>
<PointData/>
<CellData><DataArray type="Float64" Name="von_mises" format="ascii">2e6 0</DataArray>
<DataArray type="Float64" Name="gap_status" format="ascii">-1 2</DataArray></CellData>
</Piece></UnstructuredGrid></VTKFile>""")
    v = fig6_stress.read_vtu(vtu)
    idx, tris = fig6_stress.cells_of(v, fig6_stress.VTK_TRIANGLE)
    assert idx == [0] and list(tris[0]) == [0, 1, 2]
    idx, lines = fig6_stress.cells_of(v, fig6_stress.VTK_LINE)
    assert idx == [1] and list(lines[0]) == [0, 3]
    assert v["cell_data"]["von_mises"][0] == 2e6
    quarters = fig6_stress.mirrored(v["points"])
    assert {tuple(q[1][:2]) for q in quarters} == {(1, 0), (-1, 0)}
    assert {tuple(q[2][:2]) for q in quarters} == {(0, 1), (0, -1)}


def test_erection_sequence(tmp_path, fmu_path):
    relief, stiffness = 600.0, 1e5
    run_example("erection_sequence.py", tmp_path, "--relief", str(relief), "--stiffness", str(stiffness),
                fmu=fmu_path)
    assert_png(tmp_path / "erection_sequence.png")
    rows = read_csv(tmp_path / "erection_sequence.csv")
    assert_finite(rows, ["time_s", "dz_mm", "piston_mm", "Rz_N", "jack_speed_mm_s"]
                  + [f"G{i}_slip_mm" for i in range(1, 10)])
    t = [float(r["time_s"]) for r in rows]
    assert t[0] == 0 and all(a < b for a, b in zip(t, t[1:])) and t[-1] == pytest.approx(400)
    force = [abs(float(r["Rz_N"])) for r in rows]
    dz = [float(r["dz_mm"]) for r in rows]
    assert all(-150 - 1e-9 <= d <= 0 for d in dz)
    # Converged coupling: the film's frame is where the jack holds it under the film's force
    # (dz = piston - Rz / stiffness, to the master's 1e-7 relative tolerance).
    for r in rows:
        held = float(r["piston_mm"]) - float(r["Rz_N"]) / stiffness * 1e3
        assert float(r["dz_mm"]) == pytest.approx(held, rel=1e-6, abs=1e-6)
    # The jack stalls on the film: the end force in the valve's band, the stroke not used up.
    assert max(force) <= relief * (1 + 1e-6)
    assert 0.85 * relief <= force[-1] <= relief
    assert dz[-1] > -150 + 1
    assert rows[-1]["jack_phase"] == "relief valve open"
    last = rows[-1]
    slips = [float(last[f"G{i}_slip_mm"]) for i in range(1, 5)]
    assert abs(slips[0]) < 0.05 and slips == sorted(slips)
    # Interface Newton (the default): at most 3 film steps per coupling step, each after the
    # first from both FMUs rolled back.
    assert all(1 <= int(r["coupling_iterations"]) <= 3 and int(r["rollbacks"]) == int(r["coupling_iterations"]) - 1
               for r in rows[1:])


def test_discard_is_retried_in_halves(fmu_path, archfmu):
    """One step to dz = -H/2 in a single increment without cut-backs, at most 10 iterations and
    without the viscous stabilization is refused by the FMU (with it, the FMU converges it);
    ArchFMU.step_to splits it in halves from the last converged point and lands where the
    FMU's own cut-backs land."""
    reference = archfmu.ramp(0.3, 0.2, 1, fmu_path=fmu_path)[-1]["gaps"]
    params = {"archHeight": 0.3, "solver.incrementsPerStep": 1, "solver.maxCutbacks": 0,
              "solver.maxIterations": 10, "solver.stabilization": False}
    with archfmu.ArchFMU(fmu_path, parameters=params, inputs={"mu": 0.2}) as fmu:
        assert not fmu.step(1.0, {"frame.dz": -0.15})
        assert fmu.time == 0.0 and fmu.reached["frame.dz"] == 0.0
        assert any("Time stays" in m or "converge" in m for _, _, m in fmu.messages)
        substeps = fmu.step_to(1.0, {"frame.dz": -0.15})
        assert substeps > 1 and fmu.time == pytest.approx(1.0)
        gaps = fmu.snapshot()["gaps"]
    for g in archfmu.GAPS:
        assert gaps[g]["slip"] == pytest.approx(reference[g]["slip"], abs=5e-5), g
        assert gaps[g]["status"] == reference[g]["status"], g


@pytest.mark.skipif(INSTALLED, reason=f"README's block runs cargo and .venv: {NEEDS_CHECKOUT}")
def test_the_readme_own_model_block_runs_as_written():
    """README's "Your own model" commands, run by bash in the repository as a user would."""
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Your own model", 1)[1]
    block = section.split("```sh\n", 1)[1].split("```", 1)[0]
    r = subprocess.run(["bash", "-euo", "pipefail", "-c", block], cwd=ROOT, capture_output=True, text=True,
                       timeout=600)
    assert r.returncode == 0, f"{r.stdout}\n{r.stderr}"
    assert "frame reaction Rz" in r.stdout and "FilmOverTwoArches_film.pvd" in r.stdout
    assert (ROOT / "out" / "own_model" / "vtk" / "FilmOverTwoArches_film_0006.vtu").is_file()
    assert (ROOT / "out" / "own_model" / "slip.png").stat().st_size > 1000


def specimen_report(stdout):
    """run_specimen.py's comparison: {point: (Table 1, reconstruction (slip, status), literal (gap,
    slip, status))} and the summary rows {label: (reconstruction, literal)} (first number of each)."""
    points, summary = {}, {}
    for line in stdout.splitlines():
        cells = [c.split() for c in line.split("|")]
        if len(cells) == 3 and cells[0] and cells[0][0].isdigit():
            (p, m), (rs, _, rst), (g, ls, _, lst) = cells
            points[int(p)] = (float(m), (float(rs), rst), (g, float(ls), lst))
        for label in ("RMS misfit, points 2-5", "max von Mises at the end"):
            if line.startswith(label):
                numbers = [float(w) for w in line[len(label):].split() if w[0].isdigit()]
                summary[label] = (numbers[0], numbers[1])
    return points, summary


def test_run_specimen_prints_the_fmus_slips_beside_table1(fmu_path, archfmu):
    """README's main job, the literal model on few steps: every printed slip (2 decimals) and
    status of the paper's gap model is the ParallelArch FMU's on the same path, stepped by
    archfmu instead of the package's Film; both columns beside Table 1, the RMS on points 2-5 and
    the stresses as printed."""
    env = {**os.environ, "MEMBRANE_CONTACT_CLI": str(CLI)}
    r = subprocess.run([sys.executable, str(EXAMPLES / "run_specimen.py"), "--steps", STEPS,
                        "--fmu", str(fmu_path)], cwd=ROOT, capture_output=True, text=True, timeout=120, env=env)
    assert r.returncode == 0, r.stderr
    points, summary = specimen_report(r.stdout)
    final = archfmu.ramp(0.3, 0.2, int(STEPS), fmu_path=fmu_path)[-1]
    table1 = archfmu.read_table1()[300]
    assert sorted(points) == list(archfmu.OBSERVED)
    for point, g in archfmu.OBSERVED.items():
        measured, (rec, rec_status), (gap, slip, status) = points[point]
        assert (measured, gap) == (table1[point], g)
        assert slip == pytest.approx(final["gaps"][g]["slip"] * 1e3, abs=0.0051), g
        assert status == archfmu.STATUS[final["gaps"][g]["status"]], g
        assert rec_status in ("stick", "slip"), f"point {point} of the reconstruction is {rec_status}"
    assert summary["max von Mises at the end"][1] == pytest.approx(final["max_von_mises"] / 1e6, abs=0.0051)
    for column, printed in zip((1, 2), summary["RMS misfit, points 2-5"]):
        slips = {p: row[column][-2] for p, row in points.items()}
        rms = (sum((slips[p] - table1[p]) ** 2 for p in (2, 3, 4, 5)) / 4) ** 0.5
        assert printed == pytest.approx(rms, abs=0.011)


def test_run_specimen_reconstruction_explains_table1(archfmu, monkeypatch):
    """The golden number of README's first command: the reconstruction (crown to foot, curved
    supports, plastic film, through its own FMU at the documented eps, 40 steps) misses Table 1's
    points 2-5 by 1.826 mm RMS (1.8255 with the one method; docs/figures/fig8_plastic.csv, computed
    with the former solver, has 1.818880). Tolerance 0.03 mm:
    mu = 0.15 or 0.25 instead of 0.2 moves it by 0.07 / 0.11 mm, a wrong eps or contact far more.
    Every arch node touches and the stress stays on ETFE's hardening curve (21 MPa initial yield)."""
    monkeypatch.setattr(archfmu, "CLI", CLI)
    import run_specimen

    rec = run_specimen.reconstruction(300, 0.2, 40)
    rms = run_specimen.rms({p: s for p, (s, _) in rec["points"].items()}, archfmu.read_table1()[300])
    assert rms == pytest.approx(1.826, abs=0.03), rec["points"]
    assert rec["reached"] == rec["eps"] and rec["touching"] == (9, 9)
    assert 21e6 < rec["stress"] < 30e6 and rec["yielded"] > 0


@pytest.mark.skipif(INSTALLED, reason=f"run_specimen.sh runs fmu/prepare.sh (cargo, .venv): {NEEDS_CHECKOUT}")
def test_run_specimen_sh_prepares_and_prints_the_same_report():
    """README's first command: the script builds and packs (fmu/prepare.sh, quick when up to date)
    and prints what run_specimen.py prints with the same arguments."""
    sh = subprocess.run(["bash", str(EXAMPLES / "run_specimen.sh"), "--steps", STEPS], cwd=ROOT,
                        capture_output=True, text=True, timeout=600)
    assert sh.returncode == 0, sh.stderr
    py = subprocess.run([str(ROOT / ".venv" / "bin" / "python"), str(EXAMPLES / "run_specimen.py"),
                         "--steps", STEPS], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert py.returncode == 0, py.stderr
    assert sh.stdout == py.stdout
    assert "RMS misfit, points 2-5" in sh.stdout and "Why they differ" in sh.stdout


def test_fig8_wrapped_fits_table1_with_the_curved_supports(tmp_path, archfmu):
    """The 300 mm specimen wound onto the arch and extended (README's Fig. 8, crown to foot): the
    fitted extension is within [0, 10 %], the curved supports reach Table 1's points 2-5 to
    within 3 mm RMS with all five observed nodes touching (README: 1.8 mm at 40 steps), the
    paper's gaps miss by more than 10 mm (README: 15-33 mm at any extension)."""
    out = run_example("fig8_wrapped.py", tmp_path, "--heights", "300")
    assert "300 mm" in out and "200 mm" not in out
    assert_png(tmp_path / "fig8_wrapped.png")
    rows = read_csv(tmp_path / "fig8_wrapped.csv")
    assert_finite(rows, ["eps", "eps_reached", "rms_mm", "slip_mm", "experiment_mm"])
    assert len(rows) == 2 * 5
    table1 = archfmu.read_table1()[300]
    fit = {}
    for r in rows:
        assert int(r["arch_height_mm"]) == 300
        assert float(r["experiment_mm"]) == table1[int(r["point"])]
        fit.setdefault(r["contact"], []).append(r)
    assert sorted(fit) == ["curved-support", "gaps"]
    for contact, points in fit.items():
        eps, reached = float(points[0]["eps"]), float(points[0]["eps_reached"])
        assert 0.0 <= eps <= 0.1 and reached == eps, (contact, eps, reached)
        slips = {int(r["point"]): float(r["slip_mm"]) for r in points}
        rms = (sum((slips[p] - table1[p]) ** 2 for p in (2, 3, 4, 5)) / 4) ** 0.5
        assert float(points[0]["rms_mm"]) == pytest.approx(rms, abs=2e-6)  # written with 6 decimals
    curved = fit["curved-support"]
    assert float(curved[0]["rms_mm"]) < 3.0
    assert all(r["status"] != "open" for r in curved)
    slips = [float(r["slip_mm"]) for r in sorted(curved, key=lambda r: int(r["point"]))]
    assert slips == sorted(slips), "the curved-support slip grows from crown to foot"
    assert float(fit["gaps"][0]["rms_mm"]) > 10.0


def test_fig8_plastic_refits_both_films_and_keeps_the_plastic_films_residual_strain(tmp_path):
    """The 300 mm specimen crown to foot with the linear and the plastic film (docs/mechanics.md
    "The specimens with ETFE"): both fits reach Table 1 within 3 mm RMS (1.8 mm at 40 steps);
    the plastic film's largest von Mises stress is at most the data-sheet curve's flow stress
    at its largest plastic strain (Cauchy ≤ Kirchhoff = flow stress) and below the linear
    film's; released, the linear film is back at the flat start with no residual strain and its
    slips back under 1 mm, the plastic film (slack once 60-70 % released, carried on by the
    stabilization) keeps residual strain and more than 1 mm of slip at points 2-5."""
    run_example("fig8_plastic.py", tmp_path, "--heights", "300", "--no-lowered")
    assert_png(tmp_path / "fig8_plastic.png")
    rows = read_csv(tmp_path / "fig8_plastic.csv")
    assert_finite(rows, ["eps", "rms_mm", "von_mises_max_MPa", "slip_mm", "slip_released_mm",
                         "residual_plastic_strain", "released_to_time"])
    films = {}
    for r in rows:
        films.setdefault(r["film"], {})[int(r["point"])] = r
    assert sorted(films) == ["linear", "plastic"]
    for points in films.values():
        first = points[1]
        assert 0.0 < float(first["eps"]) <= 0.1 and first["eps"] == first["eps_reached"]
        assert float(first["rms_mm"]) < 3.0
    elements = read_csv(tmp_path / "fig8_plastic_residual.csv")
    assert len(elements) == 200
    top = max(float(e["equivalent_plastic_strain"]) for e in elements)
    # The data-sheet curve (docs/mechanics.md): 21 MPa at 0, 275 MPa at 1.4547.
    flow = 21.0 + (275.0 - 21.0) / 1.4547480922384253 * top
    linear, plastic = films["linear"], films["plastic"]
    assert top > 0.01
    assert float(plastic[1]["von_mises_max_MPa"]) <= flow + 1e-3
    assert float(plastic[1]["von_mises_max_MPa"]) < float(linear[1]["von_mises_max_MPa"])
    assert float(linear[1]["released_to_time"]) == 0.0
    assert float(plastic[1]["released_to_time"]) < 1.0
    for p in (2, 3, 4, 5):
        assert float(linear[p]["residual_plastic_strain"]) == 0.0
        # Friction leaves the linear film a fraction of a mm on a 4-step path (0.03 mm at 40).
        assert abs(float(linear[p]["slip_released_mm"])) < 1.0
        assert float(plastic[p]["residual_plastic_strain"]) > 0.01
        assert float(plastic[p]["slip_released_mm"]) > 1.0


#: examples/cushion_three_layer.py's golden number: the lower chamber's pressure (Pa) under
#: 1.5 kPa of snow, its air enclosed at 300 Pa, the top layer inverted onto the middle one.
#: Tolerance 0.5 Pa: the mesh moves it by 0.1 Pa (8 x 16 or 12 x 24 cells instead of 10 x 20),
#: adiabatic air (κ = 1.4) by +1.3 Pa, a layer contact ten times softer by -3.1 Pa.
CUSHION_SNOW_LOWER = 1331.3


def cushion_stages(stdout):
    """The example's table: {row label: [value per stage]} (the first number of each cell)."""
    lines = stdout.splitlines()
    header = next(i for i, line in enumerate(lines) if line.split()[:1] == ["inflated"])
    table = {}
    for line in lines[header + 1:]:
        label, _, cells = line.partition("  ")
        if not cells.strip() or ":" in label:
            break
        table[label.strip()] = [float(c.split("/")[0]) for c in cells.split()]
    return table


def test_three_layer_cushion_lands_its_top_on_the_middle_layer_under_snow_and_keeps_its_air(tmp_path):
    """The rectangular three-layer cushion (3 m x 6 m, 250/100/250 µm plastic ETFE) through
    inflation, snow, wind suction and sun, by the CLI along a staged path: the script's own checks
    pass (each enclosed chamber's gas law to 1e-6, the vertical reactions equal to the snow and
    suction loads to 1e-6: it exits non-zero otherwise); under the snow the top lies on the middle
    layer over most of the 18 m² and the lower air carries it at the golden pressure, the bottom
    layer yields; suction lowers both chambers' pressure, the sun raises it; the picture is
    written."""
    out = run_example("cushion_three_layer.py", tmp_path)
    assert_png(tmp_path / "cushion_three_layer.png")
    assert "gas law: (p + p_a) V / T of each enclosed chamber kept to" in out
    golden = float(out.split("lower chamber under the snow:")[1].split()[0])
    assert golden == pytest.approx(CUSHION_SNOW_LOWER, abs=0.5)
    t = cushion_stages(out)
    inflated, snow, melted, wind, calm, sun = range(6)
    assert t["upper chamber (Pa)"][inflated] == t["lower chamber (Pa)"][inflated] == 300.0
    assert t["upper chamber (Pa)"][snow] == 300.0, "the upper chamber is held by its supply"
    assert 14.0 < t["contact area (m²)"][snow] < 18.0
    assert t["contact area (m²)"][wind] == t["contact area (m²)"][sun] == 0.0
    assert t["plastic strain bottom"][snow] > 0.0 and t["plastic strain top"][snow] == 0.0
    assert t["plastic strain bottom"][sun] == t["plastic strain bottom"][snow], "kept once unloaded"
    for chamber in ("upper chamber (Pa)", "lower chamber (Pa)"):
        assert t[chamber][wind] < t[chamber][calm] < t[chamber][sun]
    for edge in ("long edges max/mean (kN/m)", "short edges max/mean (kN/m)"):
        assert t[edge][snow] > t[edge][inflated] > 0.0
