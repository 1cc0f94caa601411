"""VTK output of the FMU: the String parameter ``results.directory``.

TEST GOAL: ``results.directory`` is a fixed String parameter with start "" in every FMU (the
specimen and a user model); set through fmpy's ``setString`` before
``exitInitializationMode``, it makes the instance write ``<id>_0000.vtu`` (the initial state)
and one ``<id>_NNNN.vtu`` per step, all well-formed VTK XML, and a ``<id>.pvd`` that lists them
with the FMU's times; the directory is created; a write that fails returns fmi2Warning with a
``logStatusWarning`` message and the step stands; the empty default writes nothing.

MODELS: ParallelArch.fmu and CustomArch.fmu (see conftest.py).

BOUNDARY CONDITIONS: the group's ``dz`` ramped to −0.15 m over [0, 1]; only the first steps run.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest
from fmpy import read_model_description
from fmu_helpers import OK, WARNING, Slave

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
    root = ET.parse(path).getroot()
    assert (root.tag, root.get("type")) == ("VTKFile", "UnstructuredGrid")
    piece = root.find("UnstructuredGrid/Piece")
    points = piece.find("Points/DataArray").text.split()
    assert len(points) == 3 * int(piece.get("NumberOfPoints")) > 0
    return [float(x) for x in points]


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
    files = [f"{model}_{k:04d}.vtu" for k in range(4)]
    assert sorted(p.name for p in directory.iterdir()) == sorted(files + [f"{model}.pvd"])
    entries = pvd_entries(directory / f"{model}.pvd")
    assert [f for _, f in entries] == files
    assert [t for t, _ in entries] == pytest.approx(times, abs=1e-12)
    assert times[0] == 0.0 and times[-1] == pytest.approx(0.3)
    points = [vtu_points(directory / f) for f in files]
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
