"""Inspects the cross-built FMU libraries with object-file readers (tests/platforms.sh, issue 44).

    python3 tests/platforms/inspect_libraries.py TARGET_DIR linux64,win64,aarch64-linux,...

For the FMU's library and the jack's on each platform it lists the exported fmi2* functions and
the libraries the file needs, and fails when
* a library lacks one of the FMI 2.0 Co-Simulation functions (FMI 2.0 §2.1 and §4.2), or
  exports another set of fmi2* functions than linux64's;
* a win64 DLL needs a DLL that is not part of Windows (libgcc_s_seh-1.dll, libwinpthread-1.dll,
  …: .cargo/config.toml links them statically);
* a darwin library is not a dylib for its architecture, or needs anything but /usr/lib and
  /System libraries.
Readers: readelf (ELF), x86_64-w64-mingw32-objdump -p (PE), llvm-objdump and llvm-nm (Mach-O).
"""

import re
import subprocess
import sys
from pathlib import Path

#: Every function an FMI 2.0 Co-Simulation FMU exports (FMI 2.0 §2.1, §4.2).
FMI2_COSIMULATION = """
fmi2GetTypesPlatform fmi2GetVersion fmi2SetDebugLogging fmi2Instantiate fmi2FreeInstance
fmi2SetupExperiment fmi2EnterInitializationMode fmi2ExitInitializationMode fmi2Terminate fmi2Reset
fmi2GetReal fmi2GetInteger fmi2GetBoolean fmi2GetString fmi2SetReal fmi2SetInteger fmi2SetBoolean
fmi2SetString fmi2GetFMUstate fmi2SetFMUstate fmi2FreeFMUstate fmi2SerializedFMUstateSize
fmi2SerializeFMUstate fmi2DeSerializeFMUstate fmi2GetDirectionalDerivative
fmi2SetRealInputDerivatives fmi2GetRealOutputDerivatives fmi2DoStep fmi2CancelStep fmi2GetStatus
fmi2GetRealStatus fmi2GetIntegerStatus fmi2GetBooleanStatus fmi2GetStringStatus
""".split()

#: Windows' own DLLs a Rust cdylib may import (kernel, C runtime, the API sets).
WINDOWS_DLLS = re.compile(r"(?i)^(kernel32|ntdll|msvcrt|ucrtbase|advapi32|userenv|ws2_32|bcrypt|"
                          r"bcryptprimitives|synchronization|shell32|ole32|api-ms-win-.*)\.dll$")

#: folder → (target triple, FMU library file, jack library file)
PLATFORMS = {
    "linux64": ("", "libmembrane_contact.so", "libhydraulic_jack.so"),
    "win64": ("x86_64-pc-windows-gnu", "membrane_contact.dll", "hydraulic_jack.dll"),
    "aarch64-linux": ("aarch64-unknown-linux-gnu", "libmembrane_contact.so", "libhydraulic_jack.so"),
    "darwin64": ("x86_64-apple-darwin", "libmembrane_contact.dylib", "libhydraulic_jack.dylib"),
    "aarch64-darwin": ("aarch64-apple-darwin", "libmembrane_contact.dylib", "libhydraulic_jack.dylib"),
}


def run(*command):
    return subprocess.run(command, check=True, capture_output=True, text=True).stdout


def elf(path):
    exports = {line.split()[-1] for line in run("readelf", "--dyn-syms", "-W", path).splitlines()
               if " FUNC " in line and " GLOBAL " in line and " UND " not in line}
    needed = re.findall(r"\(NEEDED\)\s+Shared library: \[(.*)\]", run("readelf", "-d", path))
    glibc = sorted(set(re.findall(r"GLIBC_([0-9.]+)", run("readelf", "-V", "-W", path))),
                   key=lambda v: tuple(map(int, v.split("."))))
    needed.append(f"glibc {glibc[-1] if glibc else '?'} or newer")
    machine = re.search(r"Machine:\s+(.*)", run("readelf", "-h", path)).group(1).strip()
    return exports, needed, machine, []


def pe(path):
    text = run("x86_64-w64-mingw32-objdump", "-p", path)
    needed = re.findall(r"DLL Name: (\S+)", text)
    names = text.split("[Ordinal/Name Pointer] Table", 1)[-1]
    exports = set(re.findall(r"\]\s+(fmi2\w+)", names))
    machine = re.search(r"file format (\S+)", text).group(1)
    problems = [f"needs {d}, not a Windows DLL" for d in needed if not WINDOWS_DLLS.match(d)]
    return exports, needed, machine, problems


def macho(path, arch):
    exports = {s.split()[-1].lstrip("_") for s in
               run("llvm-nm", "--extern-only", "--defined-only", path).splitlines() if s.strip()}
    headers = run("llvm-objdump", "--macho", "--private-headers", path)
    needed = re.findall(r"cmd LC_LOAD_DYLIB\n\s+cmdsize \d+\n\s+name (\S+)", headers)
    minos = (re.search(r"cmd LC_BUILD_VERSION\n(?:.*\n)*?\s+minos (\S+)", headers)
             or re.search(r"cmd LC_VERSION_MIN_MACOSX\n\s+cmdsize \d+\n\s+version (\S+)", headers))
    needed.append(f"macOS {minos.group(1) if minos else '?'} or newer")
    filetype = re.search(r"MH_MAGIC_64\s+(\S+)\s.*?\s(DYLIB|EXECUTE|BUNDLE)\s", headers, re.S)
    machine = f"{filetype.group(1)} {filetype.group(2)}" if filetype else "?"
    problems = [f"needs {d}" for d in needed if not d.startswith(("/usr/lib/", "/System/", "macOS"))]
    if filetype is None or filetype.group(2) != "DYLIB":
        problems.append("not a Mach-O dylib")
    elif {"x86_64": "X86_64", "aarch64": "ARM64"}[arch] != filetype.group(1):
        problems.append(f"built for {filetype.group(1)}, not {arch}")
    return exports, needed, machine, problems


def main(argv):
    target, folders = Path(argv[1]), argv[2].split(",")
    failed, reference = False, {}
    for folder in folders:
        triple, *files = PLATFORMS[folder]
        for file in files:
            path = str(target / triple / "release" / file)
            if folder.endswith(("darwin", "darwin64")):
                exports, needed, machine, problems = macho(path, "aarch64" if folder.startswith("aarch64") else "x86_64")
            elif folder == "win64":
                exports, needed, machine, problems = pe(path)
            else:
                exports, needed, machine, problems = elf(path)
            fmi2 = {e for e in exports if e.startswith("fmi2")}
            missing = [f for f in FMI2_COSIMULATION if f not in fmi2]
            problems += [f"does not export {', '.join(missing)}"] if missing else []
            if folder == "linux64":
                reference[file] = fmi2
            elif file in reference and fmi2 != reference[file]:
                problems.append(f"exports other fmi2 functions than linux64: {sorted(fmi2 ^ reference[file])}")
            print(f"{folder:15} {file:26} {machine}: {len(fmi2)} fmi2* exported, needs {', '.join(needed) or 'nothing'}")
            for p in problems:
                print(f"  PROBLEM: {p}")
            failed |= bool(problems)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
