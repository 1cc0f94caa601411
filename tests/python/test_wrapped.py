"""The crown-to-foot specimen (issue 10 item 3) through its FMU.

TEST GOAL: ``export-specimen --wrap EPS --path-out`` gives a model with one boundary group per
frame node and the staged table of its inputs; the model packs into an FMU whose inputs are
those groups' ``dx, dy, dz``; stepping the table through the FMU (its default increments per step,
the CLI's too) ends where the CLI's run of the same table ends (``model --path``), with every arch
node in contact and the slip along the arch growing from the crown to the foot.

MODEL: the 300 mm specimen on curved supports, wound and extended by 2 % in 10 steps.
"""

from __future__ import annotations

import csv
import json
import subprocess

from conftest import CLI, pack

from membrane_contact import Film


def test_wrapped_specimen_runs_through_the_fmu_as_through_the_cli(cli, tmp_path):
    table = tmp_path / "wrap.csv"
    text = subprocess.run([str(CLI), "export-specimen", "--height", "300", "--contact", "curved-support",
                           "--wrap", "0.02", "--steps", "10", "--path-out", str(table)],
                          check=True, capture_output=True, text=True).stdout
    model = json.loads(text)
    model["name"] = "Wrapped300"
    assert len(model["groups"]) == 21 and all(len(g["nodes"]) == 1 for g in model["groups"])
    model_file = tmp_path / "wrapped.json"
    model_file.write_text(json.dumps(model))
    with open(table) as f:
        rows = list(csv.DictReader(f))
    columns = {k: [float(r[k]) for r in rows] for k in rows[0]}
    assert len(columns) == 1 + 3 * 21

    nodes = model["curved_supports"][0]["nodes"]
    assert len(nodes) == 9  # the checks below loop over them
    with Film(pack(model_file, tmp_path / "fmu"), logging=False) as film:
        assert {f"{g['name']}.{c}" for g in model["groups"] for c in ("dx", "dy", "dz")} <= set(film.inputs)
        film.initialize(inputs={"mu": 0.2})
        film.run(columns, outputs=[])
        slips = [film[f"arch.node{v}.slip"] for v in nodes]
        status = [int(film[f"arch.node{v}.status"]) for v in nodes]

    assert all(s != 0 for s in status), status
    assert abs(slips[0]) < 1e-6 and all(b > a for a, b in zip(slips[1:], slips[2:])), slips
    out = subprocess.run([str(CLI), "model", str(model_file), "--path", str(table), "--quiet"],
                         check=True, capture_output=True, text=True).stdout
    cli_slips = {line.split()[0]: float(line.split()[1]) for line in out.splitlines()
                 if line.startswith("arch.node")}
    for v, s in zip(nodes, slips):
        assert abs(cli_slips[f"arch.node{v}"] - 1e3 * s) < 1e-3, (v, cli_slips[f"arch.node{v}"], s)
