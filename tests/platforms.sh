#!/usr/bin/env bash
# The FMU on other platforms (issue 44): not part of tests/run.sh (CI needs no cross toolchain).
#
#   bash tests/platforms.sh            # win64 (wine), aarch64-linux (qemu), darwin if zig is there
#   PLATFORMS_DARWIN=0 bash tests/platforms.sh   # without the macOS builds
#
# 1. builds the FMU's library and the jack's natively and for x86_64-pc-windows-gnu (mingw-w64)
#    and aarch64-unknown-linux-gnu (.cargo/config.toml names the linkers); with cargo-zigbuild
#    (pip install ziglang cargo-zigbuild: on PATH, or in a venv at target/zigvenv) also for
#    x86_64- and aarch64-apple-darwin (linked, not run: checked with llvm-objdump and llvm-nm);
# 2. checks that the win64 DLLs need only Windows system DLLs (objdump -p), and the exported
#    fmi2* functions of every library;
# 3. packs the specimen FMU, a user model's FMU (examples/hinged_panel.json) and the jack FMU
#    with every binary (fmu-pack --platforms, membrane_contact.ssp.pack_jack_fmu);
# 4. runs tests/platforms/harness.c (instantiate with the resource URI, set up, initialize, step
#    the frame down, read the Real outputs, serialize and restore a state, free) on the
#    specimen FMU's library for linux64 natively, win64 under wine, aarch64-linux under
#    qemu-aarch64, and compares each with linux64 (tests/platforms/compare.py: 1e-9 relative);
#    the same for the jack FMU (its force raised; its state kept in memory, not serialized);
# 5. runs `fmpy validate` on the multi-platform FMUs.
#
# Needs (Debian): gcc-mingw-w64-x86-64 wine64 gcc-aarch64-linux-gnu qemu-user, and
# `rustup target add x86_64-pc-windows-gnu aarch64-unknown-linux-gnu` (plus x86_64-apple-darwin
# aarch64-apple-darwin for macOS). Writes target/platforms/. About 20 minutes on 2 cores from
# scratch (a release build per target), a minute when they are built.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
TARGET=${CARGO_TARGET_DIR:-$ROOT/target}
OUT=$TARGET/platforms
WIN=x86_64-pc-windows-gnu
ARM=aarch64-unknown-linux-gnu
DARWIN=(x86_64-apple-darwin aarch64-apple-darwin)
STEPS=4
DZ=-0.03

missing=()
for tool in x86_64-w64-mingw32-gcc x86_64-w64-mingw32-objdump wine aarch64-linux-gnu-gcc qemu-aarch64; do
  command -v "$tool" >/dev/null || missing+=("$tool")
done
for t in $WIN $ARM; do
  rustup target list --installed 2>/dev/null | grep -qx "$t" || missing+=("rust target $t")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "tests/platforms.sh: missing ${missing[*]}" >&2
  echo "  apt-get install gcc-mingw-w64-x86-64 wine64 gcc-aarch64-linux-gnu qemu-user" >&2
  echo "  rustup target add $WIN $ARM" >&2
  exit 1
fi
ZIGBUILD=
if [ "${PLATFORMS_DARWIN:-1}" != 0 ]; then
  for z in cargo-zigbuild "$TARGET/zigvenv/bin/cargo-zigbuild"; do
    if command -v "$z" >/dev/null && { command -v python-zig >/dev/null || command -v zig >/dev/null ||
        [ -x "$(dirname "$(command -v "$z")")/python-zig" ]; }; then
      ZIGBUILD=$(command -v "$z"); break
    fi
  done
  [ -n "$ZIGBUILD" ] || echo "(no cargo-zigbuild with zig: darwin skipped; pip install ziglang cargo-zigbuild)" >&2
fi

echo "== build: linux64, win64, aarch64-linux$( [ -n "$ZIGBUILD" ] && echo ", darwin64, aarch64-darwin") =="
cargo build --release --locked
for t in $WIN $ARM; do
  cargo build --release --locked --lib -p membrane-contact -p hydraulic-jack-fmu --target "$t"
done
platforms=linux64,win64,aarch64-linux
if [ -n "$ZIGBUILD" ]; then
  # cargo-zigbuild runs zig from its own venv (python -m ziglang) when zig is not on PATH
  PATH="$(dirname "$ZIGBUILD"):$PATH"
  # the oldest macOS Rust supports on each (zig's default is its newest SDK's, macOS 15)
  MACOSX_DEPLOYMENT_TARGET=10.12 cargo zigbuild --release --locked --lib -p membrane-contact -p hydraulic-jack-fmu --target "${DARWIN[0]}"
  MACOSX_DEPLOYMENT_TARGET=11.0 cargo zigbuild --release --locked --lib -p membrane-contact -p hydraulic-jack-fmu --target "${DARWIN[1]}"
  platforms+=,darwin64,aarch64-darwin
fi

echo "== the libraries: dependencies and exported fmi2 functions =="
python3 tests/platforms/inspect_libraries.py "$TARGET" "$platforms"

echo "== pack: specimen, user model, jack ($platforms) =="
rm -rf "$OUT" && mkdir -p "$OUT"
"$TARGET/release/fmu-pack" --platforms "$platforms" -o "$OUT/ParallelArch.fmu"
"$TARGET/release/fmu-pack" examples/hinged_panel.json --platforms "$platforms" -o "$OUT/HingedPanel.fmu"
PYTHONPATH=python python3 -c "
import sys
from pathlib import Path
from membrane_contact.ssp import pack_jack_fmu
print(pack_jack_fmu(Path(sys.argv[1]), library=sys.argv[3], root=Path('.'), platforms=sys.argv[2].split(',')))
" "$OUT/HydraulicJack.fmu" "$platforms" "$TARGET/release/libhydraulic_jack.so"
for fmu in "$OUT"/*.fmu; do
  echo "$fmu:"; python3 -m zipfile -l "$fmu" | grep binaries/
done
# one modelDescription, whatever the platforms: the same bytes (and GUID) as linux64 alone
"$TARGET/release/fmu-pack" -o "$OUT/linux64-only/ParallelArch.fmu" >/dev/null
python3 -c "
import sys, zipfile
a, b = (zipfile.ZipFile(f).read('modelDescription.xml') for f in sys.argv[1:])
sys.exit('modelDescription.xml depends on the platforms' if a != b else 0)" "$OUT/ParallelArch.fmu" "$OUT/linux64-only/ParallelArch.fmu"
echo "modelDescription.xml of the multi-platform FMU = that of linux64 alone (GUID $(python3 -c "
import sys, zipfile, re; print(re.search(r'guid=\"([^\"]*)', zipfile.ZipFile(sys.argv[1]).read('modelDescription.xml').decode()).group(1))" "$OUT/ParallelArch.fmu"))"

echo "== harness: linux64 native, win64 under wine, aarch64-linux under qemu =="
H=tests/platforms/harness.c
gcc -O1 -Wall -o "$OUT/harness-linux64" $H -ldl
x86_64-w64-mingw32-gcc -O1 -Wall -D__USE_MINGW_ANSI_STDIO=1 -static -o "$OUT/harness-win64.exe" $H
# wine 8.0 lacks Windows 10's bcryptprimitives.dll (ProcessPrng, Rust's std's random seeds): a
# stand-in beside the harness, for wine only (tests/platforms/bcryptprimitives.c)
x86_64-w64-mingw32-gcc -O1 -Wall -shared -o "$OUT/bcryptprimitives.dll" tests/platforms/bcryptprimitives.c -ladvapi32
aarch64-linux-gnu-gcc -O1 -Wall -o "$OUT/harness-aarch64" $H -ldl
export WINEPREFIX=$OUT/wine WINEDEBUG=-all

# harness FMU INPUT PER_STEP: the harness on the FMU's library on the three platforms (STEPS
# steps, the input INPUT set to k * PER_STEP before step k, every Real output), compared
with_harness() {
  local fmu=$1 input=$2 per_step=$3 name dir md guid vr reals id
  name=$(basename "$fmu" .fmu) dir=$OUT/$(basename "$fmu" .fmu)
  unzip -q -o "$fmu" -d "$dir"
  md=$dir/modelDescription.xml
  read -r guid id vr reals < <(python3 -c "
import sys, xml.etree.ElementTree as E
root = E.parse(sys.argv[1]).getroot()
variables = list(root.iter('ScalarVariable'))
print(root.get('guid'), root.find('CoSimulation').get('modelIdentifier'),
      *[v.get('valueReference') for v in variables if v.get('name') == sys.argv[2]],
      *[v.get('valueReference') for v in variables if v.get('causality') == 'output' and v.find('Real') is not None])
" "$md" "$input")
  local uri=file://$dir/resources win_uri
  win_uri="file:///$(winepath -w "$dir/resources" 2>/dev/null | tr '\\' /)"
  echo "-- $name: $input = k * $per_step, k = 1..$STEPS; $(wc -w <<<"$reals") Real outputs"
  # shellcheck disable=SC2086 # reals: one argument per value reference
  run() { local platform=$1; shift; /usr/bin/time -f "$name on $platform: %e s" "$@" "$guid" "$vr" "$per_step" "$STEPS" $reals \
    >"$OUT/$name-$platform.txt" 2>"$OUT/$name-$platform.log" || { cat "$OUT/$name-$platform.log"; echo "$name on $platform: harness failed" >&2; exit 1; }
    tail -1 "$OUT/$name-$platform.log"; }
  run linux64 "$OUT/harness-linux64" "$dir/binaries/linux64/$id.so" "$uri"
  run win64 wine "$OUT/harness-win64.exe" "$(winepath -w "$dir/binaries/win64/$id.dll" 2>/dev/null)" "$win_uri"
  run aarch64-linux qemu-aarch64 -L /usr/aarch64-linux-gnu "$OUT/harness-aarch64" "$dir/binaries/aarch64-linux/$id.so" "$uri"
  grep -E "^(version|state bytes)" "$OUT/$name-linux64.txt" || true
  python3 tests/platforms/compare.py "$md" "$OUT/$name-linux64.txt" "$OUT/$name-win64.txt" "$OUT/$name-aarch64-linux.txt"
}
with_harness "$OUT/ParallelArch.fmu" frame.dz "$DZ"
# the jack: its force raised by 200 N a step; it cannot serialize its state (kept in memory)
HARNESS_SERIALIZE=0 with_harness "$OUT/HydraulicJack.fmu" force 200

echo "== fmpy validate =="
if [ -x .venv/bin/fmpy ]; then FMPY=.venv/bin/fmpy; else
  [ -x "$TARGET/platforms-venv/bin/fmpy" ] || { python3 -m venv "$TARGET/platforms-venv" && "$TARGET/platforms-venv/bin/pip" install -q fmpy==0.3.32; }
  FMPY=$TARGET/platforms-venv/bin/fmpy
fi
for fmu in "$OUT"/*.fmu; do
  "$FMPY" validate "$fmu"
  "$FMPY" info "$fmu" | grep -i -A1 platforms || true
done
echo "tests/platforms.sh: all passed ($platforms)"
