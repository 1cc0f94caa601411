"""Bubble inflation through the FMU (issue 20): a clamped circular ETFE foil inflated past yield
by pressure, against an independent axisymmetric membrane solution.

TEST GOAL: the plastic film's pressure–height curve, driven through the FMU by the pressure input
alone, matches the axisymmetric solution of ``axisymmetric_membrane.py`` (a 1-D meridian of
conical frusta, incremental plane-stress J2 in principal Hencky strains, isochoric thickness,
written for this test; nothing of the product is called) within 0.5 % in pressure at every
measured height (the issue asks for 1 %; measured 0.28 %), up to a pole height of 0.44 of the
radius (the issue asks for at least 0.4); the smallest thickness within 1 % at every height, the
largest plastic strain within 1 % at the end. The reference's pressure rises monotonically up to
there: the data-sheet curve has no pressure maximum before 0.45 a under pure pressure control.

MATERIAL: ETFE of the data sheet `docs/mechanics.md` cites (E = 1100 MPa, yield 21 MPa, tensile
strength 50 MPa at 450 % elongation), ν = 0.43 (our reading notes: 0.42–0.45); the bilinear
table in true stress against log plastic strain is rebuilt from those numbers
(``τ = σ_nom (1 + ε_nom)``, ``ε̄p = ln(1 + ε_nom) − τ/E``) by ``examples/bubble_inflation.py``,
which also builds the model, drives the FMU and calls the reference for this test.

MODEL: a flat, unstressed disc of radius 0.1 m and 250 µm, meshed in 12 rings
(``ring_mesh`` of ``examples/slack_films.py``: 469 nodes, 864 triangles), rim group held, follower
pressure set ``inside`` towards +z, no prestress; the FMU starts it from flat (the first step
needs the product's slack-start handling). Pressures from 50 Pa to 150 kPa in 24 steps.
``examples/bubble_inflation.py`` runs a finer mesh (20 rings) and draws the curves.
"""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest
from conftest import ROOT, pack_model


def _example(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: The model, the pressure path, the FMU driver and the call of the reference.
bubble = _example("bubble_inflation")
RADIUS, PRESSURES = bubble.RADIUS, bubble.PRESSURES


@pytest.fixture(scope="module")
def bubble_fmu(tmp_path_factory):
    return pack_model(bubble.bubble_model(12), tmp_path_factory.mktemp("bubble"))


def test_bubble_inflated_past_yield_follows_the_axisymmetric_membrane_solution(bubble_fmu):
    heights, thickness, strain = bubble.inflate(bubble_fmu)
    assert np.all(np.diff(heights) > 0)
    assert heights[-1] >= 0.4 * RADIUS
    assert strain[-1] > 0.1  # well past yield: the pole has thinned by about a fifth
    pressures, ref_thickness, ref_strain = bubble.reference(heights)
    # no pressure maximum up to the last height: pressure control can follow the whole curve
    assert np.all(np.diff(pressures) > 0)
    error = np.array(PRESSURES) / pressures - 1
    assert np.max(np.abs(error)) < 0.005, error  # the issue asks for 1 %; measured 0.28 %
    assert thickness == pytest.approx(ref_thickness, rel=0.01)
    # yield starts between the same two steps as in the reference, and ends as far
    assert list(strain > 0) == list(ref_strain > 0)
    assert strain[-1] == pytest.approx(ref_strain[-1], rel=0.01)
