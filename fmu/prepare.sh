#!/usr/bin/env bash
# Shared by the test runner and the example scripts: builds the crate, packs
# target/fmu/ParallelArch.fmu, and creates/updates the Python environment .venv/ (fmpy,
# libcosimpy, numpy, pytest, matplotlib, meshio, and the package python/ as membrane_contact).
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
# The package of this checkout (python/: membrane_contact), reinstalled each time so the venv
# never holds a stale copy.
.venv/bin/pip install --quiet --disable-pip-version-check --force-reinstall --no-deps ./python
