"""The FMI 3.0 Co-Simulation FMU (``fmu-pack --fmi-version 3``) against the FMI 2.0 one.

TEST GOAL: the FMI 3.0 archives of the specimen and of a user model pass ``fmpy validate``; fmpy's
FMI 3.0 importer (``fmpy.fmi3``) gets outputs bit-identical to the FMI 2.0 FMU's on the same
inputs (the same library and instance drive both); FMU states saved, serialized and read back
into a fresh FMI 3.0 instance continue bit for bit; a refused step (``fmi3Discard``) keeps the last
converged state and tells its time; the directional derivatives equal FMI 2.0's; a wrong
instantiation token is refused.

BOUNDARY CONDITIONS: the group's ``dz`` ramped to -0.02 m over [0, 1], mu = 0.3, steps of 0.1.
"""

from __future__ import annotations

import zipfile

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu

from conftest import fmu_pack


def pack3(out_dir, *model) -> str:
    """Packs the FMI 3.0 FMU of ``model`` (none: the specimen) into ``out_dir``."""
    r = fmu_pack(*model, "--fmi-version", "3", "--out", out_dir)
    assert r.returncode == 0, r.stderr
    (path,) = [p for p in out_dir.iterdir() if p.name.endswith("_fmi3.fmu")]
    return str(path)


@pytest.fixture(scope="module")
def specimen3(tmp_path_factory):
    return pack3(tmp_path_factory.mktemp("fmi3-specimen"))


@pytest.fixture(scope="module")
def custom3(custom_model, tmp_path_factory):
    return pack3(tmp_path_factory.mktemp("fmi3-custom"), custom_model)


def dz_input(fmu) -> str:
    """The first group's ``dz`` input of ``fmu``."""
    names = [v.name for v in read_model_description(fmu).modelVariables if v.causality == "input"]
    return next(n for n in names if n.endswith(".dz"))


def test_fmi3_archives_pass_fmpy_validate_with_the_library_in_the_fmi3_folder(specimen3, custom3):
    for fmu in (specimen3, custom3):
        assert validate_fmu(fmu) == [], fmu
        with zipfile.ZipFile(fmu) as z:
            assert any(n.startswith("binaries/x86_64-linux/") for n in z.namelist())
        d = read_model_description(fmu)
        assert d.fmiVersion == "3.0" and d.coSimulation is not None


ARRAYS = ["film.nodeCount", "film.gapCount", "film.displacement", "film.reaction", "film.gapSlipX",
          "film.gapSlipY", "film.gapNormalForce", "film.gapStatus", "film.lineReaction"]
# The specimen's one reaction line, its frame (issue 45: per-line arrays).
LINES = ["frame.linePoints", "frame.lineReaction", "frame.linePosition", "frame.lineArc"]


def test_fmi3_keeps_the_fmi2_variables_value_references_and_token_and_adds_the_arrays(fmu_path, specimen3):
    d2, d3 = read_model_description(str(fmu_path)), read_model_description(specimen3)
    assert d3.instantiationToken == d2.guid
    types = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean", "String": "String"}
    rows = lambda d, t: [(v.name, v.valueReference, t(v.type), v.causality, v.variability, v.start, v.unit)
                         for v in d.modelVariables]
    n = len(d2.modelVariables)
    assert rows(d2, types.get) == rows(d3, str)[:n]
    extra = d3.modelVariables[n:]
    assert [v.name for v in extra] == ARRAYS + LINES
    assert [v.valueReference for v in extra[:len(ARRAYS)]] == list(range(n, n + len(ARRAYS)))
    # The frame's line arrays follow the references reserved for the 13 film fields (the
    # contact arrays among them are absent: the specimen has no curved supports).
    assert [v.valueReference for v in extra[len(ARRAYS):]] == list(range(n + 13, n + 17))


@pytest.mark.parametrize("which", ["specimen", "user model"])
def test_fmi3_outputs_are_bit_identical_to_fmi2_on_the_same_inputs(which, fmu_path, custom_fmu, specimen3, custom3):
    fmu2, fmu3 = (str(fmu_path), specimen3) if which == "specimen" else (str(custom_fmu), custom3)
    name = dz_input(fmu2)
    ramp = np.array([(0.0, 0.0), (1.0, -0.02)], dtype=[("time", np.float64), (name, np.float64)])
    run = lambda fmu: simulate_fmu(fmu, stop_time=0.5, output_interval=0.1, input=ramp,
                                   start_values={"mu": 0.3})
    r2, r3 = run(fmu2), run(fmu3)
    line_array = lambda n: n.rsplit(".", 1)[-1] in {"linePoints", "lineReaction", "linePosition", "lineArc"}
    extra = set(r3.dtype.names) - set(r2.dtype.names)
    assert {n for n in extra if not line_array(n)} <= set(ARRAYS) and len(r2) == len(r3) == 6
    for column in r2.dtype.names:
        assert np.array_equal(r2[column], r3[column]), column
    assert any(r2[c][-1] != 0.0 for c in r2.dtype.names if c.endswith(".Rz")), "the film was loaded"


class Film3:
    """An FMI 3.0 instance of ``fmu`` past initialization, with ``vr`` by name."""

    def __init__(self, fmu, name="film3", integers=None, booleans=None, strings=None):
        self.d = read_model_description(fmu)
        self.vr = {v.name: v.valueReference for v in self.d.modelVariables}
        self.outputs = [v.valueReference for v in self.d.modelVariables if v.causality == "output"
                        and v.type == "Float64" and not v.dimensions]
        from fmpy import extract
        self.dir = extract(fmu)
        self.fmu = FMU3Slave(guid=self.d.instantiationToken, unzipDirectory=self.dir,
                             modelIdentifier=self.d.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate()
        self.fmu.enterInitializationMode(startTime=0.0)
        self.fmu.setFloat64([self.vr["mu"]], [0.3])
        for names, setter in [(integers or {}, self.fmu.setInt32), (booleans or {}, self.fmu.setBoolean),
                              (strings or {}, self.fmu.setString)]:
            if names:
                setter([self.vr[n] for n in names], list(names.values()))
        self.fmu.exitInitializationMode()
        self.t = 0.0

    def step(self, dz, h=0.1):
        self.fmu.setFloat64([self.vr["frame.dz"]], [dz])
        result = self.fmu.doStep(self.t, h)
        self.t += h
        return result

    def values(self):
        return self.fmu.getFloat64(self.outputs)

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def test_fmi3_states_serialized_into_a_fresh_instance_continue_bit_for_bit(specimen3):
    a = Film3(specimen3)
    for k in range(3):
        a.step(-0.005 * (k + 1))
    state = a.fmu.getFMUState()
    blob = a.fmu.serializeFMUState(state)
    a.fmu.freeFMUState(state)
    at_save = a.values()
    for k in range(3, 6):
        a.step(-0.005 * (k + 1))
    reference = a.values()
    a.close()

    b = Film3(specimen3, "fresh")
    restored = b.fmu.deserializeFMUState(blob)
    b.fmu.setFMUState(restored)
    b.fmu.freeFMUState(restored)
    assert b.values() == at_save
    b.t = 0.3
    for k in range(3, 6):
        b.step(-0.005 * (k + 1))
    assert b.values() == reference
    b.close()


def test_fmi3_do_step_never_returns_early_and_a_refused_step_keeps_the_last_state(specimen3):
    # One increment, no cut-back, no stabilization: -0.15 m in one step cannot converge
    # (test_package.py's HARD settings), set through fmi3SetInt32 and fmi3SetBoolean.
    hard = {"solver.incrementsPerStep": 1, "solver.maxCutbacks": 0, "solver.maxIterations": 10}
    f = Film3(specimen3, integers=hard, booleans={"solver.stabilization": False})
    assert f.fmu.getInt32([f.vr[n] for n in hard]) == list(hard.values())
    assert f.fmu.getBoolean([f.vr["solver.stabilization"]]) == [False]
    assert f.step(-0.005) == (False, False, False, 0.1)
    before = f.values()
    f.fmu.setFloat64([f.vr["frame.dz"]], [-0.15])
    with pytest.raises(FMICallException) as refused:
        f.fmu.doStep(0.1, 1.0)
    assert refused.value.status == 2  # fmi3Discard
    assert f.values() == before
    f.t = 0.1
    assert f.step(-0.006)[3] == pytest.approx(0.2)
    f.close()


def test_fmi3_directional_derivatives_equal_fmi2s(fmu_path, specimen3):
    f3 = Film3(specimen3)
    d2 = read_model_description(str(fmu_path))
    f2 = FMU2Slave(guid=d2.guid, unzipDirectory=__import__("fmpy").extract(str(fmu_path)),
                   modelIdentifier=d2.coSimulation.modelIdentifier, instanceName="film2")
    f2.instantiate()
    f2.setupExperiment(startTime=0.0)
    f2.enterInitializationMode()
    f2.setReal([f3.vr["mu"]], [0.3])
    f2.exitInitializationMode()
    for k in range(2):
        f3.step(-0.005 * (k + 1))
        f2.setReal([f3.vr["frame.dz"]], [-0.005 * (k + 1)])
        f2.doStep(0.1 * k, 0.1)
    unknowns, knowns = [f3.vr["frame.Rz"]], [f3.vr["frame.dz"]]
    d3 = f3.fmu.getDirectionalDerivative(unknowns, knowns, [1.0])
    assert d3 == list(f2.getDirectionalDerivative(unknowns, knowns, [1.0]))
    assert d3[0] != 0.0
    f3.close()
    f2.terminate()
    f2.freeInstance()


def test_fmi3_refuses_a_wrong_instantiation_token(specimen3):
    from fmpy import extract
    d = read_model_description(specimen3)
    fmu = FMU3Slave(guid="{00000000-0000-0000-0000-000000000000}", unzipDirectory=extract(specimen3),
                    modelIdentifier=d.coSimulation.modelIdentifier, instanceName="wrong")
    with pytest.raises(Exception, match="nstantiat"):
        fmu.instantiate()


def test_fmi3_arrays_equal_the_vtk_fields_bit_for_bit(specimen3, tmp_path):
    import meshio
    f = Film3(specimen3, strings={"results.directory": str(tmp_path)})
    n = f.fmu.getUInt64([f.vr["film.nodeCount"], f.vr["film.gapCount"]])
    assert n == [121, 9]
    for k in range(3):
        f.step(-0.01 * (k + 1))
    nodes, gaps = n
    u = np.array(f.fmu.getFloat64([f.vr["film.displacement"]], 3 * nodes)).reshape(nodes, 3)
    r = np.array(f.fmu.getFloat64([f.vr["film.reaction"]], 3 * nodes)).reshape(nodes, 3)
    q = np.array(f.fmu.getFloat64([f.vr["film.lineReaction"]], 3 * nodes)).reshape(nodes, 3)
    gap = {name: np.array(f.fmu.getFloat64([f.vr[name]], gaps))
           for name in ["film.gapSlipX", "film.gapSlipY", "film.gapNormalForce"]}
    status = np.array(f.fmu.getInt32([f.vr["film.gapStatus"]], gaps))
    # An array and a scalar in one call: their values one after the other.
    both = f.fmu.getFloat64([f.vr["frame.Rz"], f.vr["film.gapSlipX"]], 1 + gaps)
    assert both[1:] == list(gap["film.gapSlipX"]) and both[0] == f.fmu.getFloat64([f.vr["frame.Rz"]])[0]
    # The frame's reaction line (issue 45): its nodes in order along it, found by their points.
    (points,) = f.fmu.getUInt64([f.vr["frame.linePoints"]])
    line_q = np.array(f.fmu.getFloat64([f.vr["frame.lineReaction"]], 3 * points)).reshape(points, 3)
    line_x = np.array(f.fmu.getFloat64([f.vr["frame.linePosition"]], 3 * points)).reshape(points, 3)
    f.close()
    film = meshio.read(tmp_path / "ParallelArch_film_0003.vtu")
    lines = meshio.read(tmp_path / "ParallelArch_gaps_0003.vtu")
    assert np.array_equal(u, film.point_data["displacement"]) and np.abs(u).max() > 0
    assert np.array_equal(r, film.point_data["reaction"]) and np.abs(r).max() > 0
    assert np.array_equal(q, film.point_data["line_reaction"]) and np.abs(q).max() > 0
    # The frame is the specimen's one line: its values are the field's at its nodes, bit for bit.
    at = [int(np.flatnonzero((film.points == x).all(axis=1))[0]) for x in line_x]
    assert len(set(at)) == points > 1
    assert np.array_equal(line_q, film.point_data["line_reaction"][at]) and np.abs(line_q).max() > 0
    for name, field in [("film.gapSlipX", "gap_slip_x"), ("film.gapSlipY", "gap_slip_y"),
                        ("film.gapNormalForce", "gap_normal_force")]:
        assert np.array_equal(gap[name], lines.cell_data[field][0]), name
    assert np.array_equal(status, lines.cell_data["gap_status"][0]) and status.any()
    assert np.abs(gap["film.gapSlipX"]).max() > 0


def test_fmi3_refuses_an_array_read_with_the_wrong_number_of_values(specimen3):
    f = Film3(specimen3)
    with pytest.raises(FMICallException):
        f.fmu.getFloat64([f.vr["film.displacement"]], 5)
    with pytest.raises(FMICallException):
        f.fmu.getInt32([f.vr["film.gapSlipX"]], 9)
    f.close()


def test_the_fmi3_shape_example_plots_the_film_lowered_by_the_frame(specimen3, tmp_path):
    import os
    import subprocess
    import sys
    from conftest import CLI, ROOT
    r = subprocess.run([sys.executable, str(ROOT / "examples" / "fmi3_shape.py"), "--fmu", specimen3,
                        "--out", str(tmp_path), "--steps", "2", "--depth", "0.01"],
                       capture_output=True, text=True, timeout=120,
                       env={**os.environ, "MEMBRANE_CONTACT_CLI": str(CLI)})
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "fmi3_shape.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    x = np.loadtxt(tmp_path / "fmi3_shape.csv", delimiter=",", skiprows=1)
    assert x.shape == (121, 3)
    assert x[:, 2].min() == pytest.approx(0.3 - 0.01)  # the frame's nodes went down with it


def test_fmi3_adjoint_is_the_transpose_of_the_film_jacobian_and_of_its_directional_derivatives(specimen3):
    """Jᵀv from fmi3GetAdjointDerivative against J s from fmi3GetDirectionalDerivative: their
    columns agree to the last bit, and with one combined seed vᵀ(J s) = (Jᵀ v)ᵀ s holds to
    1e-12: both are made of J's columns (docs/fmu.md; it held to 5e-10 … 7e-9 only while J s
    was one response to the combined seed)."""
    f = Film3(specimen3)
    for k in range(3):
        f.step(-0.01 * (k + 1))
    knowns = [f.vr[n] for n in ["frame.dx", "frame.dy", "frame.dz", "mu"]]
    unknowns = [f.vr[n] for n in ["frame.Rx", "frame.Rz", "G3.slip", "G5.slip", "G1.normalForce"]]
    rng = np.random.default_rng(1)
    s, v = rng.normal(size=len(knowns)), rng.normal(size=len(unknowns))
    # fmpy sizes the sensitivity by the unknowns unless told: the adjoint's is one per known.
    jtv = np.array(f.fmu.getAdjointDerivative(unknowns, knowns, list(v), len(knowns)))
    columns = np.array([f.fmu.getDirectionalDerivative(unknowns, [k], [1.0]) for k in knowns]).T
    assert np.array_equal(jtv, v @ columns)
    assert (np.abs(columns).max(axis=0) > 0).all() and (np.abs(columns).max(axis=1) > 0).all()
    js = np.array(f.fmu.getDirectionalDerivative(unknowns, knowns, list(s)))
    assert v @ js == pytest.approx(jtv @ s, rel=1e-12, abs=0.0)
    assert np.allclose(js, columns @ s, rtol=1e-14, atol=0.0)
    with pytest.raises(FMICallException):  # the default sensitivity size (one per unknown)
        f.fmu.getAdjointDerivative(unknowns, knowns, list(v))
    f.close()


def test_fmi3_archives_have_a_schema_valid_terminal_per_boundary_group(specimen3, custom3):
    from pathlib import Path
    import fmpy
    from lxml import etree
    schema = etree.XMLSchema(etree.parse(str(Path(fmpy.__file__).parent / "schema" / "fmi3" /
                                             "fmi3TerminalsAndIcons.xsd")))
    for fmu, group in [(specimen3, "frame"), (custom3, "rim")]:
        with zipfile.ZipFile(fmu) as z:
            doc = etree.fromstring(z.read("terminalsAndIcons/terminalsAndIcons.xml"))
        schema.assertValid(doc)
        (terminal,) = doc.iter("Terminal")
        assert terminal.get("name") == group and terminal.get("matchingRule") == "plug"
        causality = {v.name: v.causality for v in read_model_description(fmu).modelVariables}
        members = {m.get("memberName"): m.get("variableName") for m in terminal.iter("TerminalMemberVariable")}
        assert list(members) == ["dx", "dy", "dz", "Rx", "Ry", "Rz"]
        for member, variable in members.items():
            assert variable == f"{group}.{member}"
            assert causality[variable] == ("input" if member.startswith("d") else "output")


def test_the_jack_on_the_shared_glue_runs_as_fmi3_bit_identical_to_its_fmi2_fmu(tmp_path_factory):
    """The jack's FMI 3.0 FMU as pack_jack_fmu(fmi_version=3) packs it (fmu/jack/modelDescription3.xml,
    generated from its table, and the same library under binaries/x86_64-linux/): fmpy validate
    passes and the outputs equal the FMI 2.0 FMU's."""
    from conftest import ROOT
    from membrane_contact.ssp import jack_library, pack_jack_fmu
    out = tmp_path_factory.mktemp("jack3")
    fmu2 = str(pack_jack_fmu(out / "HydraulicJack.fmu"))
    fmu3 = str(pack_jack_fmu(out, fmi_version=3))
    assert fmu3 == str(out / "HydraulicJack_fmi3.fmu")
    with zipfile.ZipFile(fmu3) as z:
        assert sorted(z.namelist()) == ["binaries/x86_64-linux/hydraulic_jack.so", "modelDescription.xml"]
        assert z.read("modelDescription.xml") == (ROOT / "fmu" / "jack" / "modelDescription3.xml").read_bytes()
        assert z.read("binaries/x86_64-linux/hydraulic_jack.so") == jack_library().read_bytes()
    assert read_model_description(fmu3).fmiVersion == "3.0"
    assert validate_fmu(fmu3) == []
    force = np.array([(0.0, 0.0), (100.0, -700.0)], dtype=[("time", np.float64), ("force", np.float64)])
    run = lambda fmu: simulate_fmu(fmu, stop_time=100.0, output_interval=5.0, input=force,
                                   start_values={"relief": 600.0})
    r2, r3 = run(fmu2), run(fmu3)
    assert r2.dtype.names == r3.dtype.names and len(r2) == 21
    for column in r2.dtype.names:
        assert np.array_equal(r2[column], r3[column]), column
    assert r2["speed"].min() < 0.0 < r2["speed"].max(), "pumping and yielding back through the valve"


def test_fmi3_contact_arrays_of_curved_supports_equal_the_vtk_contacts_fields(tmp_path):
    """The specimen on curved supports (no gaps): film.contactCount and the contact arrays, and
    no gap arrays."""
    import json
    import meshio
    import subprocess
    from conftest import CLI
    model = json.loads(subprocess.run([str(CLI), "export-specimen", "--contact", "curved-support"],
                                      check=True, capture_output=True, text=True).stdout)
    (tmp_path / "curved.json").write_text(json.dumps(model))
    fmu = tmp_path / "curved_fmi3.fmu"
    r = fmu_pack(tmp_path / "curved.json", "--fmi-version", "3", "-o", fmu)
    assert r.returncode == 0, r.stderr
    assert validate_fmu(str(fmu)) == []
    out = tmp_path / "vtk"
    f = Film3(str(fmu), strings={"results.directory": str(out)})
    assert "film.gapCount" not in f.vr and "film.gapSlipX" not in f.vr
    (n,) = f.fmu.getUInt64([f.vr["film.contactCount"]])
    assert n == 9
    for k in range(3):
        f.step(-0.01 * (k + 1))
    slip = f.fmu.getFloat64([f.vr["film.contactSlip"]], n)
    force = f.fmu.getFloat64([f.vr["film.contactNormalForce"]], n)
    status = f.fmu.getInt32([f.vr["film.contactStatus"]], n)
    f.close()
    lines = meshio.read(out / "ParallelArch_contacts_0003.vtu")
    assert np.array_equal(slip, lines.cell_data["contact_slip"][0]) and np.abs(slip).max() > 0
    assert np.array_equal(force, lines.cell_data["contact_normal_force"][0]) and np.abs(force).max() > 0
    assert np.array_equal(status, lines.cell_data["contact_status"][0]) and any(status)


def test_the_jack_fmi3_fmu_carries_cross_builds_in_fmi3_platform_folders(tmp_path):
    """pack_jack_fmu(fmi_version=3, platforms=...): the cross builds of target/<triple>/release go
    to FMI 3.0's folders (x86_64-windows, aarch64-linux), named either way; an unknown platform
    and an unknown version are refused. (Stand-in files for the cross builds: this checks the
    archive's layout, tests/platforms.sh runs real ones.)"""
    import shutil
    from conftest import ROOT
    from membrane_contact.ssp import pack_jack_fmu
    (tmp_path / "fmu" / "jack").mkdir(parents=True)
    shutil.copy(ROOT / "fmu" / "jack" / "modelDescription3.xml", tmp_path / "fmu" / "jack")
    builds = {"x86_64-pc-windows-gnu": "hydraulic_jack.dll", "aarch64-unknown-linux-gnu": "libhydraulic_jack.so"}
    for triple, name in builds.items():
        (tmp_path / "target" / triple / "release").mkdir(parents=True)
        (tmp_path / "target" / triple / "release" / name).write_bytes(triple.encode())
    library = tmp_path / "host.so"
    library.write_bytes(b"host")
    for platforms in (["win64", "aarch64-linux"], ["x86_64-linux", "x86_64-windows", "aarch64-linux"]):
        fmu = pack_jack_fmu(tmp_path / "out", library=library, root=tmp_path, platforms=platforms, fmi_version=3)
        with zipfile.ZipFile(fmu) as z:
            assert sorted(z.namelist()) == ["binaries/aarch64-linux/hydraulic_jack.so",
                                            "binaries/x86_64-linux/hydraulic_jack.so",
                                            "binaries/x86_64-windows/hydraulic_jack.dll", "modelDescription.xml"]
            assert z.read("binaries/x86_64-windows/hydraulic_jack.dll") == b"x86_64-pc-windows-gnu"
            assert z.read("binaries/x86_64-linux/hydraulic_jack.so") == b"host"
    with pytest.raises(ValueError, match="unknown platform 'sparc'"):
        pack_jack_fmu(tmp_path / "out", library=library, root=tmp_path, platforms=["sparc"], fmi_version=3)
    with pytest.raises(ValueError, match="2 or 3"):
        pack_jack_fmu(tmp_path / "out", library=library, root=tmp_path, fmi_version=1)
