#!/usr/bin/env python3
"""Mutation check (issue 23): does the test suite catch a wrong program?

Applies each source mutation below in turn to a scratch copy of this checkout (never to the
checkout itself), builds it, runs the tests, and records whether at least one test fails.
Prints a table; exits 1 if a mutation survives (no test failed) or hangs a test past
`--timeout`, 2 if a mutation could not be applied or does not build (the harness would test
nothing), 0 when every mutation is caught.

    tests/mutation.sh                       # every mutation
    tests/mutation.sh radius prestress      # a subset, by name
    tests/mutation.sh --cargo "--test mechanics specimen" radius
                                            # only this cargo test run, for a short loop
    tests/mutation.sh --list                # the mutations and where they apply

Per mutation, with the default settings:
1. `cargo test --release --locked ARGS` for each of its likely catchers (`first` below), so that a
   caught mutation costs one test target;
2. if none failed, the whole Rust suite, `cargo test --release --locked` (stops at the first
   failing test target);
3. if none failed and the mutation is visible through the FMU (`fmu` below), the FMU and the CLI
   are built and packed (`fmu-pack -o target/fmu/ParallelArch.fmu --library ...`, checked to ship
   the library just built) and `pytest tests/python -x` runs (the checkout's `.venv`, made by
   `fmu/prepare.sh`).
A mutation of the Python package (a `.py` file) skips steps 1–2 and runs its `pytest` files.
`--cargo ARGS` replaces steps 1–2 by one `cargo test --release --locked ARGS`; `--no-pytest` skips
step 3; `--pytest "FILES"` runs those test files instead of all of tests/python.

Mutations are exact textual patches: each `old` text must occur exactly once in its file, or the
script stops with status 2, so that a refactored source cannot make it test nothing silently.

Each mutation's command output goes to `logs/<name>.log` beside the scratch copy, which lives
in $MUTATION_DIR (default: $TMPDIR or /tmp,
`membrane-contact-mutation-<uid>-<hash of this checkout's path>`); it keeps its `target/` between
runs (seeded once from this checkout's `target/release`), so only the crate itself is rebuilt.
A failing test counts as a catch, so run it on a checkout whose tests pass unmutated. Slow (a
release build of the crate and its tests per mutation): not part of CI.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@dataclass
class Mutation:
    name: str
    what: str
    file: str
    # (old, new) text replacements, each `old` found exactly once in `file`.
    patches: list[tuple[str, str]]
    # cargo test argument lists tried first (likely catchers), each run on its own.
    first: list[str] = field(default_factory=list)
    # Visible through the FMU: the Python FMU tests run too when the Rust tests pass.
    fmu: bool = False
    # pytest files that catch it (default: `--pytest`); a mutation of a Python file (python/)
    # runs no cargo tests, only these.
    pytest: str = ""

    @property
    def python(self) -> bool:
        return self.file.endswith(".py")


MUTATIONS = [
    Mutation(
        "radius",
        "arch radius from the full span instead of the half span",
        "src/specimens/parallel_arch.rs",
        [(
            "(self.arch_height.powi(2) + self.arch_half_span.powi(2)) / (2.0 * self.arch_height)",
            "(self.arch_height.powi(2) + (2.0 * self.arch_half_span).powi(2)) / (2.0 * self.arch_height)",
        )],
        first=["--test mechanics", "--test robustness", "--test wrapped"],
    ),
    Mutation(
        "prestress",
        "film.prestressX and film.prestressY bound to each other's component",
        "src/fmi2/variables.rs",
        [
            ("Binding::Prestress(0),", "Binding::Prestress(@X@),"),
            ("Binding::Prestress(1),", "Binding::Prestress(0),"),
            ("Binding::Prestress(@X@),", "Binding::Prestress(1),"),
        ],
        first=["--lib fmi2::"],
        fmu=True,
    ),
    Mutation(
        "kn",
        "the FMU parameter G*.kn ignored (its setter does nothing)",
        "src/fmi2/instance.rs",
        [(
            "(Binding::NormalStiffness(g), Value::Real(x)) => model.gaps[g].normal_stiffness = x,",
            "(Binding::NormalStiffness(_), Value::Real(_)) => {}",
        )],
        first=["--lib fmi2::"],
        fmu=True,
    ),
    Mutation(
        "cable",
        "cable axial force halved",
        "src/mech/elements/cable.rs",
        [("    (n0 + ea * strain).max(0.0)\n}", "    0.5 * (n0 + ea * strain).max(0.0)\n}")],
        first=["--test cables", "--lib cable::"],
        fmu=True,
    ),
    Mutation(
        "taut",
        "tension-field material point always taut (never wrinkled or slack)",
        "src/mech/elements/material.rs",
        [
            ("        if e1 <= tol {", "        if false && e1 <= tol {"),
            ("        if e2 + nu * e1 > tol {", "        if true || e2 + nu * e1 > tol {"),
        ],
        first=["--lib material::"],
    ),
    Mutation(
        "curvature",
        "curved-support tangent without its curvature term −λN ∂n/∂x",
        "src/mech/elements/curved_contact/mod.rs",
        [(
            "let mut k = n * n.transpose() * self.kn - p.normal_derivative * lambda;",
            "let mut k = n * n.transpose() * self.kn;",
        )],
        first=["--lib curved_contact::", "--test surfaces"],
    ),
    Mutation(
        "dx-seed",
        "directional derivatives: the prescribed motion of a group's x seed with its sign flipped "
        "(the right-hand side and the outputs' motion of a frame.dx seed; issue 47 item 11: "
        "every derivative test seeded dz, mu, a pressure or an angle)",
        "src/mech/solve/sensitivity.rs",
        [(
            "                du[i] = (self.prescribed_value(i, group, component, &plus.0)",
            "                du[i] = if component == 0 { -1.0 } else { 1.0 }\n"
            "                    * (self.prescribed_value(i, group, component, &plus.0)",
        )],
        first=["--lib fmi2::tests::derivatives"],
        fmu=True,
    ),
    Mutation(
        "stab-energy",
        "the reported work of the viscous stabilization over a step set to 0 (issue 47 item 11: "
        "no test read it from a real run)",
        "src/mech/solve/increments.rs",
        [(
            "            report.stabilization_dissipated += work;",
            "            report.stabilization_dissipated += work * 0.0;",
        )],
        first=["--test robustness a_slack_film"],
    ),
    Mutation(
        "study-gaps",
        "a study resume that skips the missing cases below the largest stored case id",
        "python/membrane_contact/study.py",
        [(
            "        return [k for k in range(self.cases) if k not in stored]",
            "        return [k for k in range(max(stored, default=-1) + 1, self.cases)]",
        )],
        pytest="tests/python/test_study.py",
    ),
]


class HarnessError(Exception):
    """The harness could not test a mutation (pattern not found, build failed, ...)."""


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def scratch_dir() -> Path:
    if os.environ.get("MUTATION_DIR"):
        return Path(os.environ["MUTATION_DIR"])
    tag = hashlib.sha1(str(ROOT).encode()).hexdigest()[:10]
    return Path(tempfile.gettempdir()) / f"membrane-contact-mutation-{os.getuid()}-{tag}"


def tracked_files() -> list[str]:
    out = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT, check=True, capture_output=True,
    ).stdout.decode()
    return [f for f in out.split("\0") if f and (ROOT / f).is_file()]


def prepare(copy: Path) -> None:
    """Refreshes the scratch copy: the checkout's files as they are in the working tree (fresh
    modification times, so cargo rebuilds the crate), its own `target/` kept."""
    if copy.resolve() == ROOT or ROOT in copy.resolve().parents:
        raise HarnessError(f"scratch directory {copy} must lie outside the checkout {ROOT}")
    copy.mkdir(parents=True, exist_ok=True)
    for entry in copy.iterdir():
        if entry.name == "target":
            continue
        if entry.is_symlink() or entry.is_file():
            entry.unlink()
        else:
            shutil.rmtree(entry)
    now = time.time()
    for f in tracked_files():
        dest = copy / f
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(ROOT / f, dest)
        shutil.copymode(ROOT / f, dest)
        os.utime(dest, (now, now))
    if not (copy / "target").exists() and (ROOT / "target" / "release").is_dir():
        log(f"seeding {copy / 'target'} from {ROOT / 'target' / 'release'} (once)")
        (copy / "target").mkdir()
        subprocess.run(["cp", "-a", str(ROOT / "target" / "release"), str(copy / "target")],
                       check=True)
    if (ROOT / ".venv").is_dir():
        (copy / ".venv").symlink_to(ROOT / ".venv")


# The copied sources of the mutated files, as they were when the copy was made (the checkout may
# change while the script runs).
PRISTINE: dict[str, str] = {}


def apply(copy: Path, m: Mutation) -> None:
    path = copy / m.file
    text = PRISTINE.setdefault(m.file, path.read_text())
    for old, new in m.patches:
        count = text.count(old)
        if count != 1:
            raise HarnessError(
                f"{m.name}: the text to mutate occurs {count} times in {m.file} (must be 1): {old!r}"
            )
        text = text.replace(old, new)
    path.write_text(text)


def restore(copy: Path, m: Mutation) -> None:
    # Written anew, so with a fresh modification time: cargo rebuilds from the restored source.
    (copy / m.file).write_text(PRISTINE[m.file])


# Where the output of every command of the current mutation is appended.
LOG: list[Path] = []


class Hung(Exception):
    """A test command ran past the time limit (its process group was killed)."""


def run(cmd: list[str], cwd: Path, timeout: float | None = None) -> tuple[int, str]:
    log("  $ " + shlex.join(cmd))
    # Own process group: on a timeout the test binaries cargo started are killed with it.
    p = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         text=True, start_new_session=True)
    try:
        out, _ = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, _ = p.communicate()
    if LOG:
        with LOG[0].open("a") as f:
            f.write(f"$ {shlex.join(cmd)}\n{out}\n[exit {p.returncode}]\n")
    if p.returncode == -signal.SIGKILL and timeout is not None:
        raise Hung(f"{shlex.join(cmd)} ran past {timeout:.0f} s")
    return p.returncode, out


def failed_tests(output: str) -> list[str]:
    """Names of failed Rust tests (`test x ... FAILED`) or pytest tests (`FAILED path::x`)."""
    names = re.findall(r"^test (\S+) \.\.\. FAILED", output, re.M)
    names += re.findall(r"^FAILED (\S+)", output, re.M)
    return names or ["(a test target failed: see the log)"]


# Time limit of one test command (s): `--timeout`.
TIMEOUT: list[float] = [2400.0]


def cargo_tests(copy: Path, args: str) -> str | None:
    """Builds, then runs `cargo test --release --locked ARGS`; the failed tests' names, or None
    if all passed. A build failure is a harness error, not a caught mutation."""
    base = ["cargo", "test", "--release", "--locked", *shlex.split(args)]
    split = base.index("--") if "--" in base else len(base)
    code, out = run([*base[:split], "--no-run"], copy)
    if code != 0:
        raise HarnessError(f"the mutated source does not build (cargo test {args}):\n{out[-3000:]}")
    code, out = run(base, copy, TIMEOUT[0])
    return None if code == 0 else ", ".join(failed_tests(out)[:3]) + f"  [cargo test {args}]"


def fmu_tests(copy: Path, files: str) -> str | None:
    python = copy / ".venv" / "bin" / "python"
    if not python.exists():
        raise HarnessError("no .venv in the checkout: run `bash fmu/prepare.sh` once, or --no-pytest")
    # The output and the library named: a bare fmu-pack writes into the current directory when
    # target/ holds no CACHEDIR.TAG (the scratch copy's target/ is seeded from target/release
    # only), and pytest would load a stale target/fmu/ParallelArch.fmu.
    fmu = copy / "target" / "fmu" / "ParallelArch.fmu"
    library = copy / "target" / "release" / "libmembrane_contact.so"
    for cmd in (["cargo", "build", "--release", "--locked"],
                [str(copy / "target" / "release" / "fmu-pack"), "-o", str(fmu), "--library", str(library)]):
        code, out = run(cmd, copy)
        if code != 0:
            raise HarnessError(f"{shlex.join(cmd)} failed:\n{out[-3000:]}")
    if packed_library(fmu) != library.read_bytes():
        raise HarnessError(f"{fmu} does not ship {library} as just built: the tests would load a stale FMU")
    code, out = run([str(python), "-m", "pytest", *shlex.split(files), "-x", "-q",
                     "-p", "no:cacheprovider"], copy, TIMEOUT[0])
    return None if code == 0 else ", ".join(failed_tests(out)[:3]) + "  [pytest]"


def packed_library(fmu: Path) -> bytes | None:
    """The shared library an FMU ships (`binaries/linux64/*.so`), or None."""
    import zipfile

    try:
        with zipfile.ZipFile(fmu) as z:
            (name,) = [n for n in z.namelist() if n.startswith("binaries/linux64/") and n.endswith(".so")]
            return z.read(name)
    except (OSError, ValueError, zipfile.BadZipFile):
        return None


def check(copy: Path, m: Mutation, options) -> str | None:
    """What caught `m` (None: it survived)."""
    if m.python:  # nothing of the crate changed: its pytest files only
        if options.no_pytest:
            raise HarnessError(f"{m.name} mutates {m.file}: only pytest can catch it (drop --no-pytest)")
        return fmu_tests(copy, m.pytest or options.pytest)
    caught = None
    if options.cargo is not None:
        caught = cargo_tests(copy, options.cargo)
    else:
        for args in m.first:
            target = re.match(r"--test (\S+)", args)
            if target and not (copy / "tests" / f"{target.group(1)}.rs").exists():
                log(f"  (no tests/{target.group(1)}.rs: skipped)")
                continue
            caught = cargo_tests(copy, args)
            if caught:
                return caught
        caught = cargo_tests(copy, "")
    if caught:
        return caught
    if m.fmu and not options.no_pytest:
        return fmu_tests(copy, options.pytest)
    return None


def main() -> int:
    parser = argparse.ArgumentParser(
        description="Apply each source mutation to a scratch copy and check that a test fails.",
    )
    parser.add_argument("names", nargs="*", help="mutations to run (default: all)")
    parser.add_argument("--cargo", metavar="ARGS",
                        help="run only `cargo test --release --locked ARGS` for each mutation")
    parser.add_argument("--no-pytest", action="store_true", help="skip the Python FMU tests")
    parser.add_argument("--pytest", metavar="FILES", default="tests/python",
                        help="pytest files of step 3 (default: tests/python)")
    parser.add_argument("--timeout", type=float, default=TIMEOUT[0], metavar="SECONDS",
                        help="time limit of one test command; past it the mutation counts as HUNG "
                             "(no test failed) (default: %(default)s)")
    parser.add_argument("--list", action="store_true", help="list the mutations and exit")
    options = parser.parse_args()
    TIMEOUT[0] = options.timeout
    known = {m.name: m for m in MUTATIONS}
    if options.list:
        for m in MUTATIONS:
            print(f"{m.name:10} {m.file:24} {m.what}")
        return 0
    unknown = [n for n in options.names if n not in known]
    if unknown:
        parser.error(f"unknown mutation(s) {', '.join(unknown)}; known: {', '.join(known)}")
    chosen = [known[n] for n in options.names] if options.names else MUTATIONS

    copy = scratch_dir() / "repo"
    log(f"scratch copy: {copy}")
    prepare(copy)
    # Every pattern is checked before anything is built.
    for m in chosen:
        apply(copy, m)
        restore(copy, m)

    logs = scratch_dir() / "logs"
    logs.mkdir(exist_ok=True)
    rows = []
    for m in chosen:
        log(f"\n== {m.name}: {m.what} ({m.file})")
        LOG[:] = [logs / f"{m.name}.log"]
        LOG[0].write_text("")
        start = time.time()
        apply(copy, m)
        try:
            caught = check(copy, m, options)
            verdict = "caught" if caught else "SURVIVED"
        except Hung as e:
            caught, verdict = str(e), "HUNG"
        except HarnessError as e:
            caught, verdict = str(e).splitlines()[0], "ERROR"
            log(str(e))
        finally:
            restore(copy, m)
        rows.append((m.name, verdict, f"{time.time() - start:.0f} s", caught or "no test failed"))
        log(f"   {verdict}: {caught or 'no test failed'} (log: {LOG[0]})")

    print("\n| mutation | verdict | time | first failing tests |")
    print("|---|---|---|---|")
    for row in rows:
        print("| " + " | ".join(row) + " |")
    if any(r[1] == "ERROR" for r in rows):
        return 2
    return 1 if any(r[1] in ("SURVIVED", "HUNG") for r in rows) else 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except HarnessError as e:
        log(f"mutation.py: {e}")
        sys.exit(2)
