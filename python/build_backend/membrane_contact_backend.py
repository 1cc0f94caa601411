"""PEP 517 backend of the wheel (python/pyproject.toml): maturin, after cargo has built the FMU's
shared library.

maturin's ``bin`` bindings build and ship the programs ``membrane-contact`` and ``fmu-pack``
only. The library (the crate's cdylib, which every FMU carries) is built here with
``cargo build --release --locked --lib`` into the same ``target/release`` (so an up-to-date
target is reused, not rebuilt) and staged as wheel data, ``lib/membrane-contact/``: pip installs
it to ``PREFIX/lib/membrane-contact/libmembrane_contact.so`` beside ``PREFIX/bin/fmu-pack``, where
fmu-pack looks for it. The hydraulic jack of the coupled erection system (``fmu/jack``, a small
crate of the workspace) is built the same way and staged beside it with its model description
(``libhydraulic_jack.so``, ``hydraulic_jack.xml``), so that the installed
``membrane_contact.ssp.pack_jack_fmu`` packs ``HydraulicJack.fmu`` without a Rust toolchain.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import maturin

PYTHON = Path(__file__).resolve().parents[1]
ROOT = PYTHON.parent
LIBRARY = "libmembrane_contact.so"
#: The jack's package, library and model description as staged (keep in step with
#: membrane_contact/ssp.py: INSTALLED_JACK_LIBRARY, INSTALLED_JACK_DESCRIPTION).
JACK_PACKAGE, JACK_LIBRARY, JACK_DESCRIPTION = "hydraulic-jack-fmu", "libhydraulic_jack.so", "hydraulic_jack.xml"
#: Wheel data → PREFIX/lib/membrane-contact (keep in step with INSTALLED_LIBRARY_DIR in fmu/pack.rs).
STAGED = PYTHON / "membrane_contact.data" / "data" / "lib" / "membrane-contact"

# A build from source uses the cargo on PATH; without one it stops with a message instead of
# letting maturin download a Rust toolchain into a temporary directory.
os.environ.setdefault("MATURIN_NO_INSTALL_RUST", "1")

get_requires_for_build_wheel = maturin.get_requires_for_build_wheel
prepare_metadata_for_build_wheel = maturin.prepare_metadata_for_build_wheel
build_sdist = maturin.build_sdist
get_requires_for_build_sdist = maturin.get_requires_for_build_sdist
get_requires_for_build_editable = maturin.get_requires_for_build_editable


def _build_cdylib(cargo: str, package: str, library: str) -> Path:
    """``cargo build --release --locked -p package --lib``; the path of the cdylib ``library``."""
    build = subprocess.run([cargo, "build", "--release", "--locked", "-p", package, "--lib",
                            "--message-format=json"], cwd=ROOT, stdout=subprocess.PIPE, text=True, check=True)
    built = [path for line in build.stdout.splitlines() if line.startswith("{")
             for message in [json.loads(line)]
             if message.get("reason") == "compiler-artifact" and "cdylib" in message["target"]["kind"]
             for path in message["filenames"] if path.endswith(library)]
    if len(built) != 1:
        raise RuntimeError(f"cargo build -p {package} --lib made {len(built)} {library} (expected 1): {built}")
    return Path(built[0])


def _stage(source: Path, name: str, mode: int) -> Path:
    STAGED.mkdir(parents=True, exist_ok=True)
    staged = STAGED / name
    staged.unlink(missing_ok=True)
    shutil.copy2(source, staged)
    os.chmod(staged, mode)
    return staged


def stage_library() -> Path:
    """Builds the film's and the jack's cdylibs with cargo and copies them (and the jack's model
    description) into the wheel's data; returns the film library's copy."""
    cargo = shutil.which("cargo")
    if cargo is None:
        raise RuntimeError("building the membrane-contact wheel needs cargo (a Rust toolchain) on PATH; "
                           "installing a built wheel does not")
    staged = _stage(_build_cdylib(cargo, "membrane-contact", LIBRARY), LIBRARY, 0o755)
    _stage(_build_cdylib(cargo, JACK_PACKAGE, JACK_LIBRARY), JACK_LIBRARY, 0o755)
    _stage(ROOT / "fmu" / "jack" / "modelDescription.xml", JACK_DESCRIPTION, 0o644)
    return staged


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    """PEP 517: the library staged, then maturin's wheel."""
    stage_library()
    return maturin.build_wheel(wheel_directory, config_settings, metadata_directory)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    """PEP 660 (``pip install -e ./python``): the library staged, then maturin's editable wheel."""
    stage_library()
    return maturin.build_editable(wheel_directory, config_settings, metadata_directory)
