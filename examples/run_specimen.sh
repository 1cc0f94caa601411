#!/usr/bin/env bash
# Quick start, command 1: build and package the FMU, then run the main job through fmpy
# (the 300 mm specimen stepped to its target, slip printed beside Table 1).
# Extra arguments go to examples/run_specimen.py (e.g. --height 400 --mu 0.3).
set -euo pipefail
cd "$(dirname "$0")/.."
bash fmu/prepare.sh >/dev/null
.venv/bin/python examples/run_specimen.py "$@"
