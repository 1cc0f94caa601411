"""Where FMUs come from: the repository's ``target/fmu/`` or ``fmu-pack`` run on a model file
(the checkout's, through cargo, or the one installed with this package from the wheel)."""

from __future__ import annotations

import importlib.metadata
import json
import os
import subprocess
from pathlib import Path

#: Environment variable naming an FMU to use when none is given.
FMU_VARIABLE = "MEMBRANE_CONTACT_FMU"
#: Environment variable naming the repository (for ``build_fmu`` and ``find_fmu``) when the
#: package is installed outside it.
ROOT_VARIABLE = "MEMBRANE_CONTACT_ROOT"


def _is_repository(path: Path) -> bool:
    return (path / "Cargo.toml").is_file() and (path / "fmu").is_dir()


def _own_checkout() -> Path | None:
    """The checkout this package lives in (``python/membrane_contact`` inside it), or None (the
    package is installed)."""
    root = Path(__file__).resolve().parents[2]
    return root if _is_repository(root) else None


def repository_root() -> Path | None:
    """The membrane-contact repository: ``$MEMBRANE_CONTACT_ROOT``, or the checkout this package
    lives in (``python/membrane_contact`` inside it), or the current directory or one of its
    parents holding ``Cargo.toml`` and ``fmu/``; None when there is none."""
    candidates = []
    if os.environ.get(ROOT_VARIABLE):
        candidates.append(Path(os.environ[ROOT_VARIABLE]))
    candidates.append(Path(__file__).resolve().parents[2])
    cwd = Path.cwd().resolve()
    candidates += [cwd, *cwd.parents]
    for c in candidates:
        if _is_repository(c):
            return c
    return None


def installed_program(name: str) -> Path | None:
    """The program ``name`` (``fmu-pack``, ``membrane-contact``) installed with this very package
    from the wheel (``PREFIX/bin``, found in the distribution's file list), or None: the package
    runs from a checkout, or was installed without the programs."""
    return installed_file(name, "bin")


def installed_file(name: str, folder: str) -> Path | None:
    """The file ``name`` in the folder named ``folder`` (``bin``, ``membrane-contact`` for
    ``PREFIX/lib/membrane-contact``) installed with this very package from the wheel, or None."""
    try:
        dist = importlib.metadata.distribution("membrane-contact")
    except importlib.metadata.PackageNotFoundError:
        return None
    if Path(dist.locate_file("membrane_contact/fmu.py")).resolve() != Path(__file__).resolve():
        return None  # another copy of the package (e.g. a checkout ahead of it on sys.path)
    for f in dist.files or []:
        if f.name == name and f.parent.name == folder:
            path = Path(dist.locate_file(f)).resolve()
            if path.is_file():
                return path
    return None


#: Environment variable naming the ``membrane-contact`` program to run (else the installed one).
CLI_VARIABLE = "MEMBRANE_CONTACT_CLI"


def cli_program() -> str | None:
    """The ``membrane-contact`` program: ``$MEMBRANE_CONTACT_CLI``, the one installed with this
    package, the checkout's release build, or the one on PATH; None where there is none."""
    import shutil

    program = os.environ.get(CLI_VARIABLE) or installed_program("membrane-contact")
    root = repository_root()
    if not program and root is not None and (root / "target" / "release" / "membrane-contact").is_file():
        program = str(root / "target" / "release" / "membrane-contact")
    return str(program) if program else shutil.which("membrane-contact")


def find_fmu(path=None, model: str | None = None) -> Path:
    """The FMU to use: ``path`` if given, else ``$MEMBRANE_CONTACT_FMU``, else
    ``target/fmu/<model>.fmu`` of the repository (``ParallelArch`` when ``model`` is None).
    Raises FileNotFoundError saying how to make one."""
    if path is not None:
        p = Path(path)
        if not p.is_file():
            raise FileNotFoundError(f"{p}: no such FMU")
        return p
    if os.environ.get(FMU_VARIABLE):
        return find_fmu(os.environ[FMU_VARIABLE])
    root = repository_root()
    name = model or "ParallelArch"
    if root is not None and (root / "target" / "fmu" / f"{name}.fmu").is_file():
        return root / "target" / "fmu" / f"{name}.fmu"
    raise FileNotFoundError(
        f"no {name}.fmu found: pass its path, set {FMU_VARIABLE}, or pack it with "
        f"membrane_contact.build_fmu({'model_file' if model else ''}) "
        "(fmu-pack [model.json] installed with the wheel, or cargo run --release --bin fmu-pack "
        "[-- model.json] in a checkout)"
    )


def fmu_pack_command(root=None) -> tuple[list[str], Path | None]:
    """How :func:`build_fmu` runs ``fmu-pack``, and in which directory: ``cargo run --release
    --bin fmu-pack --`` in the repository ``root`` or ``$MEMBRANE_CONTACT_ROOT``, or in the
    checkout this package lives in (so that the FMU holds the checkout's current code); else the
    ``fmu-pack`` installed with this package (the wheel: no Rust toolchain needed); else cargo in
    the repository around the current directory. Raises RuntimeError when there is none."""
    cargo = ["cargo", "run", "--quiet", "--release", "--bin", "fmu-pack", "--"]
    if root is not None:
        return cargo, Path(root)
    if os.environ.get(ROOT_VARIABLE):
        return cargo, Path(os.environ[ROOT_VARIABLE])
    if _own_checkout() is not None:
        return cargo, _own_checkout()
    program = installed_program("fmu-pack")
    if program is not None:
        return [str(program)], None
    found = repository_root()
    if found is not None:
        return cargo, found
    raise RuntimeError("no fmu-pack: install the membrane-contact wheel (pip install membrane_contact-*.whl), "
                       f"or set {ROOT_VARIABLE} to a checkout of the repository (packed with cargo)")


def build_fmu(model_file=None, out_dir=None, root=None) -> Path:
    """Packs an FMU with ``fmu-pack`` (:func:`fmu_pack_command`: the checkout's through cargo, or
    the one installed from the wheel) of ``model_file`` (a model JSON file or a dict, written to
    ``out_dir`` first) or, without one, the paper's ParallelArch specimen, into ``out_dir``
    (default: the repository's ``target/fmu``; the current directory for the installed
    ``fmu-pack``). Returns the path of the ``.fmu``; raises RuntimeError with fmu-pack's message
    when the model is refused."""
    args, cwd = fmu_pack_command(root)
    if out_dir is None:
        out_dir = cwd / "target" / "fmu" if cwd is not None else Path.cwd()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    if isinstance(model_file, dict):
        path = out_dir / f"{model_file['name']}.json"
        path.write_text(json.dumps(model_file, indent=1))
        model_file = path
    if model_file is not None:
        args.append(str(Path(model_file).resolve()))
        name = json.loads(Path(model_file).read_text())["name"]
    else:
        name = "ParallelArch"
    args += ["--out", str(out_dir.resolve())]
    r = subprocess.run(args, cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"fmu-pack failed: {r.stderr.strip()}")
    path = out_dir / f"{name}.fmu"
    if not path.is_file():
        raise RuntimeError(f"fmu-pack wrote no {path}: {r.stderr.strip()}")
    return path
