"""PEP 517 backend of the wheel (python/pyproject.toml): maturin, after cargo has built the FMU's
shared library.

maturin's ``bin`` bindings build and ship the programs ``membrane-contact`` and ``fmu-pack``
only. The library (the crate's cdylib, which every FMU carries) is built here with
``cargo build --release --locked --lib`` into the same ``target/release`` (so an up-to-date
target is reused, not rebuilt) and staged as wheel data, ``lib/membrane-contact/``: pip installs
it to ``PREFIX/lib/membrane-contact/libmembrane_contact.so`` beside ``PREFIX/bin/fmu-pack``, where
fmu-pack looks for it. The hydraulic jack of the coupled erection system (``fmu/jack``, a small
crate of the workspace) is built the same way and staged beside it with its model description
(``libhydraulic_jack.so``, ``hydraulic_jack.xml``, ``hydraulic_jack3.xml``: FMI 2.0 and 3.0),
so that the installed ``membrane_contact.ssp.pack_jack_fmu`` packs ``HydraulicJack.fmu`` (and
``HydraulicJack_fmi3.fmu``) without a Rust toolchain.
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
JACK_DESCRIPTION3 = "hydraulic_jack3.xml"  # its FMI 3.0 description (INSTALLED_JACK_DESCRIPTION3)
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
    _stage(ROOT / "fmu" / "jack" / "modelDescription3.xml", JACK_DESCRIPTION3, 0o644)
    return staged


def console_scripts() -> dict[str, str]:
    """``[tool.membrane-contact.scripts]`` of pyproject.toml: ``{name: "module:function"}``."""
    try:
        import tomllib
    except ImportError:  # Python < 3.11
        import tomli as tomllib

    with open(PYTHON / "pyproject.toml", "rb") as f:
        tool = tomllib.load(f).get("tool", {}).get("membrane-contact", {})
    return dict(tool.get("scripts", {}))


def add_console_scripts(wheel: Path, scripts: dict[str, str]) -> None:
    """Writes ``scripts`` as the ``[console_scripts]`` of the wheel's ``entry_points.txt`` (its
    ``.dist-info``), the RECORD updated: what maturin writes for ``[project.scripts]``, which it
    refuses beside bin bindings."""
    import base64
    import hashlib
    import zipfile

    if not scripts:
        return
    with zipfile.ZipFile(wheel) as z:
        entries = [(info, z.read(info)) for info in z.infolist()]
    (dist_info,) = {info.filename.split("/", 1)[0] for info, _ in entries
                    if info.filename.split("/", 1)[0].endswith(".dist-info")}
    name = f"{dist_info}/entry_points.txt"
    old = next((data.decode() for info, data in entries if info.filename == name), "")
    if "[console_scripts]" in old:
        raise RuntimeError(f"{wheel.name}: maturin already wrote console scripts: {old!r}")
    text = (old.rstrip() + "\n\n" if old.strip() else "") + "[console_scripts]\n" + \
        "".join(f"{k} = {v}\n" for k, v in sorted(scripts.items()))
    data = text.encode()
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    record = f"{dist_info}/RECORD"
    tmp = wheel.with_suffix(".tmp")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as out:
        for info, content in entries:
            if info.filename == name:
                continue
            if info.filename == record:
                lines = [ln for ln in content.decode().splitlines() if ln and not ln.startswith(f"{name},")]
                lines.insert(len(lines) - 1 if lines and lines[-1].startswith(f"{record},") else len(lines),
                             f"{name},sha256={digest},{len(data)}")
                content = ("\n".join(lines) + "\n").encode()
                out.writestr(info, content)
                continue
            out.writestr(info, content)
        info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
        info.external_attr = 0o644 << 16
        info.compress_type = zipfile.ZIP_DEFLATED
        out.writestr(info, data)
    os.replace(tmp, wheel)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    """PEP 517: the library staged, then maturin's wheel, then the console scripts."""
    stage_library()
    name = maturin.build_wheel(wheel_directory, config_settings, metadata_directory)
    add_console_scripts(Path(wheel_directory) / name, console_scripts())
    return name


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    """PEP 660 (``pip install -e ./python``): the library staged, then maturin's editable wheel,
    then the console scripts."""
    stage_library()
    name = maturin.build_editable(wheel_directory, config_settings, metadata_directory)
    add_console_scripts(Path(wheel_directory) / name, console_scripts())
    return name
