"""VTK output of the FMU: the String parameter ``results.directory``.

TEST GOAL: ``results.directory`` is a fixed String parameter with start "" in every FMU (the
specimen and a user model); set through fmpy's ``setString`` before
``exitInitializationMode``, it makes the instance write ``<id>_film_0000.vtu`` and
``<id>_gaps_0000.vtu`` (the initial state) and one of each per step, which meshio reads, and
``<id>_film.pvd`` / ``<id>_gaps.pvd`` that list them with the FMU's times; the directory is
created; a write that fails returns fmi2Warning with a ``logStatusWarning`` message and the step
stands; the empty default writes nothing. ``results.vtkFormat`` (``binary``, the default, or
``ascii``) changes the encoding only: meshio reads the same arrays from both, and they agree
with the FMU's outputs (largest von Mises stress, gap slips, normal forces, statuses).

MODELS: ParallelArch.fmu and CustomArch.fmu (see conftest.py).

BOUNDARY CONDITIONS: the group's ``dz`` ramped to −0.15 m over [0, 1]; only the first steps run.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest
from fmpy import read_model_description
from fmu_helpers import OK, WARNING, FMICallException, Slave

STEPS = 10
TARGET = -0.15


def string_parameter(fmu):
    md = read_model_description(str(fmu))
    (v,) = [x for x in md.modelVariables if x.name == "results.directory"]
    return md, v


@pytest.mark.parametrize("which", ["fmu_path", "custom_fmu"])
def test_results_directory_is_a_fixed_string_parameter(which, request):
    md, v = string_parameter(request.getfixturevalue(which))
    assert (v.type, v.causality, v.variability, v.initial, v.start) == ("String", "parameter", "fixed", "exact", "")
    # Only says where files go: no output depends on it.
    assert all(v not in (u.dependencies or []) for u in md.initialUnknowns + md.outputs)


@pytest.mark.parametrize("which", ["fmu_path", "custom_fmu"])
def test_vtk_format_is_a_fixed_string_parameter_defaulting_to_binary(which, request):
    md = read_model_description(str(request.getfixturevalue(which)))
    (v,) = [x for x in md.modelVariables if x.name == "results.vtkFormat"]
    assert (v.type, v.causality, v.variability, v.start) == ("String", "parameter", "fixed", "binary")
    assert all(v not in (u.dependencies or []) for u in md.initialUnknowns + md.outputs)


def start(fmu, directory, parameters=None):
    """An instance in initialization mode with ``results.directory`` set; returns it and the
    status of ``exitInitializationMode``."""
    s = Slave(fmu)
    s.fmu.setupExperiment(startTime=0.0)
    s.fmu.enterInitializationMode()
    vr = s.vr("results.directory")
    s.fmu.setString([vr], [str(directory)])
    assert s.fmu.getString([vr]) == [str(directory).encode()]
    s.set({"solver.incrementsPerStep": 2, **(parameters or {})})
    status = s.call("fmi2ExitInitializationMode", s.c)
    return s, status


def vtu_points(path):
    mesh = meshio.read(path)
    assert len(mesh.points) > 0
    return mesh.points.ravel().tolist()


def pvd_entries(path):
    root = ET.parse(path).getroot()
    assert (root.tag, root.get("type")) == ("VTKFile", "Collection")
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


@pytest.mark.parametrize("which, group", [("fmu_path", "frame"), ("custom_fmu", "rim")])
def test_every_step_is_written_and_listed(which, group, request, tmp_path):
    fmu = request.getfixturevalue(which)
    directory = tmp_path / "not yet there" / "vtk"
    s, status = start(fmu, directory)
    with s:
        assert status == OK, s.messages
        times = [s.get("time")]
        for k in range(3):
            s.set({f"{group}.dz": TARGET * (k + 1) / STEPS})
            assert s.step(k / STEPS, 1 / STEPS) == OK, s.messages[-3:]
            times.append(s.get("time"))
        model = s.md.coSimulation.modelIdentifier
    files = {b: [f"{model}_{b}_{k:04d}.vtu" for k in range(4)] for b in ("film", "gaps")}
    assert sorted(p.name for p in directory.iterdir()) == sorted(
        files["film"] + files["gaps"] + [f"{model}_film.pvd", f"{model}_gaps.pvd"])
    for block in ("film", "gaps"):
        entries = pvd_entries(directory / f"{model}_{block}.pvd")
        assert [f for _, f in entries] == files[block]
        assert [t for t, _ in entries] == pytest.approx(times, abs=1e-12)
    assert times[0] == 0.0 and times[-1] == pytest.approx(0.3)
    points = [vtu_points(directory / f) for f in files["film"]]
    assert points[0] != points[-1], "the film moved"


def test_a_failed_write_is_a_warning_and_the_step_stands(fmu_path, tmp_path):
    blocker = tmp_path / "a file"
    blocker.write_text("not a directory")
    s, status = start(fmu_path, blocker / "vtk")
    with s:
        assert status == WARNING
        assert any(st == WARNING and cat == "logStatusWarning" and "VTK output at t = 0 failed" in m
                   for st, cat, m in s.messages), s.messages
        s.set({"frame.dz": TARGET / STEPS})
        assert s.step(0.0, 1 / STEPS) == WARNING
        assert s.get("time") == pytest.approx(0.1) and s.get("G9.slip") != 0.0
        s.set({"frame.dz": 2 * TARGET / STEPS})
        assert s.step(0.1, 1 / STEPS) == WARNING
        assert s.get("time") == pytest.approx(0.2)


def test_the_empty_default_writes_nothing(fmu_path, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with Slave(fmu_path) as s:
        s.initialize()
        assert s.fmu.getString([s.vr("results.directory")]) == [b""]
        s.ramp({"frame.dz": TARGET}, STEPS, last=2)
    assert list(tmp_path.iterdir()) == []


def run_with_format(fmu, directory, vtk_format):
    """Three steps of the specimen with ``results.vtkFormat`` set; the outputs after the last."""
    s, status = start(fmu, directory, {"results.vtkFormat": vtk_format})
    with s:
        assert status == OK, s.messages
        assert s.fmu.getString([s.vr("results.vtkFormat")]) == [vtk_format.encode()]
        s.ramp({"frame.dz": TARGET}, STEPS, last=3)
        return s.outputs()


def test_meshio_reads_ascii_and_binary_alike_and_they_match_the_outputs(fmu_path, tmp_path):
    outputs = {f: run_with_format(fmu_path, tmp_path / f, f) for f in ("ascii", "binary")}
    assert outputs["ascii"] == outputs["binary"]
    out = outputs["binary"]
    meshes = {(f, b): meshio.read(tmp_path / f / f"ParallelArch_{b}_0003.vtu")
              for f in ("ascii", "binary") for b in ("film", "gaps")}
    assert b"AppendedData" in (tmp_path / "binary" / "ParallelArch_film_0003.vtu").read_bytes()
    assert b'format="ascii"' in (tmp_path / "ascii" / "ParallelArch_film_0003.vtu").read_bytes()
    for block in ("film", "gaps"):
        a, b = meshes["ascii", block], meshes["binary", block]
        np.testing.assert_array_equal(a.points, b.points)
        assert a.cell_data.keys() == b.cell_data.keys() and a.point_data.keys() == b.point_data.keys()
        for name in a.cell_data:
            np.testing.assert_array_equal(a.cell_data[name][0], b.cell_data[name][0])
        for name in a.point_data:
            np.testing.assert_array_equal(a.point_data[name], b.point_data[name])
    film, gaps = meshes["binary", "film"], meshes["binary", "gaps"]
    # Film: triangles only, no gap placeholders; the FMU's largest von Mises stress.
    assert [c.type for c in film.cells] == ["triangle"]
    vm = film.cell_data["von_mises"][0]
    assert vm.max() == out["film.maxEquivalentStress"] and vm.min() > 0
    assert film.cell_data["strain"][0].shape == (len(vm), 3)
    e1, e2 = film.cell_data["principal_strain_1"][0], film.cell_data["principal_strain_2"][0]
    assert np.all(e1 >= e2)
    # Displacement: the deformed points minus those of the initial state.
    initial = meshio.read(tmp_path / "binary" / "ParallelArch_film_0000.vtu")
    np.testing.assert_allclose(film.points - initial.points, film.point_data["displacement"],
                               atol=1e-15)
    # Gaps: one line per gap, in order, with the FMU's gap outputs.
    assert [c.type for c in gaps.cells] == ["line"]
    names = [f"G{k}" for k in range(1, 10)]
    cd = {k: v[0] for k, v in gaps.cell_data.items()}
    assert list(cd["gap_slip_x"]) == [out[f"{g}.slip"] for g in names]
    assert list(cd["gap_slip_y"]) == [out[f"{g}.slipY"] for g in names]
    assert list(cd["gap_normal_force"]) == [out[f"{g}.normalForce"] for g in names]
    assert list(cd["gap_status"]) == [out[f"{g}.status"] for g in names]
    # A gap's first point is its film node, as in the film file.
    nodes = cd["film_node"].astype(int)
    np.testing.assert_array_equal(gaps.points[:9], film.points[nodes])


def test_an_unknown_vtk_format_is_an_error(fmu_path):
    with Slave(fmu_path) as s:
        s.fmu.setupExperiment(startTime=0.0)
        s.fmu.enterInitializationMode()
        vr = s.vr("results.vtkFormat")
        with pytest.raises(FMICallException):
            s.fmu.setString([vr], ["xml"])
        assert any("unknown VTK format 'xml'" in m for _, _, m in s.messages), s.messages
        assert s.fmu.getString([vr]) == [b"binary"]


def test_curved_support_contacts_are_written_as_their_own_lines(tmp_path):
    """The CLI's VTK of a specimen on curved supports has a contacts file per state that meshio
    reads: one line per arch node from the film to its closest point on the pipe, with the slip
    along the arch and the forces (issue 10)."""
    import subprocess

    from conftest import CLI

    out = tmp_path / "vtk"
    run = subprocess.run([str(CLI), "specimen", "--contact", "curved-support", "--steps", "2", "--quiet",
                          "--vtk", str(out), "--vtk-format", "ascii"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    mesh = meshio.read(out / "ParallelArch_contacts_0002.vtu")
    lines = next(c.data for c in mesh.cells if c.type == "line")
    assert lines.shape == (9, 2)
    slip = mesh.cell_data["contact_slip"][0]
    travel = mesh.cell_data["contact_travel"][0]
    status = mesh.cell_data["contact_status"][0]
    # Travel along the arch grows from the crown to the foot; slip (slid in contact) is at most
    # the travel, and nothing where the film has not touched.
    assert travel[0] == pytest.approx(0.0, abs=1e-9) and np.all(np.diff(travel) > 0)
    touching = status > 0
    assert np.all(np.abs(slip) <= np.abs(travel) + 1e-12) and np.all(np.abs(slip[~touching]) < 1e-12)
    gap = mesh.cell_data["contact_gap"][0]
    assert np.all(gap[touching] < 0) and np.all(gap[~touching] >= 0)
    # The contact points lie on the pipe: the line lengths are the gaps.
    length = np.linalg.norm(mesh.points[lines[:, 0]] - mesh.points[lines[:, 1]], axis=1)
    np.testing.assert_allclose(length, np.abs(gap), rtol=1e-5, atol=1e-9)
    assert (out / "ParallelArch_contacts.pvd").is_file() and not (out / "ParallelArch_gaps.pvd").exists()
