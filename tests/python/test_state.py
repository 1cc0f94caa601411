"""FMU states: save/restore and serialize/deserialize continue exactly as the original would.

TEST GOAL: a state saved at step 8 of 20 and restored (in place, or serialized and deserialized
into a fresh instance that had other parameters) continues to the same results bit for bit;
a corrupt, truncated or foreign buffer is refused with fmi2Error and a message; states of
another instance are refused; Reset returns to the just-instantiated state.

BOUNDARY CONDITIONS: ``frame.dz`` ramped to −0.15 m in 20 steps, μ = 0.3 (so that the friction
history matters), 2 increments per step.
"""

from __future__ import annotations

import re

from ctypes import byref, c_size_t, c_void_p, create_string_buffer

import pytest
from fmu_helpers import ERROR, FMICallException, Slave

STEPS = 20
RAMP = {"frame.dz": -0.15}
PARAMETERS = {"solver.incrementsPerStep": 2}


def started(fmu_path, **parameters):
    s = Slave(fmu_path)
    s.initialize(parameters={**PARAMETERS, **parameters}, inputs={"mu": 0.3})
    return s


def test_save_restore_and_serialize_continue_identically(fmu_path):
    with started(fmu_path) as s:
        s.ramp(RAMP, STEPS, last=8)
        state = s.fmu.getFMUstate()
        at_save = s.snapshot()
        s.ramp(RAMP, STEPS, first=8)
        reference = s.snapshot()

        s.fmu.setFMUstate(state)
        assert s.snapshot() == at_save
        s.ramp(RAMP, STEPS, first=8)
        assert s.snapshot() == reference

        blob = s.fmu.serializeFMUstate(state)
        s.fmu.freeFMUstate(state)

    # A fresh instance with other parameters takes the serialized state and continues exactly.
    with Slave(fmu_path, instance_name="other") as t:
        t.initialize(parameters={"film.E": 2e9, "solver.incrementsPerStep": 7})
        restored = t.fmu.deSerializeFMUstate(blob)
        t.fmu.setFMUstate(restored)
        assert t.snapshot() == at_save
        t.ramp(RAMP, STEPS, first=8)
        assert t.snapshot() == reference
        t.fmu.freeFMUstate(restored)


def test_state_from_initialization_mode_and_reset(fmu_path):
    with Slave(fmu_path) as s:
        s.fmu.setupExperiment(startTime=0.0)
        s.fmu.enterInitializationMode()
        s.set({"film.E": 1.5e9})
        early = s.fmu.getFMUstate()
        s.fmu.exitInitializationMode()
        s.ramp(RAMP, STEPS, last=5)
        first = s.snapshot()
        # Back to initialization mode with E = 1.5 GPa, then the same steps again.
        s.fmu.setFMUstate(early)
        s.fmu.exitInitializationMode()
        s.ramp(RAMP, STEPS, last=5)
        assert s.snapshot() == first
        # Reset: start values, time 0, must be set up again.
        s.fmu.reset()
        s.fmu.setupExperiment(startTime=0.0)
        s.fmu.enterInitializationMode()
        assert s.get("film.E") == 1e9 and s.get("time") == 0.0 and s.get("G9.slip") == 0.0
        s.fmu.freeFMUstate(early)


def test_bad_buffers_and_handles_are_refused(fmu_path, custom_fmu):
    with started(fmu_path) as s:
        s.ramp(RAMP, STEPS, last=2)
        state = s.fmu.getFMUstate()
        blob = bytearray(s.fmu.serializeFMUstate(state))

        def deserialize(data):
            buf = create_string_buffer(bytes(data), len(data))
            handle = c_void_p()
            status = s.call("fmi2DeSerializeFMUstate", s.c, buf, c_size_t(len(data)), byref(handle))
            return status, handle

        cases = []
        flipped = bytearray(blob)
        flipped[len(blob) // 2] ^= 0x01
        cases.append((flipped, "checksum"))
        cases.append((blob[:-10], "payload bytes"))
        cases.append((blob[:12], "truncated"))
        cases.append((b"\x00" * 64, "wrong magic"))
        with Slave(custom_fmu) as other:
            other.initialize()
            other_state = other.fmu.getFMUstate()
            cases.append((other.fmu.serializeFMUstate(other_state), "serialized by another FMU"))
            # A state handle of another instance is not one of ours.
            assert s.call("fmi2SetFMUstate", s.c, other_state) == ERROR
            assert s.logged(ERROR, "was not created by this instance"), s.messages[-2:]
            other.fmu.freeFMUstate(other_state)
        for data, message in cases:
            status, handle = deserialize(data)
            assert status == ERROR and not handle.value, message
            assert s.logged(ERROR, message), (message, s.messages[-1:])
        # fmpy's wrapper raises on the same.
        with pytest.raises(FMICallException):
            s.fmu.deSerializeFMUstate(bytes(flipped))
        # The original still works, and a freed handle is refused.
        s.fmu.setFMUstate(state)
        s.fmu.freeFMUstate(state)
        assert s.call("fmi2SetFMUstate", s.c, c_void_p(0x1234)) == ERROR
        s.ramp(RAMP, STEPS, first=2, last=3)


def test_models_differing_in_one_number_have_two_guids_and_refuse_each_others_states(tmp_path):
    """Issue 9 item 5: the GUID covers the model, not only the interface: two FMUs of the hinged
    panel whose models differ in one node's height (same variables, same XML but the GUID)
    carry different GUIDs, and a state serialized by one is refused by the other, named."""
    import json

    from conftest import ROOT, pack
    from membrane_contact import Film, FmuError

    model = json.loads((ROOT / "examples" / "hinged_panel.json").read_text())
    paths = []
    for k, dz in enumerate((0.0, 1e-3)):
        m = json.loads(json.dumps(model))
        m["nodes"][40][2] += dz
        (tmp_path / f"m{k}").mkdir()
        (tmp_path / f"m{k}" / "model.json").write_text(json.dumps(m))
        paths.append(pack(tmp_path / f"m{k}" / "model.json", tmp_path / f"m{k}"))
    with Film(paths[0]) as a, Film(paths[1]) as b:
        assert a.md.guid != b.md.guid
        assert [v.name for v in a.md.modelVariables] == [v.name for v in b.md.modelVariables]
        a.run({"time": [1.0], "rail.angle": [0.05]})
        data = a.serialize(a.save())
        b.initialize()
        with pytest.raises(FmuError, match=re.escape(f"serialized by another FMU (GUID {a.md.guid}); this one is")):
            b.deserialize(data, time=1.0)


@pytest.mark.parametrize("law", ["isotropic", "sliding-direction"])
def test_film_restores_its_own_state_under_either_friction_law(fmu_path, law):
    """Issue 17, defect 1: ``Film.run`` to ``frame.dz`` = −0.03, −0.06, −0.09, ``save()``, one more
    step, ``restore()``: the FMU takes back the state it saved, also under the paper's
    sliding-direction law (it refused it), and the step repeated from there (in place, and from
    the serialized state in a fresh film) gives the same outputs bit for bit."""
    from membrane_contact import Film

    path = {"time": [1.0, 2.0, 3.0], "frame.dz": [-0.03, -0.06, -0.09]}
    one_more = {"time": [4.0], "frame.dz": [-0.12]}
    with Film(fmu_path) as film:
        film.initialize(parameters={"frictionLaw": law})
        film.run(path)
        state = film.save()
        data = film.serialize(state)
        first = film.run(one_more)
        assert 2 in first["G1.status"], "a gap slides in the step after the save"
        film.restore(state)
        again = film.run(one_more)
        for name in film.outputs:
            assert again[name].tobytes() == first[name].tobytes(), name
    with Film(fmu_path) as fresh:
        fresh.initialize()
        fresh.restore(fresh.deserialize(data, time=3.0))
        assert fresh.get("frictionLaw") == law
        restored = fresh.run(one_more)
        for name in fresh.outputs:
            assert restored[name].tobytes() == first[name].tobytes(), name
