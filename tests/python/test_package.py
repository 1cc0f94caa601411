"""The Python package ``membrane_contact`` (issue 9 item 3) over the FMUs of this checkout.

TEST GOAL: the package is installed in the venv (``pip install ./python``) and importable from
anywhere; ``Film`` sets and reads variables by name, and refuses unknown names and bad values
with the FMU's message; ``Film.run`` steps a staged table to the same outputs as stepping by
hand with the same inputs; a step the FMU refuses (fmi2Discard) is halved until it passes, and
the result equals a hand-stepped run over the same sub-steps, bit for bit; when even the
smallest step is refused, ``StepRefused`` names the time and the FMU's reason and the film
stays at its last converged state; ``save``/``restore`` and ``serialize``/``deserialize`` roll
back exactly; results are numpy arrays (slips along the support, reactions); the plotting
helpers draw slip, reactions (against an input column too) and a stress map from the VTK the
FMU writes. Named values round-trip for every variable type, keyword form included. A refused
step is rolled back with fmi2SetFMUstate to the state saved before it (the FMI 2.0 way; the
same answer as trusting this FMU to keep its state); split steps keep ``mu`` at the row's value
(the FMU applies it unramped); ``dt`` splits rows into steps with the inputs interpolated
linearly, and the inputs reached are recorded beside the outputs. README.md's package block
runs as written.

MODELS: the ParallelArch FMU (300 mm, frame lowered to −H/2) and the hinged panel example.
"""

from __future__ import annotations

import subprocess
from pathlib import Path
import sys

import numpy as np
import pandas as pd  # a test requirement (tests/python/requirements.txt): required, never skipped
import pytest
from conftest import INSTALLED, ROOT, pack, package_env

from membrane_contact import Film, FmuError, Results, StepRefused, build_fmu, find_fmu
from membrane_contact.film import DISCARD, OK

TARGET = -0.15


def test_the_package_is_installed_in_the_venv_and_importable_from_anywhere(tmp_path):
    r = subprocess.run([sys.executable, "-c", "import membrane_contact, sys; print(membrane_contact.__file__, "
                        "membrane_contact.__version__)"], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    path, version = r.stdout.split()
    assert "site-packages" in path and version == cargo_version()
    r = subprocess.run([sys.executable, "-c", "import membrane_contact.mesh, membrane_contact.arches, "
                        "membrane_contact.plot"], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_the_tests_import_the_package_under_test():
    """The checkout's python/ (tests/run.sh's .venv), or installed (MEMBRANE_CONTACT_INSTALLED=1,
    tests/wheel/run.sh), the wheel's copy in the venv's site-packages, never the checkout's."""
    import membrane_contact

    package = Path(membrane_contact.__file__).resolve()
    if INSTALLED:
        assert package.is_relative_to(Path(sys.prefix).resolve()) and "site-packages" in package.parts, package
        assert not package.is_relative_to(ROOT / "python"), package
    else:
        assert package == ROOT / "python" / "membrane_contact" / "__init__.py"


def test_names_in_and_out_and_bad_values_refused_with_the_fmus_message(fmu_path):
    with Film(fmu_path) as film:
        assert "frame.dz" in film.inputs and "G4.slip" in film.outputs and "film.E" in film.parameters
        assert film.gaps == [f"G{i}" for i in range(1, 10)]
        film.initialize(parameters={"archHeight": 0.3}, inputs={"mu": 0.3})
        assert film["mu"] == 0.3 and film.get("archHeight", "mu") == [0.3, 0.3]
        with pytest.raises(KeyError, match="'frame.dq' is not a variable of ParallelArch"):
            film.set({"frame.dq": 1.0})
        with pytest.raises(FmuError, match=r"fmi2SetReal returned fmi2Error: .*frame\.dz = NaN"):
            film.set({"frame.dz": float("nan")})
        assert film.step(0.5) == OK and film.time == 0.5


def test_named_values_round_trip_for_every_type_also_as_keywords(fmu_path):
    with Film(fmu_path) as film:
        # Keyword form with dotted names, one of each type: Real, Integer, Boolean, String.
        film.set(**{"film.E": 1.1e9, "solver.maxIterations": 40, "film.wrinkling": True,
                    "results.vtkFormat": "ascii"})
        with pytest.raises(FmuError, match="fmi2GetReal must not be called in state Instantiated"):
            film.get("film.E")
        film.initialize(inputs={"mu": 0.25})
        assert film.get("film.E", "solver.maxIterations", "film.wrinkling", "results.vtkFormat") == [
            1.1e9, 40, True, "ascii"]
        film.set(**{"frame.dz": -0.01}, mu=0.3)
        assert film["frame.dz"] == -0.01 and film["mu"] == 0.3
        assert film.step(0.5) == OK
        outputs = film.values()
        assert list(outputs) == film.outputs and outputs["frame.Rz"] == film["frame.Rz"] != 0.0
        assert isinstance(outputs["G1.status"], int) and isinstance(outputs["G1.slip"], float)


def by_hand(fmu_path, times, dz, parameters=None, mu=None):
    with Film(fmu_path) as film:
        film.initialize(parameters=parameters)
        t = 0.0
        for ti, zi in zip(times, dz):
            film.set({"frame.dz": zi, **({"mu": mu} if mu is not None else {})})
            assert film.step(ti - t) == OK
            t = ti
        return film.values()


def test_staged_table_reaches_what_stepping_by_hand_reaches(fmu_path):
    times, dz = [0.25, 0.5, 0.75, 1.0], [TARGET * f for f in (0.25, 0.5, 0.75, 1.0)]
    with Film(fmu_path) as film:
        # Rows at or before the current time are where the film is: skipped.
        results = film.run({"time": [0.0, *times], "frame.dz": [0.0, *dz]})
        assert isinstance(results, Results) and results.steps == 4 and results.halvings == 0
        np.testing.assert_array_equal(results.time, [0.0, *times])
        final = film.values()
    assert final == by_hand(fmu_path, times, dz)
    # Other table shapes give the same steps.
    for table in ([{"time": t, "frame.dz": z} for t, z in zip(times, dz)],
                  np.array(list(zip(times, dz)), dtype=[("time", float), ("frame.dz", float)]),
                  pd.DataFrame({"time": times, "frame.dz": dz})):
        with Film(fmu_path) as film:
            film.run(table)
            assert film.values() == final
    names, slips = results.slips()
    assert names == [f"G{i}" for i in range(1, 10)] and slips.shape == (5, 9)
    assert slips[-1, 3] == final["G4.slip"]
    assert results.reaction("frame")[-1, 2] == final["frame.Rz"]
    # One array per output and per input column, one value per point (start + 4 steps).
    assert results["G4.slip"].shape == results["frame.dz"].shape == results.time.shape == (5,)
    assert results.reaction("frame").shape == (5, 3)
    np.testing.assert_array_equal(results["frame.dz"], [0.0, *dz])
    data = results.as_dict(inputs=True)
    assert len(data) == 1 + len(film.outputs) + 1 and all(v.shape == (5,) for v in data.values())
    with Film(fmu_path) as film:
        with pytest.raises(KeyError, match="column 'G1.slip' is an output, not an input"):
            film.run({"time": [1.0], "G1.slip": [0.0]})
        with pytest.raises(ValueError, match="times must increase"):
            film.run({"time": [1.0, 0.5], "frame.dz": [0.0, 0.0]})


# One increment per step, no cut-backs inside the FMU, few iterations: lowering the frame to its
# target in one step is refused, and so are its halves down to 1/32 of it.
# A jump to TARGET in one increment is refused with these settings (the viscous stabilization,
# the last resort of a step, would converge it carrying its damping force: off here).
HARD = {"solver.incrementsPerStep": 1, "solver.maxCutbacks": 0, "solver.maxIterations": 10,
        "solver.stabilization": False}


def test_a_refused_step_raises_nothing_but_returns_discard_and_is_logged(fmu_path, capsys):
    with Film(fmu_path, echo=True) as film:
        film.initialize(parameters=HARD)
        before = film.values()
        film.set({"frame.dz": TARGET})
        assert film.step(1.0) == DISCARD
        assert film.time == 0.0 and film.values() == before
        (refusal,) = [m for s, _, m in film.messages if s == DISCARD]
        assert "did not converge" in refusal
        assert f"fmi2Discard: {refusal}" in capsys.readouterr().out
        film.set({"frame.dz": TARGET / 32})
        assert film.step(1 / 32) == OK and film.time == 1 / 32


def test_a_refused_step_is_halved_until_it_passes_and_equals_those_steps_by_hand(fmu_path):
    with Film(fmu_path) as film:
        film.initialize(parameters=HARD)
        # Count the rollbacks the FMU sees (fmpy's raw function table).
        set_state = film.fmu._functions["fmi2SetFMUstate"]
        calls = []
        film.fmu._functions["fmi2SetFMUstate"] = lambda *a: calls.append(a) or set_state(*a)
        results = film.run({"time": [1.0], "frame.dz": [TARGET]})
        assert results.halvings == 3 and results.steps == 4
        assert results.rollbacks == len(calls) == 3
        assert sum(1 for s, _, m in film.messages if s == DISCARD) == 3
        np.testing.assert_allclose(results.time, [0, 1 / 8, 1 / 4, 1 / 2, 1])
        assert film.time == 1.0
        final = film.values()
    times = list(results.time[1:])
    assert final == by_hand(fmu_path, times, [TARGET * t for t in times], HARD)
    # Without the rollback (the FMU keeps its last converged state itself): the same answer.
    with Film(fmu_path) as film:
        film.initialize(parameters=HARD)
        again = film.run({"time": [1.0], "frame.dz": [TARGET]}, rollback=False)
        assert again.rollbacks == 0 and again.halvings == 3 and film.values() == final


def test_split_steps_keep_mu_at_the_rows_value(fmu_path):
    # mu is applied as it is over a step, not ramped: halving must not average it.
    with Film(fmu_path) as film:
        film.initialize(parameters=HARD, inputs={"mu": 0.2})
        results = film.run({"time": [1.0], "frame.dz": [TARGET], "mu": [0.4]})
        assert results.halvings > 0 and set(results["mu"][1:]) == {0.4}
        final = film.values()
    times = list(results.time[1:])
    assert final == by_hand(fmu_path, times, [TARGET * t for t in times], HARD, mu=0.4)


def test_dt_splits_rows_into_steps_with_inputs_interpolated_linearly(fmu_path):
    with Film(fmu_path) as film:
        results = film.run({"time": [0.5, 1.0], "frame.dz": [TARGET / 2, TARGET]}, dt=0.125)
        assert results.steps == 8 and results.halvings == 0
        np.testing.assert_array_equal(results.time, np.arange(9) / 8)
        np.testing.assert_allclose(results["frame.dz"], TARGET * results.time, rtol=1e-15, atol=0)
        final = film.values()
    assert final == by_hand(fmu_path, list(results.time[1:]), list(results["frame.dz"][1:]))
    with Film(fmu_path) as film, pytest.raises(ValueError, match="dt = 0 must be > 0"):
        film.run({"time": [1.0], "frame.dz": [TARGET]}, dt=0)


def test_a_step_refused_after_every_halving_raises_and_keeps_the_last_state(fmu_path):
    with Film(fmu_path) as film:
        film.initialize(parameters={**HARD, "solver.maxIterations": 3})
        before = film.values()
        with pytest.raises(StepRefused, match=r"from t = 0 toward t = 0.125 even after 3 halvings .*did not converge"):
            film.run({"time": [1.0], "frame.dz": [TARGET]}, max_halvings=3)
        assert film.time == 0.0 and film.values() == before
    # Refused after some steps passed: the film stays at the last converged one, and the
    # exception names its time and carries the FMU's log.
    with Film(fmu_path) as film:
        film.initialize(parameters=HARD)
        film.run({"time": [0.25], "frame.dz": [TARGET / 4]})
        at_quarter = film.values()
        with pytest.raises(StepRefused, match=r"from t = 0.25 toward t = 0.625 even after 1 halvings") as refused:
            film.run({"time": [1.0], "frame.dz": [4 * TARGET]}, max_halvings=1)
        assert film.time == 0.25 and film.values() == at_quarter and film["frame.dz"] == TARGET / 4
        assert refused.value.time == 0.25 and any(s == DISCARD for s, _, _ in refused.value.messages)


def test_save_restore_and_serialized_states_roll_back_exactly(fmu_path):
    with Film(fmu_path) as film:
        film.run({"time": [0.5], "frame.dz": [TARGET / 2]})
        state = film.save()
        at_save = film.values()
        data = film.serialize(state)
        film.run({"time": [1.0], "frame.dz": [TARGET]})
        reference = film.values()
        film.restore(state)
        assert film.time == 0.5 and film.values() == at_save
        film.run({"time": [1.0], "frame.dz": [TARGET]})
        assert film.values() == reference
        again = film.deserialize(data, time=0.5)
        film.restore(again)
        assert film.values() == at_save
        film.free(state)
        with pytest.raises(ValueError, match="not a state saved by this film"):
            film.restore(state)


def test_plots_draw_slip_reactions_and_a_stress_map(fmu_path, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    from membrane_contact import plot

    vtk = tmp_path / "vtk"
    with Film(fmu_path) as film:
        film.initialize(parameters={"results.directory": str(vtk)})
        results = film.run({"time": [0.5, 1.0], "frame.dz": [TARGET / 2, TARGET]})
    ax = plot.slip_along_support(results, times=[0.5, 1.0])
    assert len(ax.lines) == 2 and list(ax.lines[1].get_ydata()) == list(results.slips()[1][-1] * 1e3)
    ax = plot.reactions_vs_load(results, "time", "frame", components="z")
    assert list(ax.lines[0].get_ydata()) == list(results["frame.Rz"])
    ax = plot.reactions_vs_load(results, "frame.dz", "frame")
    assert list(ax.lines[0].get_xdata()) == [0.0, TARGET / 2, TARGET] and len(ax.lines) == 3
    ax = plot.stress_map(vtk / "ParallelArch_film_0002.vtu")
    assert len(ax.collections) == 1 and ax.collections[0].get_array().max() > 1.0  # MPa
    ax.figure.savefig(tmp_path / "map.png")
    assert (tmp_path / "map.png").stat().st_size > 1000


def test_results_as_pandas_and_other_models(tmp_path):
    fmu = pack(ROOT / "examples" / "hinged_panel.json", tmp_path)
    with Film(fmu) as film:
        results = film.run({"time": [0.5, 1.0], "rail.angle": [0.05, 0.1], "snow.pressure": [-50, -100]},
                           outputs=["rail.moment", "mid.uz"])
    frame = results.to_pandas()
    assert list(frame.columns) == ["rail.moment", "mid.uz"] and isinstance(frame, pd.DataFrame)
    both = results.to_pandas(inputs=True)
    assert list(both.columns) == ["rail.moment", "mid.uz", "rail.angle", "snow.pressure"]
    assert list(both["rail.angle"]) == [0.0, 0.05, 0.1] and list(both.index) == [0.0, 0.5, 1.0]


def test_build_fmu_packs_a_model_file_or_dict_and_reports_a_refused_model(tmp_path):
    import json

    fmu = build_fmu(ROOT / "examples" / "hinged_panel.json", out_dir=tmp_path / "a")
    assert fmu == tmp_path / "a" / "HingedPanel.fmu" and fmu.is_file()
    model = json.loads((ROOT / "examples" / "hinged_panel.json").read_text())
    model["name"] = "PanelFromDict"
    fmu = build_fmu(model, out_dir=tmp_path / "b")
    with Film(fmu) as film:
        assert film.md.coSimulation.modelIdentifier == "PanelFromDict" and "rail.angle" in film.inputs
    model["material"]["youngs_modulus"] = -1.0
    with pytest.raises(RuntimeError, match=r"fmu-pack failed: .*must be > 0"):
        build_fmu(model, out_dir=tmp_path / "c")
    assert not (tmp_path / "c" / "PanelFromDict.fmu").exists()


@pytest.fixture
def repository(fmu_path, tmp_path, monkeypatch) -> Path:
    """The repository find_fmu looks into: this checkout, or installed (no checkout around the
    package), one made in a temporary directory holding the specimen FMU, the current directory."""
    if not INSTALLED:
        return ROOT
    repo = tmp_path / "repository"
    (repo / "fmu").mkdir(parents=True)
    (repo / "Cargo.toml").write_text("")
    (repo / "target" / "fmu").mkdir(parents=True)
    (repo / "target" / "fmu" / "ParallelArch.fmu").write_bytes(fmu_path.read_bytes())
    monkeypatch.chdir(repo)
    return repo


def test_find_fmu_says_how_to_make_one_when_there_is_none(repository, monkeypatch):
    monkeypatch.delenv("MEMBRANE_CONTACT_FMU", raising=False)
    assert find_fmu().name == "ParallelArch.fmu"
    with pytest.raises(FileNotFoundError, match="pack it with"):
        find_fmu(model="NoSuchModel")


def test_find_fmu_takes_a_path_then_the_environment_then_the_repository(fmu_path, repository, tmp_path,
                                                                        monkeypatch):
    copy = tmp_path / "Copy.fmu"
    copy.write_bytes(fmu_path.read_bytes())
    monkeypatch.setenv("MEMBRANE_CONTACT_FMU", str(copy))
    assert find_fmu() == copy and find_fmu(fmu_path) == fmu_path
    with Film() as film:
        assert film.path == copy
    monkeypatch.setenv("MEMBRANE_CONTACT_FMU", str(tmp_path / "gone.fmu"))
    with pytest.raises(FileNotFoundError, match="gone.fmu: no such FMU"):
        find_fmu()
    monkeypatch.delenv("MEMBRANE_CONTACT_FMU")
    assert find_fmu().resolve() == (repository / "target" / "fmu" / "ParallelArch.fmu").resolve()


def test_the_readme_python_package_block_runs_as_written(fmu_path, monkeypatch):
    import matplotlib

    matplotlib.use("Agg")
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## Python package"):]
    block = section[section.index("```python") + len("```python"):section.index("```\n\n")]
    monkeypatch.chdir(ROOT)
    if INSTALLED:  # the block's other source of the FMU: no target/fmu beside the wheel
        monkeypatch.setenv("MEMBRANE_CONTACT_FMU", str(fmu_path))
    else:
        monkeypatch.delenv("MEMBRANE_CONTACT_FMU", raising=False)
    scope = {}
    exec(compile(block, "README.md", "exec"), scope)
    assert scope["names"] == [f"G{i}" for i in range(1, 10)] and scope["slips"].shape == (21, 9)
    np.testing.assert_allclose(scope["results"]["frame.dz"], -0.15 * scope["results"].time, rtol=1e-14)


def cargo_version() -> str:
    import re

    return re.search(r'(?m)^version\s*=\s*"([^"]+)"', (ROOT / "Cargo.toml").read_text()).group(1)


# ---------------------------------------------------------------------------- packaging conventions (issue 47 item 10)


def test_the_package_has_one_version_cargos_and_declares_its_types(tmp_path):
    import importlib.metadata

    import membrane_contact

    assert membrane_contact.__version__ == cargo_version()
    if INSTALLED:
        assert importlib.metadata.version("membrane-contact") == cargo_version()
    assert (Path(membrane_contact.__file__).parent / "py.typed").is_file()
    if not INSTALLED:
        # taken from Cargo.toml, not written a second time: a checkout whose Cargo.toml says
        # another version makes another __version__
        import shutil

        other = tmp_path / "checkout"
        shutil.copytree(ROOT / "python" / "membrane_contact", other / "python" / "membrane_contact",
                        ignore=shutil.ignore_patterns("__pycache__"))
        text = (ROOT / "Cargo.toml").read_text().replace(f'version = "{cargo_version()}"', 'version = "9.8.7"', 1)
        (other / "Cargo.toml").write_text(text)
        r = subprocess.run([sys.executable, "-c", "import membrane_contact; print(membrane_contact.__version__)"],
                           cwd=tmp_path, capture_output=True, text=True,
                           env={**package_env(), "PYTHONPATH": str(other / "python")})
        assert r.returncode == 0 and r.stdout.strip() == "9.8.7", r.stderr
    # the public API is annotated
    import inspect

    for name in ("find_fmu", "build_fmu"):
        assert inspect.signature(getattr(membrane_contact, name)).return_annotation != inspect.Signature.empty, name


def test_the_importer_is_a_console_script_of_the_distribution_not_a_patched_path():
    import importlib.metadata

    scripts = {e.name: e.value for e in importlib.metadata.entry_points(group="console_scripts")
               if e.dist is not None and e.dist.name.replace("_", "-") == "membrane-contact"}
    assert scripts.get("membrane-contact-import") == "membrane_contact.mesh:main", scripts
    import membrane_contact.mesh as mesh

    assert "sys.path.insert" not in Path(mesh.__file__).read_text()


def test_study_and_inverse_import_neither_each_other_and_run_one_case_alike(fmu_path):
    for first, second in (("inverse", "study"), ("study", "inverse")):
        r = subprocess.run([sys.executable, "-c", f"import sys, membrane_contact.{first}; "
                            f"print('membrane_contact.{second}' in sys.modules)"],
                           capture_output=True, text=True, env=package_env())
        assert r.returncode == 0 and r.stdout.strip() == "False", (first, second, r.stderr, r.stdout)
    # the names user scripts import from study stay where they were
    from membrane_contact import cases, cluster, inverse, study

    assert study.Runner is cluster.Runner and study.cluster is cluster.cluster and study.apply_values is cases.apply_values
    assert inverse.read_path is cases.read_path
    # one case, one code: the inverse tool's model evaluation is the study's case
    path = {"time": [0.5, 1.0], "frame.dz": [-0.05, -0.1]}
    fitted = inverse._run(fmu_path, path, {}, [inverse.Unknown("mu", 0.25)], [0.25], ["G2.slip", "frame.Rz"])
    case = study.run_case(fmu_path, 0, {"mu": 0.25}, path, {}, ["G2.slip", "frame.Rz"], {"mu": "input"})
    assert case["status"] == "ok"
    np.testing.assert_array_equal(case["values"][-1], fitted)
