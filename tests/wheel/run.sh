#!/usr/bin/env bash
# The wheel without a Rust toolchain (issue 17 item 10): installs target/wheels/membrane_contact-*.whl
# (made by fmu/prepare.sh) into a clean venv, target/wheel-venv, and runs tests/wheel/ there with
# every directory holding cargo or rustc taken off PATH. Called at the end of tests/run.sh.
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
# The wheel with its importer extra (meshio), and pytest: nothing of the checkout's python/.
PATH="$no_rust" "$venv/bin/pip" install --quiet --disable-pip-version-check "${wheels[0]}[mesh]" pytest
PATH="$(pwd)/$venv/bin:$no_rust" "$venv/bin/python" -m pytest tests/wheel -q -p no:cacheprovider
