#!/usr/bin/env bash
# Regenerates every example figure and its CSV into docs/figures/ (or the directory given as
# the first argument): builds the core and packs the FMU, creates .venv if needed, then runs
# the seven examples with their default number of steps.
#
#   bash examples/make_figures.sh [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-docs/figures}"

bash fmu/prepare.sh

mkdir -p "$out"
for example in fig7_mu_sweep fig8_vs_experiment fig8_wrapped fig8_plastic fig6_stress erection_sequence \
    cushion_three_layer; do
  echo "== $example =="
  .venv/bin/python "examples/$example.py" --out "$out"
done
echo "figures and CSV files in $out/"
