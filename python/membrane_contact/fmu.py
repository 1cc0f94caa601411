"""Where FMUs come from: the repository's ``target/fmu/`` or ``fmu-pack`` run on a model file."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

#: Environment variable naming an FMU to use when none is given.
FMU_VARIABLE = "MEMBRANE_CONTACT_FMU"
#: Environment variable naming the repository (for ``build_fmu`` and ``find_fmu``) when the
#: package is installed outside it.
ROOT_VARIABLE = "MEMBRANE_CONTACT_ROOT"


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
        if (c / "Cargo.toml").is_file() and (c / "fmu").is_dir():
            return c
    return None


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
        "(cargo run --release --bin fmu-pack [-- model.json])"
    )


def build_fmu(model_file=None, out_dir=None, root=None) -> Path:
    """Packs an FMU with ``cargo run --release --bin fmu-pack`` in the repository: of
    ``model_file`` (a model JSON file or a dict, written to ``out_dir`` first) or, without one,
    the paper's ParallelArch specimen. Returns the path of the ``.fmu``; raises RuntimeError with
    fmu-pack's message when the model is refused."""
    root = Path(root) if root is not None else repository_root()
    if root is None:
        raise RuntimeError(f"the membrane-contact repository was not found: set {ROOT_VARIABLE}")
    out_dir = Path(out_dir) if out_dir is not None else root / "target" / "fmu"
    out_dir.mkdir(parents=True, exist_ok=True)
    args = ["cargo", "run", "--quiet", "--release", "--bin", "fmu-pack", "--"]
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
    r = subprocess.run(args, cwd=root, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"fmu-pack failed: {r.stderr.strip()}")
    path = out_dir / f"{name}.fmu"
    if not path.is_file():
        raise RuntimeError(f"fmu-pack wrote no {path}: {r.stderr.strip()}")
    return path
