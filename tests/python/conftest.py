"""Fixtures of the FMU tests.

Two modes. From the checkout (``tests/run.sh``'s ``.venv``), the package is this checkout's
``python/`` and the programs are the release build in ``target/release``; before any test, the
session makes sure that build and ``target/fmu/ParallelArch.fmu`` are newer than every source they
are built from (the ``.rs`` files of ``src/`` and ``fmu/``, ``Cargo.*``, ``modelDescription.xml.in``):
when one is missing or older, it runs ``cargo build --release`` and ``fmu-pack -o
target/fmu/ParallelArch.fmu --library target/release/libmembrane_contact.so`` (the output and the
library named, whatever ``target/`` holds), and it checks that the FMU ships that library byte for
byte, so that a pytest run outside ``tests/run.sh`` never compares stale copies.

Installed (``MEMBRANE_CONTACT_INSTALLED=1``, set by ``tests/wheel/run.sh``: the wheel in a clean
venv, no cargo on PATH), the package is the venv's, the programs are the venv's
``membrane-contact`` and ``fmu-pack``, the specimen FMU is packed by that ``fmu-pack`` into a
temporary directory, and nothing is built. Running ``cargo`` or anything of ``target/`` outside
the venv (the checkout's build) fails the test that tries.

* ``fmu_path``: the ParallelArch specimen FMU (``target/fmu/ParallelArch.fmu``, or installed, the
  one the wheel's ``fmu-pack`` packs);
* ``custom_fmu``: an FMU of a user model file, packed in the test session with ``fmu-pack
  custom.json`` (:func:`pack`); the model is the 200 mm specimen as the CLI exports it, renamed
  (model ``CustomArch``, group ``rim``, gaps ``S1``..``S9``) so that every variable name must come
  from the model file;
* ``cli``: runs the core's CLI (:data:`CLI`), the reference the FMU results are compared with.
"""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TARGET = ROOT / "target"
#: The suite runs against the installed wheel (tests/wheel/run.sh), not the checkout.
INSTALLED = os.environ.get("MEMBRANE_CONTACT_INSTALLED") == "1"
#: Why a test that needs the checkout (cargo, fmu/prepare.sh, .venv) is skipped when installed.
NEEDS_CHECKOUT = "needs the checkout's cargo build (MEMBRANE_CONTACT_INSTALLED=1 tests the wheel)"
if INSTALLED:
    VENV = Path(sys.prefix).resolve()
    CLI = Path(sysconfig.get_path("scripts")) / "membrane-contact"
    FMU_PACK = Path(sysconfig.get_path("scripts")) / "fmu-pack"
    PARALLEL_ARCH_FMU = None  # packed by the session (fmu_path)
    os.environ.pop("MEMBRANE_CONTACT_ROOT", None)  # it would make build_fmu pack with cargo
else:
    # The tests use the package of this checkout (python/), installed or not; test_package.py
    # checks the installed copy separately.
    sys.path.insert(0, str(ROOT / "python"))
    CLI = TARGET / "release" / "membrane-contact"
    FMU_PACK = TARGET / "release" / "fmu-pack"
    PARALLEL_ARCH_FMU = TARGET / "fmu" / "ParallelArch.fmu"
#: The FMU's shared library as the release build made it (what every FMU of the checkout ships).
LIBRARY = TARGET / "release" / "libmembrane_contact.so"


def package_env() -> dict:
    """The environment of a Python subprocess that must import the package under test: the
    checkout's ``python/`` ahead on ``PYTHONPATH``, or installed, the venv's as it is."""
    env = dict(os.environ)
    if not INSTALLED:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT / "python"), env.get("PYTHONPATH")]))
    return env


def cargo(*args, check=True):
    return subprocess.run(["cargo", *args], cwd=ROOT, capture_output=True, text=True, check=check)


def fmu_pack(*args) -> subprocess.CompletedProcess:
    """Runs the ``fmu-pack`` under test (the release build's, or the wheel's) with ``args``."""
    return subprocess.run([str(FMU_PACK), *map(str, args)], capture_output=True, text=True)


def pack(model_file, out_dir) -> Path:
    """Packs the FMU of ``model_file`` into ``out_dir`` with ``fmu-pack`` and returns its path
    (``<model name>.fmu``)."""
    r = fmu_pack(model_file, "--out", out_dir)
    assert r.returncode == 0, f"fmu-pack {model_file} failed: {r.stderr}"
    name = json.loads(Path(model_file).read_text())["name"]
    path = Path(out_dir) / f"{name}.fmu"
    assert path.exists(), path
    return path


def pack_model(model: dict, out_dir) -> Path:
    """Writes the model ``model`` to ``out_dir/<name>.json`` and packs its FMU (:func:`pack`)."""
    path = Path(out_dir) / f"{model['name']}.json"
    path.write_text(json.dumps(model))
    return pack(path, out_dir)


def _the_checkouts_build(word) -> bool:
    """``word`` names cargo or a file of ``target/`` that is not in the wheel's venv."""
    if not isinstance(word, (str, os.PathLike)):
        return False
    word = os.fspath(word)
    if os.path.basename(word) in ("cargo", "rustc"):
        return True
    if os.sep not in word:  # a plain argument, not a path
        return False
    path = Path(os.path.abspath(word))
    return path.is_relative_to(TARGET) and not path.is_relative_to(VENV)


def _refuse_the_checkouts_build(event, args):
    """Audit hook of the installed mode: the tests may not run cargo, nor run or open the
    checkout's build (target/release, target/fmu) instead of the wheel's."""
    if event == "open":
        words = [args[0]]
    elif event == "subprocess.Popen":
        executable, argv = args[0], args[1]
        words = [executable, *(argv.replace("'", " ").replace('"', " ").split() if isinstance(argv, str)
                               else argv)]
    else:
        return
    bad = [w for w in words if _the_checkouts_build(w)]
    if bad:
        raise RuntimeError(f"installed mode (MEMBRANE_CONTACT_INSTALLED=1): {os.fspath(bad[0])} is the "
                           "checkout's build or toolchain, not the wheel's")


if INSTALLED:
    sys.addaudithook(_refuse_the_checkouts_build)


def newest_source() -> float:
    """The latest modification time of the files the release build and the FMU are made from."""
    files = [ROOT / "Cargo.toml", ROOT / "Cargo.lock", ROOT / "modelDescription.xml.in",
             ROOT / "fmu" / "jack" / "modelDescription.xml"]
    files += [p for d in ("src", "fmu") for p in (ROOT / d).rglob("*.rs")]
    return max(p.stat().st_mtime for p in files if p.is_file())


def stale_artefacts() -> list[Path]:
    """The CLI, fmu-pack, the library and the ParallelArch FMU if missing or older than a source
    file."""
    newest = newest_source()
    return [p for p in (CLI, FMU_PACK, LIBRARY, PARALLEL_ARCH_FMU) if not p.is_file() or p.stat().st_mtime < newest]


def fmu_library(fmu: Path) -> bytes | None:
    """The shared library an FMU ships (``binaries/linux64/<modelIdentifier>.so``), or None."""
    import zipfile

    try:
        with zipfile.ZipFile(fmu) as z:
            (name,) = [n for n in z.namelist() if n.startswith("binaries/linux64/") and n.endswith(".so")]
            return z.read(name)
    except (OSError, ValueError, zipfile.BadZipFile):
        return None


def pack_specimen(fmu_pack: Path | None = None, fmu: Path | None = None, library: Path | None = None,
                  cwd: Path = ROOT) -> str | None:
    """Packs ``target/fmu/ParallelArch.fmu`` with the release build's ``fmu-pack``, its output
    and library named explicitly (without them fmu-pack writes into the current directory when
    ``target/`` holds no ``CACHEDIR.TAG``, and picks the newest library it finds), then checks
    that the FMU ships the library just built, byte for byte. Returns what went wrong, or None.
    (The arguments, defaulting to the checkout's, let a test run it elsewhere.)"""
    fmu_pack, fmu, library = fmu_pack or FMU_PACK, fmu or PARALLEL_ARCH_FMU, library or LIBRARY
    r = subprocess.run([str(fmu_pack), "-o", str(fmu), "--library", str(library)],
                       cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        return f"fmu-pack -o {fmu} failed:\n{r.stderr}"
    return specimen_mismatch(fmu, library)


def specimen_mismatch(fmu: Path | None = None, library: Path | None = None) -> str | None:
    """Why ``fmu`` (``target/fmu/ParallelArch.fmu``) is not the FMU of the release build (its
    library is not ``library``, ``target/release/libmembrane_contact.so``, byte for byte), or
    None."""
    fmu, library = fmu or PARALLEL_ARCH_FMU, library or LIBRARY
    shipped = fmu_library(fmu)
    if shipped is None:
        return f"{fmu} is missing or has no binaries/linux64/*.so"
    if not library.is_file() or shipped != library.read_bytes():
        return f"{fmu} ships another library than {library} (a stale FMU)"
    return None


def pytest_sessionstart(session):
    """Rebuilds the CLI and repacks the FMU when stale (cargo is quick when up to date).
    Installed: checks that the venv has the wheel's programs, builds nothing."""
    if INSTALLED:
        missing = [str(p) for p in (CLI, FMU_PACK) if not p.is_file()]
        if missing:
            pytest.exit(f"MEMBRANE_CONTACT_INSTALLED=1 but the venv has no {', '.join(missing)}: "
                        "pip install the wheel (tests/wheel/run.sh)", returncode=1)
        return
    stale = stale_artefacts()
    if stale:
        r = cargo("build", "--release", "--locked", check=False)
        if r.returncode != 0:
            pytest.exit(f"stale {', '.join(map(str, stale))}: cargo build --release --locked failed:\n{r.stderr}",
                        returncode=1)
    # The FMU the tests load must ship the library just built: repack it when it does not (a
    # copy packed elsewhere, or before the last build), and stop if that does not help.
    if stale or specimen_mismatch():
        wrong = pack_specimen()
        if wrong:
            pytest.exit(f"the specimen FMU is not the release build's: {wrong}", returncode=1)


@pytest.fixture(scope="session")
def fmu_path(tmp_path_factory) -> Path:
    if not INSTALLED:
        return PARALLEL_ARCH_FMU
    out = tmp_path_factory.mktemp("specimen")
    r = fmu_pack("--out", out)
    assert r.returncode == 0, f"the wheel's fmu-pack failed: {r.stderr}"
    return out / "ParallelArch.fmu"


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
