#!/usr/bin/env bash
# The wheel without a Rust toolchain (issue 17 item 10): installs target/wheels/membrane_contact-*.whl
# (made by fmu/prepare.sh) into a clean venv, target/wheel-venv, with the test requirements, and
# runs tests/wheel/ and the whole Python suite tests/python/ there against it
# (MEMBRANE_CONTACT_INSTALLED=1: the wheel's package, CLI and fmu-pack; see tests/python/conftest.py)
# with every directory holding cargo or rustc taken off PATH. Called at the end of tests/run.sh.
set -euo pipefail
cd "$(dirname "$0")/../.."

wheels=(target/wheels/membrane_contact-*.whl)
if [ "${#wheels[@]}" -ne 1 ] || [ ! -f "${wheels[0]}" ]; then
  echo "tests/wheel/run.sh: expected one wheel in target/wheels (run bash fmu/prepare.sh): ${wheels[*]}" >&2
  exit 1
fi

# PATH without the Rust toolchain: the wheel must not need it.
no_rust=""
IFS=: read -r -a dirs <<< "$PATH"
for d in "${dirs[@]}"; do
  if [ -n "$d" ] && [ ! -e "$d/cargo" ] && [ ! -e "$d/rustc" ]; then
    no_rust="${no_rust:+$no_rust:}$d"
  fi
done

venv=target/wheel-venv
rm -rf "$venv"
python3 -m venv "$venv"
# The wheel with its importer and study extras (meshio; dask, distributed, xarray, pyarrow,
# pyyaml), and what the tests use (pytest, libcosimpy, pandas, matplotlib, the pinned study
# packages): nothing of the checkout's python/.
PATH="$no_rust" "$venv/bin/pip" install --quiet --disable-pip-version-check "${wheels[0]}[mesh,study]" \
  -r tests/python/requirements.txt
PATH="$(pwd)/$venv/bin:$no_rust" MEMBRANE_CONTACT_INSTALLED=1 \
  "$venv/bin/python" -m pytest tests/wheel tests/python -q -p no:cacheprovider
