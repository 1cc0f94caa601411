#!/usr/bin/env bash
# Runs every test from a fresh clone: the Rust tests, then the FMU packaged and driven by fmpy
# (and libcosim) from a local virtual environment. Installs what it needs into .venv/.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== cargo test (release) =="
cargo test --release --locked

# Every benchmark compiles (they are run by hand; a model field added without them went unseen)
echo "== benchmarks compile (cargo bench --no-run) =="
cargo bench --locked --no-run

# -- robustness benchmark, quick slice (issue 23): every 10th load path of each family of the
#    grid must converge (exit 1 below 100 %); measured 8 s on 2 cores (15 s CPU)
echo "== robustness benchmark (--check --quick) =="
cargo bench --locked --bench robustness -- --check --quick

bash fmu/prepare.sh

echo "== pytest (fmpy, libcosim) =="
.venv/bin/python -m pytest tests/python -q -p no:cacheprovider

# --- The wheel (issue 17 item 10): the wheel fmu/prepare.sh built, installed into a clean venv
# with no cargo on PATH, packs FMUs and runs the specimen (tests/wheel/), then the whole Python
# suite against it (tests/python/ with MEMBRANE_CONTACT_INSTALLED=1).
echo "== wheel: pip install into a clean venv, no Rust toolchain =="
bash tests/wheel/run.sh
