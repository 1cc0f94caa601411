"""The packed FMUs as files: schema-valid description, exported symbols, variables, packing.

TEST GOAL: ``fmpy.validation.validate_fmu`` finds nothing; the shared library exports every
FMI 2.0 function an importer binds; the variable table is the documented one and is derived
from the model file (names, start values); packing is deterministic; ``fmu-pack`` refuses a
bad model file with the core's message and writes nothing.

MODELS: ParallelArch.fmu (the paper's specimen, 300 mm) and CustomArch.fmu (a user model
file: the 200 mm specimen renamed, see conftest.py).
"""

from __future__ import annotations

import ctypes
import json
import zipfile

import pytest
from conftest import fmu_pack, pack
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu
from fmu_helpers import ERROR, callbacks_for

COMMON = """GetTypesPlatform GetVersion SetDebugLogging Instantiate FreeInstance SetupExperiment
EnterInitializationMode ExitInitializationMode Terminate Reset GetReal GetInteger GetBoolean
GetString SetReal SetInteger SetBoolean SetString GetFMUstate SetFMUstate FreeFMUstate
SerializedFMUstateSize SerializeFMUstate DeSerializeFMUstate GetDirectionalDerivative""".split()
CO_SIMULATION = """SetRealInputDerivatives GetRealOutputDerivatives DoStep CancelStep GetStatus
GetRealStatus GetIntegerStatus GetBooleanStatus GetStringStatus""".split()
MODEL_EXCHANGE = """EnterEventMode NewDiscreteStates EnterContinuousTimeMode CompletedIntegratorStep
SetTime SetContinuousStates GetDerivatives GetEventIndicators GetContinuousStates
GetNominalsOfContinuousStates""".split()


def test_validate_fmu_finds_no_problem(fmu_path, custom_fmu):
    assert validate_fmu(str(fmu_path)) == []
    assert validate_fmu(str(custom_fmu)) == []


def test_archive_layout(fmu_path):
    with zipfile.ZipFile(fmu_path) as z:
        names = set(z.namelist())
        assert names == {
            "modelDescription.xml",
            "binaries/linux64/ParallelArch.so",
            "resources/parallel_arch.json",
            "documentation/index.html",
        }
        assert all(i.compress_type in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED) for i in z.infolist())
        assert "<code>G1.slip</code>" in z.read("documentation/index.html").decode()


def test_every_fmi2_function_is_exported(fmu_path, tmp_path):
    with zipfile.ZipFile(fmu_path) as z:
        z.extract("binaries/linux64/ParallelArch.so", tmp_path)
    lib = ctypes.CDLL(str(tmp_path / "binaries/linux64/ParallelArch.so"))
    for name in COMMON + CO_SIMULATION + MODEL_EXCHANGE:
        assert hasattr(lib, "fmi2" + name), name
    assert len(COMMON) == 25 and len(CO_SIMULATION) == 9 and len(MODEL_EXCHANGE) == 10
    lib.fmi2GetVersion.restype = ctypes.c_char_p
    lib.fmi2GetTypesPlatform.restype = ctypes.c_char_p
    assert lib.fmi2GetVersion() == b"2.0" and lib.fmi2GetTypesPlatform() == b"default"


def test_specimen_variables(fmu_path):
    md = read_model_description(str(fmu_path))
    assert md.coSimulation.modelIdentifier == "ParallelArch"
    cs = md.coSimulation
    assert cs.canHandleVariableCommunicationStepSize and cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    assert (md.defaultExperiment.startTime, md.defaultExperiment.stopTime, md.defaultExperiment.stepSize) == (
        "0", "1", "0.05")
    v = {x.name: x for x in md.modelVariables}
    assert v["time"].causality == "independent"
    assert [n for n, x in v.items() if x.causality == "input"] == ["mu", "frame.dx", "frame.dy", "frame.dz"]
    for name, unit in [("frame.dz", "m"), ("film.E", "Pa"), ("G1.kn", "N/m"), ("G1.normalForce", "N"),
                       ("frame.Rz", "N"), ("film.maxEquivalentStress", "Pa"), ("mu", "1"), ("archHeight", "m")]:
        assert v[name].unit == unit, name
    assert v["archHeight"].start == "0.3" and v["archHeight"].causality == "parameter"
    assert v["G5.status"].type == "Integer" and v["G5.status"].variability == "discrete"
    assert v["solver.useJuRowlands"].type == "Boolean" and v["solver.useJuRowlands"].start == "false"
    assert v["solver.incrementsPerStep"].start == "1"
    law = v["frictionLaw"]
    assert (law.type, law.causality, law.start) == ("String", "parameter", "isotropic")
    assert v["film.wrinkling"].type == "Boolean" and v["film.wrinkling"].start == "false"
    for name in ["film.wrinkledElements", "film.slackElements"]:
        assert v[name].type == "Integer" and v[name].causality == "output", name
    for gap in [f"G{i}" for i in range(1, 10)]:
        for suffix in ["slip", "slipY", "normalForce", "frictionForce", "frictionX", "frictionY", "status"]:
            assert v[f"{gap}.{suffix}"].causality == "output"
    outputs = [x for x in md.modelVariables if x.causality == "output"]
    assert [u.variable for u in md.outputs] == outputs
    assert [u.variable for u in md.initialUnknowns] == outputs


def test_custom_model_variables_come_from_the_file(custom_fmu, custom_model):
    model = json.loads(custom_model.read_text())
    md = read_model_description(str(custom_fmu))
    assert md.coSimulation.modelIdentifier == "CustomArch" == md.modelName
    v = {x.name: x for x in md.modelVariables}
    assert "archHeight" not in v and "frame.dz" not in v
    assert {"rim.dx", "rim.dy", "rim.dz", "rim.Rz", "S1.slip", "S9.status"} <= set(v)
    assert float(v["S3.kn"].start) == model["gaps"][2]["normal_stiffness"]
    assert float(v["film.nu"].start) == model["material"]["poisson_ratio"]
    assert md.description == model["description"]


def test_model_wrinkling_setting_is_the_parameter_start(custom_model, tmp_path):
    model = json.loads(custom_model.read_text())
    model["material"]["wrinkling"] = "tension-field"
    path = tmp_path / "wrinkling.json"
    path.write_text(json.dumps(model))
    v = {x.name: x for x in read_model_description(str(pack(path, tmp_path))).modelVariables}
    assert v["film.wrinkling"].start == "true"


def test_packing_is_deterministic(fmu_path, tmp_path):
    r = fmu_pack("--out", tmp_path)
    assert r.returncode == 0, r.stderr
    again = tmp_path / "ParallelArch.fmu"
    with zipfile.ZipFile(fmu_path) as a, zipfile.ZipFile(again) as b:
        assert a.read("modelDescription.xml") == b.read("modelDescription.xml")
        assert a.read("resources/parallel_arch.json") == b.read("resources/parallel_arch.json")


def test_fmu_pack_refuses_a_bad_model_and_writes_nothing(custom_model, tmp_path):
    model = json.loads(custom_model.read_text())
    cases = []
    bad = json.loads(json.dumps(model))
    bad["material"]["youngs_modulus"] = -1.0
    cases.append((bad, "E = -1 must be > 0"))
    bad = json.loads(json.dumps(model))
    bad["gaps"][0]["name"] = "mu"
    cases.append((bad, "gap 'mu': the name is reserved"))
    bad = json.loads(json.dumps(model))
    bad["material"]["wrinkling"] = "sometimes"
    cases.append((bad, "unknown variant `sometimes`, expected `none` or `tension-field`"))
    bad = json.loads(json.dumps(model))
    bad["name"] = "not an identifier"
    cases.append((bad, "must be an identifier"))
    cases.append(("{ not json", "model file:"))
    out = tmp_path / "out"
    for i, (content, expect) in enumerate(cases):
        path = tmp_path / f"bad{i}.json"
        path.write_text(content if isinstance(content, str) else json.dumps(content))
        r = fmu_pack(path, "--out", out)
        assert r.returncode != 0, expect
        assert expect in r.stderr and str(path) in r.stderr, r.stderr
        assert not out.exists() or not any(out.iterdir()), "nothing written"


def test_unpacked_resources_rebuild_the_same_guid(fmu_path, tmp_path):
    """The binary recomputes the GUID from resources/: a tampered resource file is refused."""
    md = read_model_description(str(fmu_path))
    unzipdir = extract(str(fmu_path), unzipdir=str(tmp_path / "fmu"))
    spec = tmp_path / "fmu/resources/parallel_arch.json"
    data = json.loads(spec.read_text())
    data["arch_height"] = 0.25
    spec.write_text(json.dumps(data))
    messages = []
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="ParallelArch", instanceName="x")
    with pytest.raises(Exception, match="instantiate"):
        slave.instantiate(callbacks=callbacks_for(messages, "x"))
    slave.freeLibrary()
    assert any(s == ERROR and "GUID mismatch" in m for s, _, m in messages), messages
