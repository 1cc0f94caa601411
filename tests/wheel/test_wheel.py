"""The wheel (issue 17 item 10): ``pip install membrane_contact-*.whl`` gives a machine without a
Rust toolchain the programs ``membrane-contact`` and ``fmu-pack`` and ``membrane_contact.build_fmu``.

Run by ``tests/wheel/run.sh`` in a clean venv (the wheel, its dependencies and pytest) with no
cargo on PATH. This directory has no conftest: nothing puts the checkout's ``python/`` on the path.

TEST GOAL:
* the package imported is the wheel's (the venv's site-packages, not the checkout), its commands
  are the venv's, and neither cargo nor rustc can be reached;
* ``build_fmu`` packs an FMU of ``examples/circular_membrane.json`` with the installed fmu-pack,
  the FMU carries the installed library, and its pressure input lifts the centre to where the
  wheel's CLI puts it; a refused model is reported with fmu-pack's message naming the bad item;
* the specimen FMU packed by the wheel's ``fmu-pack`` (into the current directory, its default
  when installed) steps through ``Film`` to the slips, normal forces and statuses that the
  wheel's CLI computes for the same load path (the recipe of tests/python/test_core_agreement.py);
* ``membrane-contact-import`` (a script of the wheel) turns the example gmsh mesh into a model
  that the installed fmu-pack accepts;
* the hydraulic jack of the coupled erection system ships with the wheel: the installed
  ``pack_jack_fmu`` packs ``HydraulicJack.fmu`` (into the current directory) from the wheel's
  library and model description, and it steps (the coupling and SSP tests of tests/python use it);
  ``pack_jack_fmu(fmi_version=3)`` packs ``HydraulicJack_fmi3.fmu`` from its 3.0 description.
"""

from __future__ import annotations

import csv
import json
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(sysconfig.get_path("scripts"))
LIBRARY = Path(sys.prefix) / "lib" / "membrane-contact" / "libmembrane_contact.so"
STATUS = {0: "Open", 1: "Stick", 2: "Slip"}
GAPS = [f"G{i}" for i in range(1, 10)]


def shipped_library(fmu: Path) -> bytes:
    with zipfile.ZipFile(fmu) as z:
        (name,) = [n for n in z.namelist() if n.startswith("binaries/linux64/")]
        return z.read(name)


def test_the_package_and_commands_are_the_wheels_and_no_rust_toolchain_is_reachable():
    import membrane_contact

    package = Path(membrane_contact.__file__).resolve()
    assert package.is_relative_to(Path(sys.prefix).resolve()) and "site-packages" in package.parts, package
    assert not package.is_relative_to(ROOT / "python")
    assert shutil.which("cargo") is None and shutil.which("rustc") is None
    for command in ("membrane-contact", "fmu-pack", "membrane-contact-import"):
        found = shutil.which(command)
        assert found is not None and Path(found).resolve() == (BIN / command).resolve(), command
    assert LIBRARY.is_file()
    version = subprocess.run(["membrane-contact", "--version"], capture_output=True, text=True, check=True)
    assert membrane_contact.__version__ in version.stdout


def test_build_fmu_packs_a_model_file_with_the_installed_fmu_pack(tmp_path):
    from membrane_contact import Film, build_fmu

    fmu = build_fmu(ROOT / "examples" / "circular_membrane.json", out_dir=tmp_path)
    assert fmu == tmp_path / "CircularMembrane.fmu"
    assert shipped_library(fmu) == LIBRARY.read_bytes()
    with Film(fmu) as film:
        assert film.md.coSimulation.modelIdentifier == "CircularMembrane"
        assert "top.pressure" in film.inputs and "centre.uz" in film.outputs
        results = film.run({"time": [1.0, 2.0], "top.pressure": [100.0, 200.0]}, outputs=["centre.uz"])
    uz = results["centre.uz"]
    assert 0 < uz[1] < uz[2], uz  # the pressure lifts the centre, more pressure more
    # The wheel's CLI ramps the same file's 200 Pa over two steps to the same centre.
    cli = subprocess.run(["membrane-contact", "model", str(ROOT / "examples" / "circular_membrane.json"),
                          "--steps", "2"], capture_output=True, text=True, check=True).stdout
    (cli_uz,) = re.findall(r"output point centre \(node 0\): displacement \(\S+, \S+, (\S+)\) m", cli)
    assert uz[2] == pytest.approx(float(cli_uz), abs=1e-6)

    model = json.loads((ROOT / "examples" / "circular_membrane.json").read_text())
    model["material"]["poisson_ratio"] = 0.7
    with pytest.raises(RuntimeError, match=r"fmu-pack failed: .*material: ν = 0\.7 must lie in"):
        build_fmu(model, out_dir=tmp_path / "refused")
    assert not (tmp_path / "refused" / "CircularMembrane.fmu").exists()


def test_the_specimen_packed_by_the_wheels_fmu_pack_steps_as_the_wheels_cli(tmp_path):
    from membrane_contact import Film

    steps, target = 5, -0.15
    run = subprocess.run(["fmu-pack"], cwd=tmp_path, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    fmu = tmp_path / "ParallelArch.fmu"
    assert shipped_library(fmu) == LIBRARY.read_bytes()
    with Film(fmu) as film:
        film.initialize(parameters={"archHeight": 0.3})  # the CLI's default increments too
        results = film.run({"time": [k + 1.0 for k in range(steps)],
                            "frame.dz": [target * (k + 1) / steps for k in range(steps)]})
    assert results.halvings == 0

    out = tmp_path / "cli.csv"
    subprocess.run(["membrane-contact", "specimen", "--height", "300", "--steps", str(steps), "--csv", str(out),
                    "--quiet"], check=True, capture_output=True, text=True)
    with open(out, newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == steps * len(GAPS)
    for r in rows:
        k, g, where = int(r["step"]), r["gap"], f"step {r['step']} gap {r['gap']}"
        assert results[f"{g}.slip"][k] * 1e3 == pytest.approx(float(r["slip_x_mm"]), abs=1e-6), where
        assert results[f"{g}.slipY"][k] * 1e3 == pytest.approx(float(r["slip_y_mm"]), abs=1e-6), where
        assert results[f"{g}.normalForce"][k] == pytest.approx(float(r["normal_force_N"]), abs=1e-6), where
        assert STATUS[int(results[f"{g}.status"][k])] == r["status"], where
    assert results["G9.slip"][-1] > results["G2.slip"][-1] > 0


def test_the_importer_script_makes_a_model_the_installed_fmu_pack_accepts(tmp_path):
    example = ROOT / "examples" / "film_over_two_arches"
    model = tmp_path / "film.json"
    run = subprocess.run(["membrane-contact-import", str(example / "film_over_two_arches_v22.msh"),
                          str(example / "mapping.json"), "-o", str(model)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    name = json.loads(model.read_text())["name"]
    run = subprocess.run(["fmu-pack", str(model), "--out", str(tmp_path)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert shipped_library(tmp_path / f"{name}.fmu") == LIBRARY.read_bytes()


def test_the_wheel_ships_the_jack_and_packs_its_fmu_without_the_checkout(tmp_path, monkeypatch):
    from fmpy.validation import validate_fmu

    from membrane_contact import Film
    from membrane_contact.ssp import pack_jack_fmu

    monkeypatch.chdir(tmp_path)
    fmu = pack_jack_fmu()
    assert fmu == tmp_path / "HydraulicJack.fmu"
    assert shipped_library(fmu) == (LIBRARY.parent / "libhydraulic_jack.so").read_bytes()
    with zipfile.ZipFile(fmu) as z:
        assert z.read("modelDescription.xml") == (ROOT / "fmu" / "jack" / "modelDescription.xml").read_bytes()
    assert validate_fmu(str(fmu)) == []
    with Film(fmu) as jack:
        jack.initialize()
        jack.set({"force": -100.0})
        jack.step(5.0)
        assert jack["piston"] == pytest.approx(-5.0 * 5e-4)  # pumping at its 0.5 mm/s
    # Its FMI 3.0 FMU from the wheel's copy of the 3.0 description.
    fmu3 = pack_jack_fmu(fmi_version=3)
    assert fmu3 == tmp_path / "HydraulicJack_fmi3.fmu"
    with zipfile.ZipFile(fmu3) as z:
        assert z.read("modelDescription.xml") == (ROOT / "fmu" / "jack" / "modelDescription3.xml").read_bytes()
        assert z.read("binaries/x86_64-linux/hydraulic_jack.so") == shipped_library(fmu)
    assert validate_fmu(str(fmu3)) == []
