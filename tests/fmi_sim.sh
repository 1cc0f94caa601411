#!/usr/bin/env bash
# The FMI 3.0 FMUs in fmi-sim, the simulator of rust-fmi (issue 45): not part of tests/run.sh (CI
# has no fmi-sim). Without fmi-sim on PATH (or FMI_SIM=/path/to/fmi-sim) it says so and exits 0.
#
#   cargo install fmi-sim --locked     # once (fmi-sim 0.7.0 was run here); its fmi-sys crate runs
#                                      # bindgen, which needs libclang (Debian: apt-get install libclang-dev)
#   bash tests/fmi_sim.sh
#
# 1. builds the release programs and packs the specimen (ParallelArch) and a user model
#    (examples/hinged_panel.json) as FMI 2.0 and FMI 3.0 FMUs (fmu-pack, fmu-pack --fmi-version 3);
# 2. runs each FMI 3.0 FMU in fmi-sim (co-simulation, 0 to 1 s, 4 communication steps of 0.25 s)
#    with an input CSV: the specimen's frame lowered (frame.dz 0 … -0.02 m, mu = 0.3), the panel's
#    rail lowered and turned (rail.dz 0 … -0.02 m, rail.angle 0 … 0.04 rad), a row at every
#    communication point (no importer's interpolation rule decides a value); the FMI 2.0 FMUs too;
# 3. tests/fmi_sim/compare.py: fmpy's runs of the FMI 3.0 and the FMI 2.0 FMU on the same inputs,
#    and every column of fmi-sim's CSVs (time and each output) against both, bit for bit.
#
# fmi-sim 0.7.0 does not run the FMI 3.0 archive as it is, for two limits of its own:
#  - its model-description reader (fmi-schema 0.8.0) refuses the `unit` attribute of a Float64
#    variable ('unknown field "unit" in element "FmiFloat64"'), which the FMI 3.0 schema allows
#    (fmpy validate finds no problem);
#  - it reads every output with one value (fmi3GetFloat64 with nValues = 1), also the array
#    outputs (film.displacement, ...), which the FMU refuses as the standard asks ("nValues = 1,
#    but the 1 variables hold 363 values"): fmi-sim stops at its first recording.
# So fmi-sim runs a copy of the FMI 3.0 archive whose modelDescription.xml has no `unit`
# attributes and declares the array outputs local (value references, instantiation token,
# library and resources unchanged: the library rebuilds its description from resources/, so the
# copy is the same FMU to it). Both refusals of the unchanged archive are run and shown first.
# fmpy runs the unchanged archives. Writes target/fmi_sim/. A minute (the release build).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
TARGET=${CARGO_TARGET_DIR:-$ROOT/target}
OUT=$TARGET/fmi_sim
FMI_SIM=${FMI_SIM:-$(command -v fmi-sim || true)}
if [ -z "$FMI_SIM" ] || [ ! -x "$FMI_SIM" ]; then
  echo "tests/fmi_sim.sh: fmi-sim is not installed (cargo install fmi-sim --locked, or set FMI_SIM): skipped"
  exit 0
fi
PY=${PYTHON:-}
if [ -z "$PY" ]; then
  if [ -x .venv/bin/python ]; then PY=.venv/bin/python; else PY=python3; fi
fi
"$PY" -c "import fmpy, numpy" 2>/dev/null || {
  echo "tests/fmi_sim.sh: $PY has no fmpy/numpy (bash tests/run.sh makes .venv, or set PYTHON)" >&2; exit 1; }
echo "$(RUST_BACKTRACE=0 "$FMI_SIM" --version 2>&1 | head -1 | sed 's/^Error: //'), fmpy $("$PY" -c 'import fmpy; print(fmpy.__version__)')"

cargo build --release --locked --bin fmu-pack --lib -p membrane-contact
rm -rf "$OUT" && mkdir -p "$OUT"
"$TARGET/release/fmu-pack" -o "$OUT/ParallelArch.fmu"
"$TARGET/release/fmu-pack" --fmi-version 3 -o "$OUT/ParallelArch_fmi3.fmu"
"$TARGET/release/fmu-pack" examples/hinged_panel.json -o "$OUT/HingedPanel.fmu"
"$TARGET/release/fmu-pack" examples/hinged_panel.json --fmi-version 3 -o "$OUT/HingedPanel_fmi3.fmu"

# the inputs, a row per communication point (times and values as Python writes them)
"$PY" - "$OUT" <<'PY'
import sys
out = sys.argv[1]
rows = lambda k: 0.25 * k
with open(f"{out}/ParallelArch_in.csv", "w") as f:
    f.write("time,mu,frame.dz\n")
    for k in range(5):
        f.write(f"{rows(k)!r},0.3,{-0.005 * k!r}\n")
with open(f"{out}/HingedPanel_in.csv", "w") as f:
    f.write("time,rail.dz,rail.angle\n")
    for k in range(5):
        f.write(f"{rows(k)!r},{-0.005 * k!r},{0.01 * k!r}\n")
PY

# a copy of an FMI 3.0 archive for fmi-sim (see above): without `unit` attributes ($3 = units),
# and with the array outputs local too ($3 = units+arrays)
fmisim_copy() {
  "$PY" - "$1" "$2" "$3" <<'PY'
import re, sys, zipfile
src, dst, what = sys.argv[1:]
with zipfile.ZipFile(src) as z, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as w:
    for info in z.infolist():
        data = z.read(info)
        if info.filename == "modelDescription.xml":
            text = data.decode()
            units = len(re.findall(r'<Float64 [^>]* unit="', text))
            text = re.sub(r'(<Float(?:32|64) [^>]*?) unit="[^"]*"', r"\1", text)
            arrays = re.findall(r'<\w+ name="([^"]+)" valueReference="(\d+)"[^>]*causality="output"[^>]*>\s*<Dimension', text)
            if what == "units+arrays":
                for name, vr in arrays:
                    text = re.sub(rf'(<\w+ name="{re.escape(name)}"[^>]*?)causality="output"', r'\1causality="local"', text, count=1)
                    # a local variable is neither an Output nor an InitialUnknown of the ModelStructure
                    text = re.sub(rf'\n\s*<(?:Output|InitialUnknown) valueReference="{vr}"[^>]*/>', "", text)
                print(f"{dst}: {units} unit attributes removed, {len(arrays)} array outputs declared local "
                      f"({', '.join(n for n, _ in arrays)})")
            data = text.encode()
        w.writestr(info, data)
PY
}

fmisim() {  # fmisim FMU NAME LOG: a co-simulation of FMU with NAME's inputs, to NAME's CSV
  RUST_LOG=info RUST_BACKTRACE=0 "$FMI_SIM" --model "$1" -i "$OUT/${2%%_*}_in.csv" -o "$OUT/$2.csv" \
    co-simulation -s 0 -f 1 --output-interval 0.25 >"$OUT/$2.log" 2>&1
}

status=0
for m in ParallelArch HingedPanel; do
  echo "== $m"
  fmisim_copy "$OUT/${m}_fmi3.fmu" "$OUT/${m}_fmi3_nounits.fmu" units
  fmisim_copy "$OUT/${m}_fmi3.fmu" "$OUT/${m}_fmi3_fmisim.fmu" units+arrays
  for v in fmi3 fmi3_nounits; do
    if fmisim "$OUT/${m}_$v.fmu" "${m}_${v}_run"; then
      echo "fmi-sim ran $m's $v archive (the limits above are gone: see whether the copy is still needed)"
    else
      echo "fmi-sim refuses $m's $v archive: $(grep -E '^(Error|ERROR)' "$OUT/${m}_${v}_run.log" | sed 's/^ERROR \[fmu\] /FMU: /' | tr '\n' ' ')"
    fi
  done
  fmisim "$OUT/${m}_fmi3_fmisim.fmu" "${m}_fmi3_fmisim" || { cat "$OUT/${m}_fmi3_fmisim.log"; status=1; continue; }
  fmisim "$OUT/$m.fmu" "${m}_fmi2_fmisim" || { cat "$OUT/${m}_fmi2_fmisim.log"; status=1; continue; }
  "$PY" tests/fmi_sim/compare.py "$OUT/$m.fmu" "$OUT/${m}_fmi3.fmu" "$OUT/${m}_in.csv" \
    "$OUT/${m}_fmi3_fmisim.csv" 1.0 0.25 "$OUT/${m}_fmi2_fmisim.csv" 2>&1 | grep -v '^Warning: missing input' || status=1
done
[ $status = 0 ] && echo "tests/fmi_sim.sh: fmi-sim's outputs are fmpy's, FMI 3.0 and FMI 2.0, bit for bit" ||
  echo "tests/fmi_sim.sh: FAILED" >&2
exit $status
