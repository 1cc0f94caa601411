"""Output points, element-set summaries, reactions and warnings through fmpy (issue 8, item 3).

TEST GOAL: the FMU packed from ``examples/circular_membrane.json`` reports its output point
``centre`` and element set ``disc``; the set over every triangle agrees with the film-wide
outputs; the total restraint force equals the rim group's reaction (the only restraint); with
``material.yield_stress`` below the stress the pressure reaches, ``fmi2DoStep`` returns
fmi2Warning (which fmpy does not raise on), logs the reason, and the run goes on.

BOUNDARY CONDITIONS: rim held at zero; ``top.pressure`` ramped 0 → 200 Pa in 4 steps; gravity
and the lamp load applied in the first step.
"""

from __future__ import annotations

import json

import pytest
from conftest import ROOT
from conftest import pack as pack_file
from fmu_helpers import OK, WARNING, Slave

EXAMPLE = ROOT / "examples" / "circular_membrane.json"


def pack(tmp_path, model: dict, name: str):
    source = tmp_path / f"{name}.json"
    source.write_text(json.dumps(model))
    return pack_file(source, tmp_path)


def test_output_point_set_summary_and_total_reaction(tmp_path):
    fmu = pack(tmp_path, json.loads(EXAMPLE.read_text()), "plain")
    with Slave(fmu) as s:
        v = s.variables
        assert v["centre.uz"].causality == "output" and v["centre.uz"].unit == "m"
        assert v["disc.compressedArea"].unit == "m2"
        s.initialize(inputs={"top.pressure": 0.0})
        for k in range(4):
            s.set({"top.pressure": 50.0 * (k + 1)})
            assert s.step(k / 4, 0.25) == OK, s.messages[-3:]
        assert s.get("centre.uz") > 0.01, "the centre rises under 200 Pa"
        assert s.get("disc.maxEquivalentStress") == s.get("film.maxEquivalentStress")
        assert s.get("disc.minPrincipalStress") > 0.0 and s.get("disc.compressedArea") == 0.0
        assert s.get("reactions.Rz") == pytest.approx(s.get("rim.Rz"), rel=1e-12)


def test_stress_above_the_yield_stress_is_a_warning_and_the_run_goes_on(tmp_path):
    model = json.loads(EXAMPLE.read_text())
    model["name"] = "YieldingMembrane"
    model["material"]["yield_stress"] = 3.0e6
    fmu = pack(tmp_path, model, "yielding")
    with Slave(fmu) as s:
        s.initialize(inputs={"top.pressure": 0.0})
        statuses = []
        for k in range(4):
            s.set({"top.pressure": 50.0 * (k + 1)})
            statuses.append(s.step(k / 4, 0.25))
        assert statuses[0] == OK and statuses[-1] == WARNING, statuses
        assert s.logged(WARNING, "above the material's yield_stress 3.000 MPa")
        assert s.get("film.maxEquivalentStress") > 3.0e6
