"""Fixtures of the FMU tests.

* ``fmu_path``: ``target/fmu/ParallelArch.fmu`` (packed by ``tests/run.sh``; built here if
  missing);
* ``custom_fmu``: an FMU of a user model file, packed in the test session with
  ``cargo run --release --bin fmu-pack -- custom.json``; the model is the 200 mm specimen as the
  CLI exports it, renamed (model ``CustomArch``, group ``rim``, gaps ``S1``..``S9``) so that every
  variable name must come from the model file;
* ``cli``: runs the core's CLI (``target/release/membrane-contact``), the reference the FMU
  results are compared with.
"""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
# The tests use the package of this checkout (python/), installed or not; test_package.py checks
# the installed copy separately.
sys.path.insert(0, str(ROOT / "python"))
TARGET = ROOT / "target"
PARALLEL_ARCH_FMU = TARGET / "fmu" / "ParallelArch.fmu"
CLI = TARGET / "release" / "membrane-contact"


def cargo(*args, check=True):
    return subprocess.run(["cargo", *args], cwd=ROOT, capture_output=True, text=True, check=check)


def pack(model_file, out_dir) -> Path:
    """Packs the FMU of ``model_file`` into ``out_dir`` with ``fmu-pack`` and returns its path
    (``<model name>.fmu``)."""
    cargo("run", "--quiet", "--release", "--bin", "fmu-pack", "--", str(model_file), "--out", str(out_dir))
    name = json.loads(Path(model_file).read_text())["name"]
    path = Path(out_dir) / f"{name}.fmu"
    assert path.exists(), path
    return path


@pytest.fixture(scope="session")
def fmu_path() -> Path:
    if not PARALLEL_ARCH_FMU.exists():
        cargo("build", "--release")
        cargo("run", "--release", "--bin", "fmu-pack")
    return PARALLEL_ARCH_FMU


class Cli:
    """The core's command line: the FMU's reference."""

    def __init__(self, tmp: Path):
        if not CLI.exists():
            cargo("build", "--release")
        self.tmp = tmp

    def run(self, *args) -> list[dict]:
        """Runs the CLI with ``--csv`` and returns the CSV rows (slips in mm)."""
        out = self.tmp / f"cli-{abs(hash(args))}.csv"
        subprocess.run([str(CLI), *map(str, args), "--csv", str(out), "--quiet"], check=True,
                       capture_output=True, text=True)
        with open(out, newline="") as f:
            return list(csv.DictReader(f))

    def final_slips_mm(self, *args) -> dict[str, float]:
        rows = self.run(*args)
        last = max(int(r["step"]) for r in rows)
        return {r["gap"]: float(r["slip_x_mm"]) for r in rows if int(r["step"]) == last}

    def export_specimen(self, height_mm) -> dict:
        out = subprocess.run([str(CLI), "export-specimen", "--height", str(height_mm)],
                             check=True, capture_output=True, text=True).stdout
        return json.loads(out)


@pytest.fixture(scope="session")
def cli(tmp_path_factory) -> Cli:
    return Cli(tmp_path_factory.mktemp("cli"))


CUSTOM_GAPS = {f"G{i}": f"S{i}" for i in range(1, 10)}


@pytest.fixture(scope="session")
def custom_model(cli, tmp_path_factory) -> Path:
    """The 200 mm specimen as a user model file, renamed."""
    model = cli.export_specimen(200)
    model["name"] = "CustomArch"
    model["description"] = "user model: the 200 mm specimen, renamed (a test of fmu-pack FILE)"
    for g in model["gaps"]:
        g["name"] = CUSTOM_GAPS[g["name"]]
    (group,) = model["groups"]
    group["name"] = "rim"
    path = tmp_path_factory.mktemp("custom") / "custom.json"
    path.write_text(json.dumps(model, indent=1))
    return path


@pytest.fixture(scope="session")
def custom_fmu(custom_model, tmp_path_factory) -> Path:
    return pack(custom_model, tmp_path_factory.mktemp("custom-fmu"))
