"""Form finding and cutting patterns through the Python package (issue 46):
``membrane_contact.design`` runs the program's ``form-find`` and ``pattern``."""

import json
import math
from pathlib import Path

import pytest

from membrane_contact.design import DesignError, form_find, pattern

CATENOID = Path(__file__).resolve().parents[2] / "examples" / "catenoid.json"


def _catenoid_a(r=1.0, h=1.0):
    """``a`` of the stable catenoid ``r = a cosh(z/a)`` through two rings of radius ``r`` ``h``
    apart: the larger root of ``r = a cosh(h/(2a))``, where it grows with ``a`` (``h = r``)."""
    lo, hi = 0.5 * r, r
    for _ in range(200):
        a = 0.5 * (lo + hi)
        lo, hi = (lo, a) if a * math.cosh(h / (2 * a)) > r else (a, hi)
    return 0.5 * (lo + hi)


def test_form_find_gives_the_catenoid_waist_of_the_example():
    found = form_find(CATENOID)
    waist = min(math.hypot(x, y) for x, y, _ in found["nodes"])
    a = _catenoid_a()
    assert abs(waist - 0.84668) < 1e-4, waist  # the README's golden number (32 x 16 cells)
    assert abs(waist / a - 1) < 5e-3, (waist, a)
    assert found["material"]["prestress"][:2] == json.loads(CATENOID.read_text())["material"]["prestress"][:2]


def test_pattern_cuts_the_found_catenoid_into_four_equal_strips_with_their_distortion(tmp_path):
    found = form_find(CATENOID)
    svg = tmp_path / "strips.svg"
    report = pattern(found, seam_planes=[(0, 0, 0, 1, 0, 0), (0, 0, 0, 0, 1, 0)], svg=svg)
    strips = report["strips"]
    assert len(strips) == 4 and report["erections"] == []
    assert sum(len(s["triangles"]) for s in strips) == len(found["triangles"])
    for s in strips:
        assert s["size"] == pytest.approx([1.4830, 1.0701], abs=1e-4)
        assert s["distortion"]["max"] == pytest.approx(0.08233, abs=1e-5)
        assert s["compensation"][0] == pytest.approx(0.00114, abs=1e-5)
    assert svg.read_text().startswith("<svg")
    uniform = pattern(found, seam_planes=[(0, 0, 0, 1, 0, 0)], compensation=0.5)
    assert [s["compensation"] for s in uniform["strips"]] == [[0.005, 0.005]] * 2


def test_a_model_the_program_refuses_raises_design_error_naming_the_item():
    model = json.loads(CATENOID.read_text())
    model["material"]["thickness"] = -1.0
    with pytest.raises(DesignError, match="thickness"):
        form_find(model)
    with pytest.raises(DesignError, match="seam"):
        pattern(json.loads(CATENOID.read_text()), seam_nodes=[[0, 10 ** 9]])
