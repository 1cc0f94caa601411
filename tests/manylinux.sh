#!/usr/bin/env bash
# The manylinux wheel (issue 44 item 4): not part of tests/run.sh (CI builds and tests the
# linux_x86_64 wheel of fmu/prepare.sh, and needs no zig).
#
#   bash tests/manylinux.sh              # x86_64: build, auditwheel show, the wheel test suite
#   MANYLINUX_AARCH64=1 bash tests/manylinux.sh   # also the aarch64 wheel (built and shown, not run)
#
# 1. builds the FMU's and the jack's libraries with `cargo zigbuild --target
#    x86_64-unknown-linux-gnu.2.28` (zig links them against glibc 2.28's symbols) and stages them
#    as the wheel's data (python/membrane_contact.data/, as the PEP 517 backend of
#    python/build_backend/ does with the native build);
# 2. builds the wheel with `maturin build --release --zig --compatibility manylinux_2_28` from
#    python/pyproject.toml (the programs membrane-contact and fmu-pack, the package), then adds
#    the console scripts as the backend does (add_console_scripts) -> target/manylinux/;
# 3. `auditwheel show` on it (every ELF file of the wheel: programs and libraries);
# 4. installs it into a clean venv, target/manylinux-venv, with the test requirements and no
#    cargo or rustc on PATH, and runs tests/wheel and tests/python there
#    (MEMBRANE_CONTACT_INSTALLED=1), as tests/wheel/run.sh does with the linux_x86_64 wheel.
#
# Needs: pip install maturin ziglang cargo-zigbuild auditwheel (on PATH, or installed here into
# target/manylinux-tools), and `rustup target add aarch64-unknown-linux-gnu` for the aarch64
# wheel. The staged libraries in python/membrane_contact.data/ are the zig builds afterwards;
# fmu/prepare.sh stages the native ones again.
set -euo pipefail
shopt -s inherit_errexit
cd "$(dirname "$0")/.."
ROOT=$PWD
TARGET=${CARGO_TARGET_DIR:-$ROOT/target}
export CARGO_TARGET_DIR=$TARGET
GLIBC=2.28
OUT=$TARGET/manylinux
TOOLS=$TARGET/manylinux-tools

if ! command -v maturin >/dev/null || ! command -v cargo-zigbuild >/dev/null || ! command -v auditwheel >/dev/null ||
    ! python3 -c "import ziglang" 2>/dev/null; then
  if [ ! -x "$TOOLS/bin/maturin" ]; then
    python3 -m venv "$TOOLS"
    "$TOOLS/bin/pip" install --quiet --disable-pip-version-check maturin ziglang cargo-zigbuild auditwheel
  fi
  PATH=$TOOLS/bin:$PATH
fi
TOOLBIN=$(dirname "$(command -v maturin)")
PY=$TOOLBIN/python
[ -x "$PY" ] || PY=python3

# wheel TRIPLE: the libraries zig-built and staged, the wheel built into $OUT/TRIPLE/; prints its path
wheel() {
  local triple=$1 dir=$OUT/$1
  echo "== $triple: the libraries (cargo zigbuild, glibc $GLIBC) ==" >&2
  cargo zigbuild --release --locked --lib -p membrane-contact -p hydraulic-jack-fmu --target "$triple.$GLIBC" >&2
  rm -rf "$dir" && mkdir -p "$dir"
  echo "== $triple: the wheel (maturin --zig --compatibility manylinux_${GLIBC/./_}) ==" >&2
  "$PY" - "$TARGET/$triple/release" "$ROOT" <<'EOF' >&2
import shutil, sys
from pathlib import Path
release, root = Path(sys.argv[1]), Path(sys.argv[2])
sys.path.insert(0, str(root / "python" / "build_backend"))
import membrane_contact_backend as b
b._stage(release / b.LIBRARY, b.LIBRARY, 0o755)
b._stage(release / b.JACK_LIBRARY, b.JACK_LIBRARY, 0o755)
b._stage(root / "fmu" / "jack" / "modelDescription.xml", b.JACK_DESCRIPTION, 0o644)
print("staged", *sorted(p.name for p in b.STAGED.iterdir()), "from", release)
EOF
  (cd python && maturin build --release --locked --zig --compatibility "manylinux_${GLIBC/./_}" \
    --target "$triple" --out "$dir") >&2
  local whl
  whl=$(ls "$dir"/membrane_contact-*.whl)
  "$PY" - "$whl" "$ROOT" <<'EOF' >&2
import sys
from pathlib import Path
sys.path.insert(0, str(Path(sys.argv[2]) / "python" / "build_backend"))
import membrane_contact_backend as b
b.add_console_scripts(Path(sys.argv[1]), b.console_scripts())
EOF
  echo "== $triple: auditwheel show ==" >&2
  auditwheel show "$whl" >&2
  echo "$whl"
}

start=$SECONDS
whl=$(wheel x86_64-unknown-linux-gnu)
echo "built in $((SECONDS - start)) s: $(basename "$whl")"
if [ "${MANYLINUX_AARCH64:-0}" != 0 ]; then
  start=$SECONDS
  arm=$(wheel aarch64-unknown-linux-gnu)
  echo "built in $((SECONDS - start)) s: $(basename "$arm") (not run here)"
fi

echo "== the wheel test suite, installed in a clean venv without cargo =="
no_rust=""
IFS=: read -r -a dirs <<< "$PATH"
for d in "${dirs[@]}"; do
  if [ -n "$d" ] && [ ! -e "$d/cargo" ] && [ ! -e "$d/rustc" ] && [ "$d" != "$TOOLBIN" ]; then
    no_rust="${no_rust:+$no_rust:}$d"
  fi
done
venv=$TARGET/manylinux-venv
rm -rf "$venv"
python3 -m venv "$venv"
PATH="$no_rust" "$venv/bin/pip" install --quiet --disable-pip-version-check "$whl[mesh,study]" \
  -r tests/python/requirements.txt
start=$SECONDS
PATH="$venv/bin:$no_rust" MEMBRANE_CONTACT_INSTALLED=1 \
  "$venv/bin/python" -m pytest tests/wheel tests/python -q -p no:cacheprovider -rs
echo "tests/manylinux.sh: the wheel suite passed in $((SECONDS - start)) s ($(basename "$whl"))"
