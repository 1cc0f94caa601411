"""Issue 19's reproductions through the package with default settings (``Film.run``, halving on
Discard): the suction panel over three tube arches (``examples/suction_panel.py``, a small mesh
here, the full one in the benchmark), with and without edge cables — rails lowered, 400 Pa
suction lifting the film off, suction removed — and the flat unstressed disc under its own weight
(``examples/slack_films.py``)."""

from __future__ import annotations

import importlib.util
import json
import re

import numpy as np
import pytest

from conftest import ROOT, pack


def _example(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


suction_panel = _example("suction_panel")
slack_films = _example("slack_films")


def _film(model: dict, tmp_path):
    from membrane_contact import Film

    path = tmp_path / f"{model['name']}.json"
    path.write_text(json.dumps(model))
    return Film(pack(path, tmp_path), logging=False, quiet=True)


@pytest.mark.parametrize("cables", [False, True], ids=["free-edges", "edge-cables"])
def test_suction_lifts_the_panel_off_its_arches_and_its_removal_lays_it_back(cables, tmp_path):
    model = suction_panel.model(17, 9, cables=cables)
    table = suction_panel.load_table()
    with _film(model, tmp_path) as film:
        res = film.run(table)
        assert res.time[-1] == table["time"][-1], film.messages[-3:]
        normal = [f"arch2.node{n}.normalForce" for n in model["curved_supports"][1]["nodes"]]
        erected = int(np.searchsorted(res.time, 10.0))
        lifted = int(np.searchsorted(res.time, 14.0))
        # on the arches after erection, off the middle arch at full suction, back on after
        assert max(res[n][erected] for n in normal) > 10.0
        assert max(res[n][lifted] for n in normal) == 0.0
        assert max(res[n][-1] for n in normal) > 10.0
        # every step reports the artificial energy left by the continuation, within its bound
        ratio = res["solver.stabilizationRatio"]
        assert np.all(ratio <= 2e-4), ratio  # the documented bound (StepReport::stabilization_warning)


def test_a_flat_unstressed_disc_takes_its_own_weight(tmp_path):
    with _film(slack_films.disc(), tmp_path) as film:
        res = film.run({"time": [0.0, 1.0]})
        assert res.time[-1] == 1.0, film.messages[-3:]
        assert res["centre.uz"][-1] < -1e-3


def _cli_disc(model: dict, tmp_path, *options):
    """Runs a disc through the CLI: the centre's final z (m, initial shape included), the mean
    major principal stress of the six centre triangles at the last step (Pa), and the output."""
    import csv
    import subprocess

    from conftest import CLI

    path = tmp_path / f"{model['name']}_{len(options)}.json"
    path.write_text(json.dumps(model))
    elements = tmp_path / f"{path.stem}_elements.csv"
    r = subprocess.run([str(CLI), "model", str(path), "--quiet", "--elements-csv", str(elements), *options],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-2000:]
    uz = float(re.search(r"output point centre .*?displacement \(\S+, \S+, (\S+)\) m", r.stdout).group(1))
    with open(elements) as f:
        rows = list(csv.DictReader(f))
    last = max(int(row["step"]) for row in rows)
    centre = [float(row["principal_1_Pa"]) for row in rows if int(row["step"]) == last and int(row["element"]) < 6]
    return model["nodes"][0][2] + uz, sum(centre) / len(centre), r.stdout + r.stderr


def test_the_flat_disc_under_self_weight_matches_a_curved_start_without_stabilization(tmp_path):
    # Hencky's dead-load problem from the flat, stress-free disc: the first Newton matrix has no
    # out-of-plane stiffness, and the pseudo-time term (or the stabilized rows) hold the film until
    # its own stress does; 0.5 mm of initial sag changes the answer by less than 0.2 %.
    flat_z, flat_stress, flat_out = _cli_disc(slack_films.disc(), tmp_path)
    curved_z, curved_stress, curved_out = _cli_disc(slack_films.disc(sag=5e-4), tmp_path, "--no-stabilization")
    assert flat_z < -5e-3, flat_z
    assert abs(flat_z / curved_z - 1) < 2e-3, (flat_z, curved_z)
    assert abs(flat_stress / curved_stress - 1) < 2e-3, (flat_stress, curved_stress)
    stabilization = re.search(r"stabilization: (\d+) increments viscously stabilized; largest work taken out (\S+) J "
                              r"at step \d+ \((\S+) of the strain energy; bound \S+\), (\S+) J left", flat_out)
    if stabilization:  # where a stabilized row carried a step, the force its answer carries is within 2e-4
        strain_energy = float(stabilization.group(2)) / float(stabilization.group(3))
        assert float(stabilization.group(4)) <= 2e-4 * strain_energy, flat_out[-500:]
    assert "stabilization:" not in curved_out


def test_a_slack_strip_lifted_at_its_middle_takes_the_straight_shape(tmp_path):
    import subprocess

    from conftest import CLI

    model = slack_films.strip()
    path = tmp_path / "strip.json"
    path.write_text(json.dumps(model))
    r = subprocess.run([str(CLI), "model", str(path), "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-2000:]
    # the quarter point of a taut strip between the clamped end and the lifted middle: half the lift
    uz = float(re.search(r"output point quarter .*?displacement \(\S+, \S+, (\S+)\) m", r.stdout).group(1))
    assert abs(uz - 0.05) < 1e-6, uz
