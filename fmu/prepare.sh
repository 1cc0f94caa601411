#!/usr/bin/env bash
# Shared by the test runner and the example scripts: builds the crate, packs
# target/fmu/ParallelArch.fmu, and creates/updates the Python environment .venv/ (fmpy,
# libcosimpy, numpy, pytest, matplotlib, meshio, and this checkout's wheel, target/wheels/: the
# package membrane_contact with the programs membrane-contact and fmu-pack, the FMU's library and
# the hydraulic jack's, fmu/jack).
# Idempotent; run from anywhere.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== build the crate and pack the FMU ==" >&2
cargo build --release --locked
cargo run --release --locked --quiet --bin fmu-pack

echo "== python environment (.venv) ==" >&2
if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
.venv/bin/pip install --quiet --disable-pip-version-check -r tests/python/requirements.txt
# The wheel of this checkout (python/pyproject.toml: the package membrane_contact, the programs
# membrane-contact and fmu-pack, the FMU's library; built from target/release, no recompiling),
# reinstalled each time so the venv never holds a stale copy. tests/wheel/run.sh installs the
# same wheel into a clean venv without cargo.
rm -rf target/wheels
.venv/bin/pip wheel --quiet --disable-pip-version-check --no-deps -w target/wheels ./python
.venv/bin/pip install --quiet --disable-pip-version-check --force-reinstall --no-deps target/wheels/membrane_contact-*.whl
