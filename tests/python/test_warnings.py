"""The solver's warnings reach the user (issue 17, item 5).

TEST GOAL:
* a run whose film goes beyond the material's ``yield_stress`` warns the master: a
  ``SolverWarning`` through Python's ``warnings``, once per kind (not once per step), the FMU's
  message in ``Results.warnings`` and a one-line summary on stderr (none with ``quiet``);
  ``strict=True`` raises ``SolverWarningError`` at the first warning instead, the film at the
  step that warned;
* a model with E = 800 (MPa written as Pa) warns at ``fmu-pack`` (stderr, the CLI's text), at the
  FMU's initialization (a ``SolverWarning`` of the run) and in the mesh importer
  (``MeshImportWarning``), all from the core's one check;
* the importer passes a pressure set's ``towards`` on and reports the orientation the solver
  finds: the number of triangles turned is the number of the mesh's triangles whose node-order
  normal points down (counted here with numpy).

MODEL: the 200 mm specimen (``export-specimen``) with ``yield_stress`` = 2 MPa (the prestress is
0.5 MPa; lowering the frame by 50 mm raises the largest equivalent stress to several MPa), and the
gmsh example ``film_over_two_arches`` with a pressure set on its film.
"""

from __future__ import annotations

import json
import subprocess
import warnings

import numpy as np
import pytest
from conftest import CLI, ROOT, fmu_pack

from membrane_contact import Film, SolverWarning, SolverWarningError

EXAMPLE = ROOT / "examples" / "film_over_two_arches"
TABLE = {"time": [1.0, 2.0, 3.0], "frame.dz": [-0.01, -0.03, -0.05]}


def specimen(**material) -> dict:
    text = subprocess.run([str(CLI), "export-specimen", "--height", "200"], check=True, capture_output=True,
                          text=True).stdout
    model = json.loads(text)
    model["material"].update(material)
    return model


def pack(model: dict, tmp_path, name: str):
    model["name"] = name
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(model))
    r = fmu_pack(path, "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    return tmp_path / f"{name}.fmu", r.stderr


@pytest.fixture(scope="module")
def yielding_fmu(tmp_path_factory):
    path, stderr = pack(specimen(yield_stress=2e6), tmp_path_factory.mktemp("yield"), "YieldingArch")
    assert stderr == ""
    return path


def test_yield_warning_reaches_the_master_once_per_run(yielding_fmu, capsys):
    with Film(yielding_fmu) as film:
        with pytest.warns(SolverWarning, match="above the material's yield_stress 2.000 MPa") as caught:
            results = film.run(TABLE)
        stepped = [m for s, _, m in film.messages if s == 1]
    yields = [w for w in caught if "yield_stress" in str(w.message)]
    # Several steps went beyond the yield stress; the master hears of it once.
    assert len([m for m in stepped if "yield_stress" in m]) >= 2
    assert len(yields) == 1
    assert len(results.warnings) == 1 and "above the material's yield_stress" in results.warnings[0]
    assert results.warnings[0] in str(yields[0].message)
    assert max(results["film.maxEquivalentStress"]) > 2e6
    err = capsys.readouterr().err
    assert err.count("solver warning(s) in this run") == 1, err
    with Film(yielding_fmu, quiet=True) as film, warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        assert film.run(TABLE).warnings
    assert "solver warning" not in capsys.readouterr().err


def test_strict_raises_at_the_first_warning_and_the_film_stays_there(yielding_fmu):
    with Film(yielding_fmu) as film, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reference = film.run(TABLE, quiet=True)
    first = reference.time[np.argmax(reference["film.maxEquivalentStress"] > 2e6)]
    assert 0 < first < 3
    for strict_film, strict_run in ((True, None), (False, True)):
        with Film(yielding_fmu, strict=strict_film) as film:
            with pytest.raises(SolverWarningError, match="yield_stress") as raised:
                film.run(TABLE, strict=strict_run)
            assert film.time == first and raised.value.time == first
            assert film["film.maxEquivalentStress"] > 2e6


def test_modulus_in_mpa_warns_at_packing_at_initialization_and_in_the_importer(tmp_path):
    path, stderr = pack(specimen(youngs_modulus=800.0), tmp_path, "SoftArch")
    expected = "material youngs_modulus = 800 Pa looks like a value in MPa"
    assert f"warning: {expected}" in stderr
    with Film(path) as film:
        with pytest.warns(SolverWarning, match=expected):
            results = film.run({"time": [0.0]}, quiet=True)
    assert any(expected in w for w in results.warnings)
    # Initialized by the master before the run: warned then, and in the run's results.
    with Film(path) as film:
        with pytest.warns(SolverWarning, match=expected):
            film.initialize()
        results = film.run({"time": [0.0]}, quiet=True)
    assert any(expected in w for w in results.warnings)

    from membrane_contact.mesh import MeshImportWarning, import_mesh

    mapping = json.loads((EXAMPLE / "mapping.json").read_text())
    mapping["material"]["youngs_modulus"] = 800.0
    with pytest.warns(MeshImportWarning, match=expected):
        import_mesh(EXAMPLE / "film_over_two_arches_v22.msh", mapping)


def test_importer_passes_towards_on_and_reports_the_orientation_it_finds():
    from membrane_contact.mesh import MeshImportError, import_mesh

    mapping = json.loads((EXAMPLE / "mapping.json").read_text())
    film = mapping["physical_groups"]["film"]
    wind = {"role": "pressure", "name": "wind", "pressure": -100.0}
    mapping["physical_groups"]["film"] = [film, wind]
    report: list[str] = []
    model = import_mesh(EXAMPLE / "film_over_two_arches_v22.msh", mapping, report)
    nodes, triangles = np.array(model["nodes"]), np.array(model["triangles"])
    x = nodes[triangles]
    normals = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    down = int((normals[:, 2] < 0).sum())
    (line,) = report
    assert line.startswith(f"pressure set 'wind': {len(triangles)} triangles, a positive pressure pushes along "
                           "each triangle's node-order normal"), line
    mean_z = np.sign(normals[:, 2]).mean()  # a flat film: the mean pushed normal is ±z by area
    assert f"mean pushed normal [0.000, 0.000, {mean_z:.3f}]" in line or abs(mean_z) != 1, line

    wind["towards"] = "+z"
    report.clear()
    model = import_mesh(EXAMPLE / "film_over_two_arches_v22.msh", mapping, report)
    (wind_set,) = model["loads"]["pressures"]
    assert wind_set["towards"] == "+z"
    (line,) = report
    assert f"pushes towards [0.0, 0.0, 1.0]; {down} triangles' node-order normals point away from it" in line, line
    assert "mean pushed normal [0.000, 0.000, 1.000]; 0 triangles pushed against" in line, line

    wind["towards"] = "up"
    with pytest.raises(MeshImportError, match="towards 'up' is not one of"):
        import_mesh(EXAMPLE / "film_over_two_arches_v22.msh", mapping)
