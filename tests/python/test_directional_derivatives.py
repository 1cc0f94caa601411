"""fmi2GetDirectionalDerivative of the film FMU (issue 21 item 1): the derivatives of the
outputs with respect to the inputs agree with central differences of FMU steps (the state
saved before the step and restored around each), through fmpy, to 1e-6 relative (1e-7
absolute for outputs that are zero up to rounding):

* the ParallelArch specimen at a state with gaps open, sticking and slipping (frame.dz, and mu
  at a state where μ has just been raised);
* the specimen on curved supports, its contacts open, sticking and slipping (mu, to 1e-4: the
  tolerances these contacts converge with leave that noise in differences of steps);
* the cushion under pressure (its pressure input);
* the hinged panel (rail.angle).

They are linear in the seed; an unknown reference, a known that is not an input, an unknown
that is not a Real output, and a call before initialization are fmi2Error with a message; fmpy
validate passes with the ModelStructure dependencies, which list every input for every output
(ascending, no ``dependenciesKind``: "dependent" by the schema), the derivatives answer for every
one of them, and the step statistics among the outputs are refused by name. The tangent's factor
held between calls is replaced after a step and a restored state (the answers of an instance
that never held one, bit for bit).
"""

from __future__ import annotations

import json
import subprocess
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest
from fmpy.validation import validate_fmu

from conftest import CLI, ROOT, pack
from membrane_contact import Film
from membrane_contact.film import FmuError

#: One increment per step (the derivatives are the last increment's: module doc of the core's
#: sensitivity; the steps checked are small enough not to be cut back), tight Newton
#: tolerances so that the differences of steps are smooth. The residual's at 1e-11: on the
#: specimen at mu = 1 Newton's iterates reach corrections of 1e-17 m and then alternate between
#: residuals of 0.92e-9 and 1.09e-9 N, 1.5e-12 of the force scale (its rounding floor), so
#: 1e-12 is met by chance or refused as a stall.
EXACT = {"solver.incrementsPerStep": 1,
         "solver.displacementTolerance": 1e-12, "solver.residualTolerance": 1e-11}


def real_outputs(film):
    return [n for n in film.outputs if film.variables[n].type == "Real"
            and not n.startswith("solver.")]


def derivative(film, unknowns, known, seed=1.0):
    vr = film.variables
    return np.array(film._guard("fmi2GetDirectionalDerivative", lambda: film.fmu.getDirectionalDerivative(
        [vr[n].valueReference for n in unknowns], [vr[known].valueReference], [seed])))


def check_against_steps(film, start_inputs, end_inputs, known, delta, h=1.0, rtol=1e-6):
    """Steps from the current state to ``end_inputs``; compares the derivatives w.r.t.
    ``known`` with central differences of the same step with ``known`` moved by ±delta."""
    start = film.save()
    film.set(end_inputs)
    assert film.step(h) in (0, 1)
    names = real_outputs(film)
    exact = derivative(film, names, known)
    twice = derivative(film, names, known, 2.0)
    ends = []
    for sign in (1, -1):
        film.restore(start)
        film.set({**end_inputs, known: end_inputs[known] + sign * delta})
        assert film.step(h) in (0, 1)
        ends.append(np.array([film[n] for n in names]))
    film.restore(start)
    film.free(start)
    fd = (ends[0] - ends[1]) / (2 * delta)
    # Relative to the output, or to the largest of its unit (a reaction that is zero by
    # symmetry is compared with the others, not with its own rounding noise).
    units = [film.variables[n].unit for n in names]
    largest = {u: max(abs(f) for f, v in zip(fd, units) if v == u) for u in set(units)}
    scale = np.array([max(abs(f), 1e-6 * largest[u]) for f, u in zip(fd, units)])
    # 1e-7 absolute (SI units per unit seed): outputs that are zero up to rounding (the
    # reactions of a closed cushion, a reaction zero by symmetry), whose differences of steps
    # are the Newton tolerance's noise.
    bad = [(n, e, f) for n, e, f, s in zip(names, exact, fd, scale) if abs(e - f) > rtol * s + 1e-7]
    assert not bad, (known, bad[:5])
    assert np.array_equal(twice, 2 * exact)
    return dict(zip(names, exact))


def lowered_specimen(film, mu):
    """The specimen lowered to dz = -0.13 m with mu = 0.2, then to -0.133 m with ``mu``; returns
    the inputs of the step checked (on to -0.134 m, one increment)."""
    film.initialize({"archHeight": 0.3, **EXACT}, {"mu": 0.2})
    film.run({"time": np.arange(1.0, 14.0), "frame.dz": -0.01 * np.arange(1.0, 14.0)}, quiet=True)
    film.set({"frame.dz": -0.133, "mu": mu})
    assert film.step(1.0) == 0
    return {"frame.dz": -0.134, "mu": mu}


def statuses_after(film, end):
    """The gaps' statuses after the step to ``end`` (the state restored afterwards)."""
    start = film.save()
    film.set(end)
    film.step(1.0)
    statuses = [film[f"G{i}.status"] for i in range(1, 10)]
    assert film["solver.cutbacks"] == 0
    film.restore(start)
    film.free(start)
    return statuses


def test_specimen_derivatives_agree_with_steps_with_gaps_open_sticking_and_slipping(fmu_path):
    with Film(fmu_path, logging=True, quiet=True) as film:
        # mu = 1: the crown gaps G1..G3 stick, G4 slips, G5..G9 are open.
        end = lowered_specimen(film, 1.0)
        # delta: central differences converge as delta² (G4.frictionY, slipping: 1.1e-6 off at
        # 1e-5, 1e-7 at 3e-6, measured), and the residual's floor adds 1e-9 N / delta.
        d = check_against_steps(film, {}, end, "frame.dz", 3e-6)
        statuses = statuses_after(film, end)
        assert set(statuses) == {0, 1, 2}, statuses
        assert d["frame.Rz"] > 0 and d["G1.normalForce"] != 0 and d["G9.normalForce"] == 0


def test_specimen_mu_derivatives_agree_with_steps_with_gaps_sticking_slipping_and_open(fmu_path):
    with Film(fmu_path, logging=True, quiet=True) as film:
        # mu = 0.5: G1, G2 stick, G3, G4 slip, G5..G9 are open.
        end = lowered_specimen(film, 0.5)
        # delta: the gap normal forces of a step are exact to ~1e-9 N (k_n = 2.5e8 N/m times
        # the rounding of the displacements), which a smaller delta turns into more than 1e-6
        # of their derivatives; the differences' own truncation is still below 1e-6 here.
        d = check_against_steps(film, {}, end, "mu", 3e-4)
        assert statuses_after(film, end) == [1, 1, 2, 2, 0, 0, 0, 0, 0]
        # A slipping gap's friction grows with mu; an open gap's forces do not move.
        assert d["G3.frictionForce"] > 0 and d["G4.frictionForce"] > 0
        assert d["G9.normalForce"] == 0 and d["frame.Rz"] != 0


def test_curved_support_mu_derivatives_agree_with_steps(cli, tmp_path):
    """The specimen on curved supports (node-to-tube contacts, no gaps): mu moves the contacts'
    friction too. Before, their own coefficients were never moved (the derivatives were 0
    against 20.9 N per unit mu from steps)."""
    text = subprocess.run([str(CLI), "export-specimen", "--height", "300", "--contact", "curved-support"],
                          check=True, capture_output=True, text=True).stdout
    model = json.loads(text)
    model["name"] = "Curved300"
    assert not model["gaps"]
    model_file = tmp_path / "curved.json"
    model_file.write_text(json.dumps(model))
    nodes = model["curved_supports"][0]["nodes"]
    with Film(pack(model_file, tmp_path / "fmu"), logging=True, quiet=True) as film:
        # Tolerances of 1e-8: 1e-12 stalls on these contacts. The differences of steps are then
        # exact to ~1e-5 of the derivatives only (a larger delta, 1e-3, halves that noise).
        film.initialize({"solver.incrementsPerStep": 1, "solver.displacementTolerance": 1e-8,
                         "solver.residualTolerance": 1e-8}, {"mu": 0.2})
        film.run({"time": np.arange(1.0, 14.0), "frame.dz": -0.01 * np.arange(1.0, 14.0)}, quiet=True)
        film.set({"frame.dz": -0.133, "mu": 0.5})
        assert film.step(1.0) == 0
        end = {"frame.dz": -0.134, "mu": 0.5}
        d = check_against_steps(film, {}, end, "mu", 1e-3, rtol=1e-4)
        start = film.save()
        film.set(end)
        film.step(1.0)
        statuses = {int(film[f"arch.node{v}.status"]) for v in nodes}
        film.restore(start)
        assert statuses == {0, 1, 2}, statuses
        assert all(d[f"arch.node{v}.frictionForce"] != 0 for v in nodes[:2]), d


def test_cushion_derivatives_with_respect_to_its_pressure_agree_with_steps(tmp_path):
    fmu = pack(ROOT / "examples" / "cushion.json", tmp_path)
    with Film(fmu, logging=True, quiet=True) as film:
        film.initialize(EXACT)
        pressure = [n for n in film.inputs if n.endswith(".pressure")][0]
        film.set({pressure: 200.0})
        film.step(1.0)
        check_against_steps(film, {}, {pressure: 300.0}, pressure, 1e-2)


def test_hinged_panel_derivatives_with_respect_to_the_angle_agree_with_steps(tmp_path):
    fmu = pack(ROOT / "examples" / "hinged_panel.json", tmp_path)
    with Film(fmu, logging=True, quiet=True) as film:
        film.initialize(EXACT)
        film.set({"rail.angle": 0.05})
        film.step(1.0)
        d = check_against_steps(film, {}, {"rail.angle": 0.1}, "rail.angle", 1e-5)
        assert d["rail.moment"] != 0


def test_a_restored_state_answers_like_an_instance_that_never_held_a_factor(fmu_path):
    """The factorized tangent held between calls belongs to one state: after a step (the next
    state's factor held) and fmi2SetFMUstate back, the derivatives are bit for bit those of
    another instance restored to the same state, whose first call they are."""
    with Film(fmu_path, quiet=True) as a, Film(fmu_path, quiet=True) as b:
        end = lowered_specimen(a, 1.0)
        assert lowered_specimen(b, 1.0) == end
        names = real_outputs(a)
        saved = a.save(), b.save()
        a.set(end)
        assert a.step(1.0) == 0
        stepped = derivative(a, names, "frame.dz"), derivative(a, names, "mu")
        a.restore(saved[0])
        b.restore(saved[1])
        for known, other in zip(("frame.dz", "mu"), stepped):
            restored = derivative(a, names, known)
            assert np.array_equal(restored, derivative(b, names, known)), known
            assert not np.array_equal(restored, other), known


def test_bad_derivative_requests_are_refused_with_a_message(fmu_path):
    with Film(fmu_path, logging=True, quiet=True) as film:
        v = film.variables
        with pytest.raises(FmuError, match="fmi2GetDirectionalDerivative"):
            derivative(film, ["frame.Rz"], "frame.dz")  # before initialization
        film.initialize({"archHeight": 0.3})
        with pytest.raises(FmuError, match="unknown value reference 99999"):
            film._guard("fmi2GetDirectionalDerivative",
                        lambda: film.fmu.getDirectionalDerivative([99999], [v["frame.dz"].valueReference], [1.0]))
        with pytest.raises(FmuError, match="archHeight .* is not an input"):
            derivative(film, ["frame.Rz"], "archHeight")
        with pytest.raises(FmuError, match="G1.status .* is not a Real output"):
            derivative(film, ["G1.status"], "frame.dz")


def test_fmpy_validate_passes_with_the_directional_derivatives(fmu_path):
    assert validate_fmu(str(fmu_path)) == []
    with Film(fmu_path) as film:
        assert film.md.coSimulation.providesDirectionalDerivative


def test_model_structure_declares_the_dependencies_the_derivatives_answer(fmu_path):
    with zipfile.ZipFile(fmu_path) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    variables = root.find("ModelVariables").findall("ScalarVariable")
    inputs = [i + 1 for i, v in enumerate(variables) if v.get("causality") == "input"]
    unknowns = root.find("ModelStructure").find("Outputs").findall("Unknown")
    outputs = [i + 1 for i, v in enumerate(variables) if v.get("causality") == "output"]
    assert [int(u.get("index")) for u in unknowns] == outputs
    for u in unknowns:
        assert [int(i) for i in u.get("dependencies").split()] == inputs, u.attrib
        assert "dependenciesKind" not in u.attrib
    names = [variables[i - 1].get("name") for i in inputs]
    assert names == ["mu", "frame.dx", "frame.dy", "frame.dz"]
    with Film(fmu_path, logging=True, quiet=True) as film:
        film.initialize({"archHeight": 0.3})
        film.set({"frame.dz": -0.02})
        film.step(1.0)
        real = [n for n in film.outputs if film.variables[n].type == "Real"]
        statistics = [n for n in real if n.startswith("solver.")]
        assert statistics == [
            "solver.residual",
            "solver.stabilizationEnergy",
            "solver.stabilizationRatio",
            "solver.dissipationRatio",
        ]
        for known in names:
            d = derivative(film, real_outputs(film), known)
            assert np.all(np.isfinite(d)), known
        for name in statistics:
            with pytest.raises(FmuError, match=f"{name} .* is not a Real output"):
                derivative(film, [name], "frame.dz")
