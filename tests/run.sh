#!/usr/bin/env bash
# Runs every test from a fresh clone: the Rust tests, then the FMU packaged and driven by fmpy
# (and libcosim) from a local virtual environment. Installs what it needs into .venv/.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== cargo test (release) =="
cargo test --release --locked

echo "== package the FMU =="
cargo build --release --locked
cargo run --release --locked --bin fmu-pack

echo "== python environment =="
if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
.venv/bin/pip install --quiet --disable-pip-version-check -r tests/python/requirements.txt

echo "== pytest (fmpy, libcosim) =="
.venv/bin/python -m pytest tests/python -q -p no:cacheprovider
