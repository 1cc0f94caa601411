"""The test harness itself (issue 47 item 11): the specimen FMU the suite loads is the one packed
from the library just built, wherever ``target/`` lies and whether or not it holds cargo's
``CACHEDIR.TAG`` (without it, a bare ``fmu-pack`` writes into the current directory, and the
suite used to load a stale ``target/fmu/ParallelArch.fmu`` without a word)."""

from __future__ import annotations

import shutil

import pytest

from conftest import FMU_PACK, INSTALLED, LIBRARY, NEEDS_CHECKOUT, PARALLEL_ARCH_FMU, TARGET, fmu_library, \
    pack_specimen, specimen_mismatch

pytestmark = pytest.mark.skipif(INSTALLED, reason=NEEDS_CHECKOUT)


def test_the_suites_specimen_fmu_ships_the_library_of_the_release_build():
    assert specimen_mismatch() is None
    assert fmu_library(PARALLEL_ARCH_FMU) == LIBRARY.read_bytes()


def test_the_harness_packs_to_the_named_path_without_cachedir_tag_and_catches_a_stale_fmu(tmp_path):
    # a target/ as a scratch copy has it: target/release only, no CACHEDIR.TAG beside it
    release = tmp_path / "target" / "release"
    release.mkdir(parents=True)
    shutil.copy2(FMU_PACK, release / "fmu-pack")
    shutil.copy2(LIBRARY, release / LIBRARY.name)
    assert not (tmp_path / "target" / "CACHEDIR.TAG").exists()
    fmu = tmp_path / "target" / "fmu" / "ParallelArch.fmu"
    cwd = tmp_path / "elsewhere"
    cwd.mkdir()
    assert pack_specimen(release / "fmu-pack", fmu, release / LIBRARY.name, cwd=cwd) is None
    assert fmu.is_file() and not list(cwd.iterdir())  # nothing packed into the current directory
    assert fmu_library(fmu) == LIBRARY.read_bytes()
    # a library built since: the FMU packed before it is stale, and the check says so
    newer = release / LIBRARY.name
    newer.write_bytes(LIBRARY.read_bytes() + b"\0")
    assert "ships another library" in specimen_mismatch(fmu, newer)
    # the jack's library is not the film's either
    jack = TARGET / "release" / "libhydraulic_jack.so"
    if jack.is_file():
        assert "ships another library" in specimen_mismatch(fmu, jack)
