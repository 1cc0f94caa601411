"""Studies on Dask (issue 22): ``membrane_contact.study``.

TEST GOAL: a study's dataset holds, for each case, the outputs of that case's own FMU run (the
same as one whole-path ``Film.run`` with the case's values in this process); one and two
LocalCluster workers give bit-identical datasets, and so does a scheduler and workers started
as separate processes, which receive the FMU's bytes (not its path: each worker has its own
temporary directory, where the FMU lands); a study whose driver is killed mid-way resumes on
the same directory and runs only the cases not stored: none runs twice, none is lost; a case
the FMU refuses (a parameter at initialization, a step refused after every halving) is stored
with the FMU's message and the other cases run; the inverse tool fits the same values, bit for
bit, serially and with its sensitivity runs on the cluster; designs: factorial order, one
Latin-hypercube point per stratum, seeded Monte-Carlo draws with the named distribution's
quantiles, bad names and distributions refused naming them; the command line runs a TOML and
a YAML spec and prints quantiles; the example specs name variables their FMUs have.

MODEL: the ParallelArch FMU (300 mm), frame lowered to −0.15 m in 3–4 rows.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, package_env

from membrane_contact import Film
from membrane_contact.inverse import Unknown, _run, fit
from membrane_contact.study import (Distribution, Study, check_variables, cluster, design_from_spec, factorial,
                                    latin_hypercube, load_spec, monte_carlo, open_study, path_from_spec)

ROWS = [0.25, 0.5, 0.75, 1.0]
PATH = {"time": ROWS, "frame.dz": [-0.15 * t for t in ROWS]}
OUTPUTS = ["G2.slip", "G4.slip", "G6.slip", "frame.Rz", "film.maxEquivalentStress"]
DESIGN = factorial({"mu": [0.15, 0.3, 0.4], "film.prestressX": [0.5e6, 1.0e6], "scale:frame.dz": [0.8, 1.0]})


def identical(a, b) -> bool:
    """Two datasets with the same variables, coordinates and bits in every float."""
    if not a.identical(b):
        return False
    return all(np.array_equal(a[v].values.view(np.uint64), b[v].values.view(np.uint64))
               for v in a.data_vars if a[v].dtype == np.float64)


@pytest.fixture(scope="module")
def two_workers():
    """A LocalCluster of two worker processes, shared by the tests that need one."""
    with cluster(workers=2) as client:
        yield client


@pytest.fixture(scope="module")
def one_worker(fmu_path, tmp_path_factory):
    study = Study(fmu_path, DESIGN, PATH, OUTPUTS, directory=tmp_path_factory.mktemp("one") / "study")
    return study, study.run(workers=1, progress=False)


def test_each_case_holds_the_outputs_of_its_own_run(fmu_path, one_worker):
    study, ds = one_worker
    assert ds.sizes == {"case": 12, "step": 5} and list(ds.time.values) == [0.0] + ROWS
    assert (ds.status == "ok").all() and ds.attrs["parameters"] == '{"solver.threads": 1}'
    for k in (0, 5, 11):
        mu, prestress, scale = (float(ds[n].values[k]) for n in ("mu", "film.prestressX", "scale:frame.dz"))
        with Film(fmu_path, logging=False, quiet=True) as film:
            film.initialize(parameters={"film.prestressX": prestress, "solver.threads": 1})
            r = film.run({"time": ROWS, "mu": [mu] * 4, "frame.dz": [-0.15 * t * scale for t in ROWS]}, outputs=OUTPUTS)
        for o in OUTPUTS:
            np.testing.assert_array_equal(ds[o].values[k], r[o], err_msg=f"case {k} {o}")
    # The design is seen in the outputs: more friction, less slip at G4 (same prestress and path).
    g4 = ds["G4.slip"].isel(step=-1)
    assert g4.values[0] > g4.values[4] > g4.values[8] > 0


def test_one_and_two_local_workers_give_bit_identical_datasets(fmu_path, one_worker, two_workers, tmp_path):
    _, ds1 = one_worker
    ds2 = Study(fmu_path, DESIGN, PATH, OUTPUTS, directory=tmp_path / "two").run(two_workers, progress=False)
    assert len(set(r["worker"] for r in Study(fmu_path, DESIGN, PATH, OUTPUTS, directory=tmp_path / "two")
                   .results().values())) == 2  # both workers ran cases
    assert identical(ds1, ds2)
    assert identical(open_study(tmp_path / "two"), ds2)  # read back from the directory alone
    # Without a directory, the results come back in memory; workers reading the FMU at its path
    # (a shared filesystem) instead of receiving its bytes: the same dataset.
    ds0 = Study(fmu_path, DESIGN, PATH, OUTPUTS).run(two_workers, progress=False, shared_fmu=True)
    assert identical(ds1, ds0)


def _start(args, env, log):
    return subprocess.Popen([sys.executable, "-m", *args], env=env, stdout=log, stderr=subprocess.STDOUT,
                            start_new_session=True)


def test_a_scheduler_and_workers_in_separate_processes_give_the_same_dataset(fmu_path, one_worker, tmp_path):
    scheduler_file = tmp_path / "scheduler.json"
    env = package_env()
    processes = []
    log = open(tmp_path / "cluster.log", "w")
    try:
        processes.append(_start(["distributed.cli.dask_scheduler", "--scheduler-file", str(scheduler_file),
                                 "--host", "127.0.0.1", "--port", "0", "--no-dashboard"], env, log))
        temporaries = []
        for w in range(2):
            temporaries.append(tmp_path / f"worker{w}-tmp")
            temporaries[-1].mkdir()
            processes.append(_start(["distributed.cli.dask_worker", "--scheduler-file", str(scheduler_file),
                                     "--nthreads", "1", "--no-dashboard", "--no-nanny", "--host", "127.0.0.1"],
                                    {**env, "TMPDIR": str(temporaries[-1])}, log))
        deadline = time.monotonic() + 60
        while not scheduler_file.is_file():
            assert time.monotonic() < deadline, (tmp_path / "cluster.log").read_text()
            time.sleep(0.1)
        from dask.distributed import Client

        with Client(scheduler_file=str(scheduler_file)) as client:
            client.wait_for_workers(2, timeout=60)
            workers = client.run(os.getpid)
            assert len(workers) == 2 and os.getpid() not in workers.values()
            ds = Study(fmu_path, DESIGN, PATH, OUTPUTS).run(client, progress=False)
        assert identical(ds, one_worker[1])
        # The FMU travelled as bytes: each worker wrote it into its own temporary directory.
        for t in temporaries:
            (copy,) = (t / "membrane-contact-fmus").glob("*/*.fmu")
            assert copy.read_bytes() == Path(fmu_path).read_bytes()
    finally:
        for p in processes:
            os.killpg(p.pid, signal.SIGTERM)
        for p in processes:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
        log.close()


RESUME = """
import sys
from membrane_contact.study import Study, factorial
if __name__ == "__main__":
    design = factorial({"mu": [0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45], "film.prestressX": [0.5e6, 1e6]})
    path = {"time": [0.25, 0.5, 0.75, 1.0], "frame.dz": [-0.0375, -0.075, -0.1125, -0.15]}
    Study(sys.argv[1], design, path, ["G2.slip", "G4.slip"], {"solver.incrementsPerStep": 20},
          directory=sys.argv[2], run_log=sys.argv[3]).run(workers=1, progress=False)
"""


def test_a_killed_study_resumes_running_each_case_once(fmu_path, tmp_path):
    script = tmp_path / "resume.py"
    script.write_text(RESUME)
    directory, run_log = tmp_path / "study", tmp_path / "run.log"
    args = [sys.executable, str(script), str(fmu_path), str(directory), str(run_log)]
    driver = subprocess.Popen(args, env=package_env(), start_new_session=True, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 60
    while len(list((directory / "cases").glob("*.parquet"))) < 4:
        assert driver.poll() is None, driver.stderr.read().decode()
        assert time.monotonic() < deadline
        time.sleep(0.01)
    os.killpg(driver.pid, signal.SIGKILL)  # the driver, its nannies and its worker
    driver.wait()
    first = {int(p.stem.split("-")[1]) for p in (directory / "cases").glob("*.parquet")}
    started_first = len(run_log.read_text().splitlines())
    assert 4 <= len(first) < 16, first
    r = subprocess.run(args, env=package_env(), capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    started_again = [int(line.split()[0]) for line in run_log.read_text().splitlines()[started_first:]]
    assert not set(started_again) & first, "a stored case ran again"
    assert sorted(started_again) == sorted(set(range(16)) - first), "a case was lost or ran twice after the resume"
    stored = [json.loads(line)["case"] for line in (directory / "log.jsonl").read_text().splitlines()]
    # each case stored once; the kill may fall between a case file's rename and its log line,
    # so at most one case the first driver stored may lack its line (its file is there)
    assert len(stored) == len(set(stored)) and set(stored) <= set(range(16))
    unlogged = set(range(16)) - set(stored)
    assert len(unlogged) <= 1 and unlogged <= first, unlogged
    design = factorial({"mu": [0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45], "film.prestressX": [0.5e6, 1e6]})
    path = {"time": [0.25, 0.5, 0.75, 1.0], "frame.dz": [-0.0375, -0.075, -0.1125, -0.15]}
    resumed = Study(fmu_path, design, path, ["G2.slip", "G4.slip"], {"solver.incrementsPerStep": 20},
                    directory=directory).dataset()
    assert (resumed.status == "ok").all() and not np.isnan(resumed["G4.slip"].values).any()
    # The directory is this study's: another design is refused, naming what differs.
    with pytest.raises(ValueError, match="holds another study .*design"):
        Study(fmu_path, factorial({"mu": [0.2]}), path, ["G2.slip", "G4.slip"], {"solver.incrementsPerStep": 20},
              directory=directory).run(workers=1, progress=False)


def test_a_refused_case_is_stored_with_the_fmus_message_and_the_study_goes_on(fmu_path, two_workers, tmp_path):
    table = tmp_path / "cases.csv"
    table.write_text("# E, the Newton iterations allowed per increment and the cut-backs per step\n"
                     "film.E,solver.maxIterations,solver.maxCutbacks\n1e9,100,12\n-1,100,12\n1e9,1,0\n1.2e9,100,12\n")
    design = design_from_spec({"kind": "table", "csv": "cases.csv"}, tmp_path)
    path = {"time": [1.0], "frame.dz": [-0.15]}
    ds = Study(fmu_path, design, path, ["G2.slip"], directory=tmp_path / "s",
               max_halvings=1).run(two_workers, progress=False)
    assert list(ds.status.values) == ["ok", "error", "refused", "ok"]
    assert "invalid parameters: material: E = -1 must be > 0" in ds.message.values[1]
    assert "did not converge" in ds.message.values[2] and "solver.maxIterations" in ds.message.values[2]
    assert np.isnan(ds["G2.slip"].values[1]).all() and np.isnan(ds["G2.slip"].values[2, 1])
    assert ds["G2.slip"].values[2, 0] == 0.0  # the initialized state was reached
    assert np.isfinite(ds["G2.slip"].values[[0, 3], 1]).all() and ds.message.values[0] == ""


def test_the_inverse_tool_fits_the_same_serially_and_on_the_cluster(fmu_path, two_workers):
    path = {"time": [0.5, 1.0], "frame.dz": [-0.075, -0.15]}
    tight = {"solver.displacementTolerance": 1e-10, "solver.residualTolerance": 1e-10}
    outputs = ["G2.slip", "G3.slip", "G4.slip"]
    truth = [Unknown("mu", 0.3), Unknown("scale:frame.dz", 0.9)]
    measured = dict(zip(outputs, _run(fmu_path, path, tight, truth, [0.3, 0.9], outputs)))
    unknowns = [Unknown("mu", 0.2, 0.0, 1.0), Unknown("scale:frame.dz", 1.0, 0.5, 1.5)]
    serial = fit(fmu_path, measured, unknowns, path, tight, max_iterations=4)
    parallel = fit(fmu_path, measured, unknowns, path, tight, max_iterations=4, client=two_workers)
    assert serial.evaluations == parallel.evaluations > 8
    np.testing.assert_array_equal(serial.values, parallel.values)
    np.testing.assert_array_equal(serial.sensitivities, parallel.sensitivities)
    assert serial.history == parallel.history
    assert abs(serial.values[1] - 0.9) < 1e-3  # it did fit


def test_designs_factorial_latin_hypercube_and_seeded_monte_carlo():
    d = factorial({"a": [1, 2], "b": [10, 20, 30], "law": ["isotropic", "sliding-direction"]})
    assert list(d["a"]) == [1] * 6 + [2] * 6 and list(d["b"][:6]) == [10, 10, 20, 20, 30, 30]
    assert d["law"].dtype.kind == "U" and list(d["law"][:2]) == ["isotropic", "sliding-direction"]
    lhs = latin_hypercube({"x": [0.0, 1.0], "y": {"dist": "uniform", "low": -2, "high": 2}}, 20, seed=3)
    for column, (lo, hi) in ((lhs["x"], (0, 1)), (lhs["y"], (-2, 2))):
        strata = np.floor((column - lo) / (hi - lo) * 20).astype(int)
        assert sorted(strata) == list(range(20))  # one point per stratum
    spec = {"mu": {"dist": "lognormal", "median": 0.2, "sigma": 0.25},
            "t": {"dist": "triangular", "low": 0, "mode": 1, "high": 4},
            "n": {"dist": "normal", "mean": 5, "sd": 2}}
    a, b = monte_carlo(spec, 4000, seed=7), monte_carlo(spec, 4000, seed=7)
    assert all(np.array_equal(a[k], b[k]) for k in spec)
    assert not np.array_equal(a["mu"], monte_carlo(spec, 4000, seed=8)["mu"])
    assert np.median(a["mu"]) == pytest.approx(0.2, rel=0.03) and (a["mu"] > 0).all()
    assert np.std(np.log(a["mu"])) == pytest.approx(0.25, rel=0.05)
    assert np.mean(a["t"]) == pytest.approx(5 / 3, rel=0.03) and 0 <= a["t"].min() and a["t"].max() <= 4
    assert np.mean(a["n"]) == pytest.approx(5, abs=0.1)
    assert Distribution.parse("q", {"dist": "lognormal", "median": 2.0, "sigma": 0.5}).ppf(np.array([0.5]))[0] == 2.0
    with pytest.raises(ValueError, match="'mu': distribution 'lognorm' is not one of"):
        monte_carlo({"mu": {"dist": "lognorm", "median": 0.2, "sigma": 0.1}}, 3)
    with pytest.raises(ValueError, match="'mu': a lognormal distribution takes median, sigma; given mean, sigma"):
        monte_carlo({"mu": {"dist": "lognormal", "mean": 0.2, "sigma": 0.1}}, 3)
    with pytest.raises(ValueError, match="'mu': invalid triangular"):
        monte_carlo({"mu": {"dist": "triangular", "low": 0, "mode": 2, "high": 1}}, 3)


def test_names_the_fmu_does_not_have_are_refused_naming_them(fmu_path):
    with pytest.raises(KeyError, match="design variable 'film.colour' is not a parameter or an input of "
                                       "ParallelArch .no such variable."):
        Study(fmu_path, {"film.colour": [20.0]}, PATH)
    with pytest.raises(KeyError, match="output 'frame.dz' is not an output of ParallelArch .a input."):
        Study(fmu_path, {"mu": [0.2]}, PATH, ["frame.dz"])
    with pytest.raises(KeyError, match="'scale:frame.dx': the load path has no column 'frame.dx'"):
        Study(fmu_path, {"scale:frame.dx": [1.0]}, PATH)


def test_the_command_line_runs_toml_and_yaml_specs(fmu_path, tmp_path):
    (tmp_path / "mc.toml").write_text(f"""
fmu = "{fmu_path}"
outputs = ["G2.slip", "G4.slip"]
[path]
steps = 3
to = {{ "frame.dz" = -0.15 }}
[design]
kind = "montecarlo"
cases = 6
seed = 11
[design.variables]
mu = {{ dist = "lognormal", median = 0.25, sigma = 0.3 }}
[report]
quantiles = [0.05, 0.5, 0.95]
outputs = ["G4.slip"]
""")
    (tmp_path / "mc.yaml").write_text(f"""
fmu: {fmu_path}
outputs: [G2.slip, G4.slip]
path: {{steps: 3, to: {{frame.dz: -0.15}}}}
design:
  kind: montecarlo
  cases: 6
  seed: 11
  variables:
    mu: {{dist: lognormal, median: 0.25, sigma: 0.3}}
report: {{quantiles: [0.05, 0.5, 0.95], outputs: [G4.slip]}}
""")
    toml, yaml = load_spec(tmp_path / "mc.toml"), load_spec(tmp_path / "mc.yaml")
    assert toml == {**yaml, "fmu": str(fmu_path)}  # the same spec in both languages

    def run(spec):
        return subprocess.run([sys.executable, "-m", "membrane_contact.study", str(tmp_path / spec), "--workers", "1",
                               "--out", str(tmp_path / "mc")], capture_output=True, text=True, env=package_env(),
                              cwd=tmp_path)

    r = run("mc.toml")
    assert r.returncode == 0, r.stderr
    assert "6 cases in" in r.stdout and "6 ran through, 0 refused" in r.stdout, r.stdout
    assert "study: 6/6 cases done, 0 failed" in r.stderr  # plain progress lines: not a terminal
    # The YAML spec is the same study: on the same directory, nothing is left to run.
    again = run("mc.yaml")
    assert again.returncode == 0 and "all 6 cases already stored" in again.stderr, again.stderr
    assert again.stdout == r.stdout and "| G4.slip |" in r.stdout
    # The quantiles are those of the stored cases' last step.
    ds = Study(fmu_path, monte_carlo({"mu": {"dist": "lognormal", "median": 0.25, "sigma": 0.3}}, 6, 11),
               path_from_spec({"steps": 3, "to": {"frame.dz": -0.15}}, tmp_path), ["G2.slip", "G4.slip"],
               directory=tmp_path / "mc").dataset()
    q = np.quantile(ds["G4.slip"].isel(step=-1).values, [0.05, 0.5, 0.95])
    assert r.stdout.split("| G4.slip |")[1].split("|")[:3] == [f" {x:.6g} " for x in q]
    (tmp_path / "typo.toml").write_text((tmp_path / "mc.toml").read_text().replace("outputs =", "output ="))
    r = subprocess.run([sys.executable, "-m", "membrane_contact.study", str(tmp_path / "typo.toml")],
                       capture_output=True, text=True, env=package_env(), cwd=tmp_path)
    assert r.returncode == 2 and "unknown keys output" in r.stderr, r.stderr


@pytest.mark.parametrize("spec", ["study_mu_prestress.toml", "study_two_arches_mc.yaml"])
def test_the_example_specs_name_variables_their_fmus_have(spec, fmu_path):
    spec_path = ROOT / "examples" / spec
    loaded = load_spec(spec_path)
    design = design_from_spec(loaded["design"], spec_path.parent)
    path = path_from_spec(loaded["path"], spec_path.parent)
    if "mesh" in loaded:  # checked against the names the mapping gives (packing needs fmu-pack)
        mapping = json.loads((spec_path.parent / loaded["mapping"]).read_text())
        prefixes = {g["prefix"] for g in mapping["physical_groups"].values() if g["role"] == "gaps"}
        assert all(o.split(".")[0].rstrip("0123456789") in prefixes for o in loaded["report"]["outputs"])
        assert set(design) == {"mu"} and len(design["mu"]) == loaded["design"]["cases"]
        return
    check_variables(fmu_path, design, path, loaded.get("parameters", {}), loaded["outputs"])
    assert len(design["mu"]) == 4 * 3 * 3


# ---------------------------------------------------------------------------- a study directory cannot be corrupted
# (issue 47 items 4 and 11)

SMALL_PATH = {"time": [1.0], "frame.dz": [-0.1]}
SMALL_DESIGN = {"mu": [0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45]}


def started_cases(run_log: Path, after: int = 0) -> list[int]:
    return [int(line.split()[0]) for line in run_log.read_text().splitlines()[after:]] if run_log.exists() else []


@pytest.fixture(scope="module")
def small_study(fmu_path, two_workers, tmp_path_factory):
    """8 cases of one step, stored; the directory's files as they were (to copy for each test)."""
    directory = tmp_path_factory.mktemp("small") / "study"
    ds = Study(fmu_path, SMALL_DESIGN, SMALL_PATH, ["G2.slip", "frame.Rz"], directory=directory).run(
        two_workers, progress=False)
    assert (ds.status == "ok").all()
    return directory, ds


def small_copy(small_study, tmp_path) -> Path:
    import shutil

    directory = tmp_path / "study"
    shutil.copytree(small_study[0], directory)
    return directory


def test_a_resume_runs_exactly_the_missing_cases_when_the_stored_case_ids_have_gaps(fmu_path, small_study,
                                                                                   two_workers, tmp_path):
    directory = small_copy(small_study, tmp_path)
    for case in (1, 3, 4):  # gaps below the largest stored id (7)
        (directory / "cases" / f"case-{case:06d}.parquet").unlink()
    run_log = tmp_path / "run.log"
    ds = Study(fmu_path, SMALL_DESIGN, SMALL_PATH, ["G2.slip", "frame.Rz"], directory=directory,
               run_log=run_log).run(two_workers, progress=False)
    assert sorted(started_cases(run_log)) == [1, 3, 4]
    assert identical(ds, small_study[1])


def test_a_damaged_or_foreign_case_file_is_run_again_with_a_warning_not_taken_as_done(fmu_path, small_study,
                                                                                       two_workers, tmp_path):
    directory = small_copy(small_study, tmp_path)
    cases = directory / "cases"
    truncated = cases / "case-000002.parquet"
    truncated.write_bytes(truncated.read_bytes()[:100])
    (cases / "case-000005.parquet").write_bytes(b"")
    (cases / "case-000007.parquet").write_bytes((cases / "case-000000.parquet").read_bytes())  # case 0's result
    run_log = tmp_path / "run.log"
    with pytest.warns(UserWarning) as caught:
        ds = Study(fmu_path, SMALL_DESIGN, SMALL_PATH, ["G2.slip", "frame.Rz"], directory=directory,
                   run_log=run_log).run(two_workers, progress=False)
    said = "\n".join(str(w.message) for w in caught)
    assert "case-000002.parquet cannot be read" in said and "case-000005.parquet cannot be read" in said
    assert "case-000007.parquet holds the result of case 0, not of case 7" in said
    assert sorted(started_cases(run_log)) == [2, 5, 7]
    assert identical(ds, small_study[1])
    assert sorted(p.name for p in cases.glob("*.invalid")) == [f"case-00000{k}.parquet.invalid" for k in (2, 5, 7)]


def test_a_nan_in_a_design_table_runs_on_a_fresh_directory_and_resumes_as_the_same_study(fmu_path, two_workers,
                                                                                         tmp_path):
    (tmp_path / "design.csv").write_text("mu\n0.3\nnan\n")
    design = design_from_spec({"kind": "table", "csv": "design.csv"}, tmp_path)
    ds = Study(fmu_path, design, SMALL_PATH, ["G2.slip"], directory=tmp_path / "s").run(two_workers, progress=False)
    assert list(ds.status.values) == ["ok", "error"] and "not finite" in ds.message.values[1]
    again = Study(fmu_path, design, SMALL_PATH, ["G2.slip"], directory=tmp_path / "s").run(two_workers, progress=False)
    assert identical(again, ds)


def test_a_design_table_naming_a_column_twice_is_refused_naming_it(tmp_path):
    (tmp_path / "design.csv").write_text("mu,film.E,mu\n0.3,1e9,0.4\n")
    with pytest.raises(ValueError, match="names the column 'mu' more than once"):
        design_from_spec({"kind": "table", "csv": "design.csv"}, tmp_path)
    (tmp_path / "path.csv").write_text("time,frame.dz,frame.dz\n1,-0.1,-0.2\n")
    with pytest.raises(ValueError, match="names the column 'frame.dz' more than once"):
        path_from_spec({"csv": "path.csv"}, tmp_path)


def test_a_second_driver_on_a_directory_is_refused_naming_the_first_ones_process_and_touches_nothing(
        fmu_path, tmp_path):
    script = tmp_path / "resume.py"
    script.write_text(RESUME)
    directory, run_log = tmp_path / "study", tmp_path / "run.log"
    args = [sys.executable, str(script), str(fmu_path), str(directory), str(run_log)]
    first = subprocess.Popen(args, env=package_env(), start_new_session=True, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        while not started_cases(run_log):
            assert first.poll() is None, first.stderr.read().decode()
            assert time.monotonic() < deadline
            time.sleep(0.01)
        design = factorial({"mu": [0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45], "film.prestressX": [0.5e6, 1e6]})
        path = {"time": [0.25, 0.5, 0.75, 1.0], "frame.dz": [-0.0375, -0.075, -0.1125, -0.15]}
        partial = directory / "cases" / "case-000099.part"  # stands for the first driver's file being written
        partial.write_bytes(b"being written")
        second = Study(fmu_path, design, path, ["G2.slip", "G4.slip"], {"solver.incrementsPerStep": 20},
                       directory=directory, run_log=tmp_path / "second.log")
        with pytest.raises(RuntimeError, match=rf"in use by another study driver \(process {first.pid} on "):
            second.run(workers=1, progress=False)
        assert partial.read_bytes() == b"being written" and not (tmp_path / "second.log").exists()
    finally:
        os.killpg(first.pid, signal.SIGKILL)
        first.wait()
    # the killed driver's lock went with its process: a driver resumes the study
    ds = second.run(workers=1, progress=False)
    assert (ds.status == "ok").all()


def test_the_largest_slip_per_support_of_each_case_is_the_largest_magnitude_over_its_gaps_and_steps(one_worker):
    from membrane_contact.study import largest_slips

    _, ds = one_worker
    found = largest_slips(ds)
    assert set(found.data_vars) == {"G", "G.where"}  # G2, G4, G6: the specimen's one support
    gaps = ["G2", "G4", "G6"]
    for case in range(ds.sizes["case"]):
        values = np.stack([ds[f"{g}.slip"].values[case] for g in gaps], axis=1)
        step, k = np.unravel_index(np.argmax(np.abs(values)), values.shape)
        assert found["G"].values[case] == values[step, k] != 0.0
        assert found["G.where"].values[case] == gaps[k]
    mine = largest_slips(ds, {"edge": ["G2"], "middle": ["G4", "G6"]})
    np.testing.assert_array_equal(np.abs(mine["edge"].values), np.max(np.abs(ds["G2.slip"].values), axis=1))
