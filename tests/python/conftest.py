"""Fixtures of the FMU tests.

Before any test, the session makes sure the release build (CLI and library) and
``target/fmu/ParallelArch.fmu`` are newer than every source they are built from (the ``.rs``
files of ``src/`` and ``fmu/``, ``Cargo.*``, ``modelDescription.xml.in``): when one is missing or
older, it runs ``cargo build --release`` and ``fmu-pack`` (what ``fmu/prepare.sh`` runs), so
that a pytest run outside ``tests/run.sh`` never compares stale copies.

* ``fmu_path``: ``target/fmu/ParallelArch.fmu``;
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


def newest_source() -> float:
    """The latest modification time of the files the release build and the FMU are made from."""
    files = [ROOT / "Cargo.toml", ROOT / "Cargo.lock", ROOT / "modelDescription.xml.in"]
    files += [p for d in ("src", "fmu") for p in (ROOT / d).rglob("*.rs")]
    return max(p.stat().st_mtime for p in files if p.is_file())


def stale_artefacts() -> list[Path]:
    """The CLI and the ParallelArch FMU if missing or older than a source file."""
    newest = newest_source()
    return [p for p in (CLI, PARALLEL_ARCH_FMU) if not p.is_file() or p.stat().st_mtime < newest]


def pytest_sessionstart(session):
    """Rebuilds the CLI and repacks the FMU when stale (cargo is quick when up to date)."""
    stale = stale_artefacts()
    if not stale:
        return
    for args in (["build", "--release", "--locked"],
                 ["run", "--release", "--locked", "--quiet", "--bin", "fmu-pack"]):
        r = cargo(*args, check=False)
        if r.returncode != 0:
            pytest.exit(f"stale {', '.join(map(str, stale))}: cargo {' '.join(args)} failed:\n{r.stderr}",
                        returncode=1)


@pytest.fixture(scope="session")
def fmu_path() -> Path:
    return PARALLEL_ARCH_FMU


class Cli:
    """The core's command line: the FMU's reference."""

    def __init__(self, tmp: Path):
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
