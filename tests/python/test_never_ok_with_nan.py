"""Issue 12: never fmi2OK (or exit 0) with a wrong answer, seen from an importer and a shell.

TEST GOAL, one test per finding of the issue:
1. a huge but finite input (``frame.dz = -1e100``) is refused (fmi2Error or fmi2Discard) and the
   outputs stay finite: those of the last converged state;
2. singular models (a floating film, a node held only by a gap) are refused by ``fmu-pack`` and
   by the CLI with the nodes and the free motion named, before any step;
3. a forged state (displacements × 1e150, length and CRC-32 recomputed) and a state whose sizes
   do not fit are refused by ``fmi2DeSerializeFMUstate`` itself;
4. a control character in the model's description is refused by ``fmu-pack`` naming the field;
   markup, tabs and line feeds give a well-formed modelDescription.xml that reads back exactly;
5. ``membrane-contact export-specimen ... | head -c 10`` ends quietly;
and ``fmi2FreeFMUstate(c, NULL)`` returns fmi2Error.

Issue 47, defect 2: the jack FMU (fmu/jack) holds the same rule. A step whose output overflows
(``stiffness = 1e-10``, ``force = 1e308``: ``dz = -inf``) is discarded with a message and the
last good state kept; inputs whose outputs overflow in initialization mode, and non-finite or
out-of-range values, are refused by ``fmi2SetReal`` with a message.

MODEL: ParallelArch.fmu, the renamed 200 mm specimen of ``custom_model`` (conftest.py), and
HydraulicJack.fmu packed as test_coupling.py packs it (``pack_jack_fmu``).
"""

from __future__ import annotations

import json
import math
import re
import struct
import subprocess
import zlib
from ctypes import byref, c_size_t, c_void_p, create_string_buffer

import pytest
from conftest import CLI, fmu_pack
from fmpy import read_model_description
from fmu_helpers import DISCARD, ERROR, OK, Slave
from membrane_contact.film import FmuError
from membrane_contact.ssp import pack_jack_fmu

RAMP = {"frame.dz": -0.15}


def test_huge_finite_input_is_refused_and_outputs_stay_finite(fmu_path):
    with Slave(fmu_path) as s:
        s.initialize(inputs={"mu": 0.2})
        s.ramp(RAMP, 20, last=2)
        before = s.outputs()
        s.set({"frame.dz": -1e100})
        status = s.step(0.1, 0.05)
        assert status in (ERROR, DISCARD), (status, s.messages[-2:])
        after = s.outputs()
        assert all(math.isfinite(v) for v in after.values())
        assert after == before
        # The master can go on with a sensible input.
        s.set({"frame.dz": -0.15 * 3 / 20})
        assert s.step(0.1, 0.05) == OK


def pack(model: dict, tmp_path, name="m.json"):
    path = tmp_path / name
    path.write_text(json.dumps(model))
    out = tmp_path / "out"
    r = fmu_pack(path, "--out", out)
    return r, out


def test_singular_models_are_refused_by_fmu_pack_and_the_cli(custom_model, tmp_path):
    model = json.loads(custom_model.read_text())
    floating = json.loads(json.dumps(model))
    floating["groups"] = []  # the frame held the film
    lonely = json.loads(json.dumps(model))
    # Beside the first gap's film node along its sliding direction: the same initial gap.
    first = lonely["gaps"][0]
    a, x = lonely["nodes"][first["film_node"]], first["frame"]["x"]
    lonely["nodes"].append([a[c] + 0.01 * x[c] for c in range(3)])
    extra = dict(lonely["gaps"][0], name="Lonely", film_node=len(lonely["nodes"]) - 1)
    lonely["gaps"].append(extra)
    cases = [
        (floating, "(121 nodes) can rotate about an axis along Y"),
        (lonely, f"node {len(lonely['nodes']) - 1} has free DOFs but belongs to no triangle"),
    ]
    for i, (bad, expect) in enumerate(cases):
        r, out = pack(bad, tmp_path, f"singular{i}.json")
        assert r.returncode != 0 and expect in r.stderr, r.stderr
        assert not out.exists() or not any(out.iterdir())
        cli = subprocess.run([str(CLI), "model", str(tmp_path / f"singular{i}.json"), "--steps", "1"],
                             capture_output=True, text=True)
        assert cli.returncode != 0 and expect in cli.stderr, cli.stderr
        assert "NaN" not in cli.stdout


def frame(blob: bytes):
    """(header up to the payload length, payload) of a serialized state."""
    (guid_len,) = struct.unpack_from("<I", blob, 12)
    head = blob[: 16 + guid_len]
    return head, blob[16 + guid_len + 12 :]


def reframe(head: bytes, payload: bytes) -> bytes:
    """A forged buffer: the format's length and CRC-32 recomputed."""
    out = head + struct.pack("<Q", len(payload))
    crc = zlib.crc32(payload, zlib.crc32(out))
    return out + struct.pack("<I", crc) + payload


def test_forged_states_are_refused_at_deserialization(fmu_path):
    with Slave(fmu_path) as s:
        s.initialize(inputs={"mu": 0.2})
        s.ramp(RAMP, 20, last=4)
        state = s.fmu.getFMUstate()
        blob = bytes(s.fmu.serializeFMUstate(state))
        head, payload = frame(blob)
        assert reframe(head, payload) == blob  # the forger's framing is the FMU's

        def deserialize(data):
            buf = create_string_buffer(data, len(data))
            handle = c_void_p()
            status = s.call("fmi2DeSerializeFMUstate", s.c, buf, c_size_t(len(data)), byref(handle))
            return status, handle

        def forged(edit):
            snapshot = json.loads(payload)
            edit(snapshot["analysis"])
            return reframe(head, json.dumps(snapshot).encode())

        cases = [
            (lambda a: a.update(displacement=[v * 1e150 for v in a["displacement"]]), "beyond"),
            (lambda a: a.update(displacement=a["displacement"][:-3]), "displacements, the model"),
            (lambda a: a.update(status=a["status"] + ["Open"]), "gap statuses, the model"),
            (lambda a: a["status"].__setitem__(0, "Open"), "status of gap 'G1' is Open"),
        ]
        for edit, expect in cases:
            status, handle = deserialize(forged(edit))
            assert status == ERROR and not handle.value, expect
            assert s.logged(ERROR, expect), (expect, s.messages[-1:])
        # The genuine buffer is still accepted, and the instance steps on.
        status, handle = deserialize(blob)
        assert status == OK
        s.fmu.setFMUstate(handle)
        s.ramp(RAMP, 20, first=4, last=5)
        s.fmu.freeFMUstate(handle)
        s.fmu.freeFMUstate(state)
        # fmi2FreeFMUstate(c, NULL): a NULL argument.
        assert s.call("fmi2FreeFMUstate", s.c, None) == ERROR
        assert s.logged(ERROR, "FMUstate")


def test_description_text_is_checked_and_escaped(custom_model, tmp_path):
    model = json.loads(custom_model.read_text())
    model["description"] = "a \u0001 b"
    r, out = pack(model, tmp_path, "control.json")
    assert r.returncode != 0 and "model description: character U+0001" in r.stderr, r.stderr
    text = 'line 1\nline 2\t<b> & "q" \'s\' @GUID@ ünï ✓ 𝄞'
    model["description"] = text
    r, out = pack(model, tmp_path, "markup.json")
    assert r.returncode == 0, r.stderr
    md = read_model_description(str(out / "CustomArch.fmu"))
    assert md.description == text


def test_cli_ends_quietly_on_a_closed_pipe():
    r = subprocess.run(
        f"'{CLI}' export-specimen --height 300 --refine 4 | head -c 10; echo \"status ${{PIPESTATUS[0]}}\"",
        shell=True, executable="/bin/bash", capture_output=True, text=True)
    assert r.stdout.startswith("{") and r.stdout.rstrip().endswith("status 0"), r.stdout
    assert r.stderr == "", r.stderr


@pytest.fixture(scope="module")
def jack_fmu(tmp_path_factory):
    return pack_jack_fmu(tmp_path_factory.mktemp("jack") / "HydraulicJack.fmu")


def test_jack_discards_a_step_to_an_infinite_output_and_keeps_its_last_state(jack_fmu):
    with Slave(jack_fmu) as s:
        s.initialize(parameters={"stiffness": 1e-10})
        s.set({"force": -1e-9})
        assert s.step(0.0, 1.0) == OK
        before = s.outputs()
        s.set({"force": 1e308})  # dz = piston - force / stiffness = -inf
        status = s.step(1.0, 1.0)
        assert status == DISCARD, (status, s.messages[-2:])
        assert s.logged(DISCARD, "fmi2DoStep: dz would be -inf"), s.messages[-1:]
        assert s.logged(DISCARD, "force = 1e308, stiffness = 1e-10"), s.messages[-1:]
        after = s.outputs()
        assert all(math.isfinite(v) for v in after.values()), after
        assert after == before
        assert s.fmu.getRealStatus(2) == 1.0  # fmi2LastSuccessfulTime: the discarded step is not
        # The master goes on from the same state with a sensible force.
        s.set({"force": -1e-9})
        assert s.step(1.0, 1.0) == OK
        assert all(math.isfinite(v) for v in s.outputs().values())


def test_jack_refuses_values_whose_outputs_overflow_and_non_finite_values_with_a_message(jack_fmu):
    with Slave(jack_fmu) as s:
        s.fmu.setupExperiment(startTime=0.0)
        s.fmu.enterInitializationMode()
        s.set({"stiffness": 1e-10})
        with pytest.raises(FmuError, match=r"dz would be -inf"):
            s.set({"force": 1e308})
        assert s.get("force") == 0.0 and s.get("dz") == 0.0
        for name, value, message in [("force", math.nan, "force = NaN: values must be finite"),
                                     ("relief", -math.inf, "relief = -inf: values must be finite"),
                                     ("stiffness", -1e308, "stiffness = -1e308 must be > 0"),
                                     ("crack", 1.0, "crack = 1 must lie in [0, 1)")]:
            with pytest.raises(FmuError, match=re.escape(message)):
                s.set({name: value})
        s.fmu.exitInitializationMode()
        assert all(math.isfinite(v) for v in s.outputs().values())
