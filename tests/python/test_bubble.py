"""Bubble inflation through the FMU (issue 20): a clamped circular ETFE foil inflated past yield
by pressure, against an independent axisymmetric membrane solution.

TEST GOAL: the plastic film's pressure–height curve, driven through the FMU by the pressure input
alone, matches the axisymmetric solution of ``axisymmetric_membrane.py`` (a 1-D meridian of
conical frusta, incremental plane-stress J2 in principal Hencky strains, isochoric thickness,
written for this test; nothing of the product is called) within 1 % in pressure at every
measured height, up to a pole height of 0.44 of the radius (the test asks for at least 0.4).
The same for the smallest thickness. The reference's pressure rises monotonically up to there:
the data-sheet curve has no pressure maximum before 0.45 a under pure pressure control.

MATERIAL: ETFE of the data sheet `docs/mechanics.md` cites (E = 1100 MPa, yield 21 MPa, tensile
strength 50 MPa at 450 % elongation), ν = 0.43 (our reading notes: 0.42–0.45); the bilinear
table in true stress against log plastic strain is rebuilt here from those numbers
(``τ = σ_nom (1 + ε_nom)``, ``ε̄p = ln(1 + ε_nom) − τ/E``).

MODEL: a flat, unstressed disc of radius 0.1 m and 250 µm, meshed in 12 rings
(``examples/slack_films.py's ``ring_mesh````: 469 nodes, 864 triangles), rim group held, follower
pressure set ``inside`` towards +z, no prestress; the FMU starts it from flat (the first step
needs the product's slack-start handling). Pressures from 50 Pa to 150 kPa in 24 steps.
``examples/bubble_inflation.py`` runs a finer mesh and draws the curves.
"""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest
from axisymmetric_membrane import Bubble, Film, Hardening
from conftest import ROOT, pack_model
from fmu_helpers import OK, Slave

RADIUS, T0, E, NU = 0.1, 250e-6, 1100e6, 0.43
YIELD, STRENGTH, ELONGATION = 21e6, 50e6, 4.5


def datasheet_hardening():
    """Bilinear (ε̄p, σy) rows from initial yield to the data sheet's breaking point."""
    tau = STRENGTH * (1 + ELONGATION)
    return [[0.0, YIELD], [math.log(1 + ELONGATION) - tau / E, tau]]


#: Pressure at the end of each communication step (Pa).
PRESSURES = [50, 200, 600, 1500, 3000, 5000, 8000, 11000, 15000, 20000, 26000, 33000, 40000, 50000,
             60000, 70000, 80000, 90000, 100000, 110000, 120000, 130000, 140000, 150000]


def _slack_films():
    spec = importlib.util.spec_from_file_location("slack_films", ROOT / "examples" / "slack_films.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def bubble_model(rings, hardening=None):
    """The clamped flat disc with the plastic film and the pressure set ``inside``."""
    nodes, triangles, rim = _slack_films().ring_mesh(RADIUS, rings)
    return {
        "name": "Bubble",
        "description": "clamped circular ETFE foil inflated past yield (bubble-inflation test, issue 20)",
        "nodes": nodes,
        "triangles": triangles,
        "material": {"youngs_modulus": E, "poisson_ratio": NU, "thickness": T0, "prestress": [0.0, 0.0, 0.0],
                     "plasticity": {"hardening": hardening or datasheet_hardening()}},
        "groups": [{"name": "rim", "nodes": list(range(rim, len(nodes))), "target": [0.0, 0.0, 0.0]}],
        "loads": {"pressures": [{"name": "inside", "elements": "all", "pressure": PRESSURES[-1], "towards": "+z"}]},
        "outputs": {"points": [{"name": "pole", "node": 0}], "element_sets": [{"name": "foil", "elements": "all"}]},
    }


def inflate(fmu, pressures=PRESSURES):
    """Pole heights, smallest thicknesses and largest ε̄p after each pressure step."""
    heights, thickness, strain = [], [], []
    with Slave(fmu) as s:
        s.initialize()
        for k, p in enumerate(pressures):
            s.set({"inside.pressure": float(p)})
            status = s.step(k * 0.25, 0.25)
            assert status == OK, f"step {k} (p = {p} Pa): status {status}: {s.messages[-3:]}"
            heights.append(s.get("pole.uz"))
            thickness.append(s.get("film.minThickness"))
            strain.append(s.get("foil.maxPlasticStrain"))
    return np.array(heights), np.array(thickness), np.array(strain)


def reference(heights, hardening=None, n=50, **film):
    """Pressures, smallest thickness and largest ε̄p of the axisymmetric solution at ``heights``."""
    rows = hardening or datasheet_hardening()
    bubble = Bubble(Film(E, NU, T0, Hardening(rows), **film), RADIUS, n)
    return bubble.inflate(np.asarray(heights), max_increment=0.01 * RADIUS)


@pytest.fixture(scope="module")
def bubble_fmu(tmp_path_factory):
    return pack_model(bubble_model(12), tmp_path_factory.mktemp("bubble"))


def test_bubble_inflated_past_yield_follows_the_axisymmetric_membrane_solution(bubble_fmu):
    heights, thickness, strain = inflate(bubble_fmu)
    assert np.all(np.diff(heights) > 0)
    assert heights[-1] >= 0.4 * RADIUS
    assert strain[-1] > 0.1  # well past yield: the pole has thinned by about a fifth
    pressures, ref_thickness, ref_strain = reference(heights)
    # no pressure maximum up to the last height: pressure control can follow the whole curve
    assert np.all(np.diff(pressures) > 0)
    error = np.array(PRESSURES) / pressures - 1
    assert np.max(np.abs(error)) < 0.005, error  # the issue asks for 1 %; measured 0.28 %
    assert thickness == pytest.approx(ref_thickness, rel=0.01)
    # yield starts between the same two steps as in the reference, and ends as far
    assert list(strain > 0) == list(ref_strain > 0)
    assert strain[-1] == pytest.approx(ref_strain[-1], rel=0.01)
