"""Compares what tests/platforms/harness.c printed on each platform with the linux64 run.

    python3 tests/platforms/compare.py MODELDESCRIPTION linux64.txt OTHER.txt...

Each file holds the lines "step k vr value" and "replay k vr value" of one run. Every value of
every other run must agree with linux64's within 1e-9 relative (absolute below 1e-300, where
both are zero or tiny); "replay identical 1" (the state restored from its serialized bytes gives
the last step again, bit for bit) must be in every file. Prints, per run, the number of values,
how many are bitwise equal, the largest relative difference and the variable where it is, and
exits 1 when any check fails."""

import sys
import xml.etree.ElementTree as ET

TOLERANCE = 1e-9


def names(description):
    return {int(v.get("valueReference")): v.get("name")
            for v in ET.parse(description).getroot().iter("ScalarVariable")}


def values(path):
    out, identical = {}, False
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            word = line.split()
            if len(word) == 4 and word[0] in ("step", "replay"):
                out[(word[0], int(word[1]), int(word[2]))] = float(word[3])
            elif word[:3] == ["replay", "identical", "1"]:
                identical = True
    return out, identical


def main(argv):
    table = names(argv[1])
    reference, identical = values(argv[2])
    failed = not reference or not identical
    if failed:
        print(f"{argv[2]}: no values or no bit-identical replay")
    for path in argv[3:]:
        other, same_replay = values(path)
        if set(other) != set(reference):
            print(f"{path}: {len(other)} values, linux64 {len(reference)}: runs differ in what they printed")
            failed = True
            continue
        worst, where, bitwise = 0.0, None, 0
        for key, a in reference.items():
            b = other[key]
            bitwise += a == b
            scale = max(abs(a), abs(b))
            diff = 0.0 if a == b else abs(a - b) / scale if scale > 1e-300 else abs(a - b)
            if diff > worst:
                worst, where = diff, key
        ok = worst <= TOLERANCE and same_replay
        failed |= not ok
        at = f" at {where[0]} {where[1]} {table.get(where[2], where[2])}" if where else ""
        print(f"{path}: {len(other)} values, {bitwise} bitwise equal to linux64, largest relative "
              f"difference {worst:.3g}{at}, replay from the restored state identical: "
              f"{'yes' if same_replay else 'NO'} -> {'agrees' if ok else 'DIFFERS'} (tolerance {TOLERANCE:g})")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
