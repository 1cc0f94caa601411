"""Side-by-side benchmark (issue 11 item 4): the sheet of sheet.py in this solver, Kratos and
CalculiX, repeated and interleaved; prints markdown tables of medians and ratios.

Not part of CI or `cargo test`. Installing the peers: see README.md in this directory.

    python3 benches/peers/run.py --sizes 27,83,259 --repeats 2
    python3 benches/peers/run.py --sizes 577 --solvers ours,ours-plain --repeats 2

Each run is a fresh process under `nice -n 5` and `/usr/bin/time -v` (wall time, peak RSS),
with OMP_NUM_THREADS=1 (or --threads) and OMP_WAIT_POLICY=PASSIVE. Within a repeat the solvers
run in a rotated order, so slow phases of the shared machine spread over all of them.
Standard library only (the Kratos runs use the Kratos venv's python).
"""

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import sheet  # noqa: E402

SOLVERS = ("ours", "ours-plain", "kratos", "ccx")
LABELS = {
    "ours": "membrane-contact (default settings)",
    "ours-plain": "membrane-contact (`--no-line-search`)",
    "kratos": "Kratos MembraneElement3D3N (sparse_lu)",
    "ccx": "CalculiX S3 + NLGEOM (SPOOLES)",
}


def timed(cmd, cwd, env, timeout):
    """Runs cmd under nice and /usr/bin/time -v; returns (stdout, stderr, wall s, peak MiB,
    CPU s = user + system)."""
    full = ["nice", "-n", "5", "/usr/bin/time", "-v"] + cmd
    t0 = time.perf_counter()
    p = subprocess.run(full, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr)
    cpu = sum(float(m) for m in re.findall(r"(?:User|System) time \(seconds\): ([0-9.]+)", p.stderr))
    return p.stdout, p.stderr, wall, int(rss.group(1)) / 1024 if rss else float("nan"), cpu


def run_ours(files, plain, args, env):
    cmd = [args.bin, "model", files["ours"], "--steps", str(sheet.STEPS), "--quiet"]
    if plain:
        cmd.append("--no-line-search")
    out, _, wall, rss, cpu = timed(cmd, os.path.dirname(files["ours"]), env, args.timeout)
    w = re.search(r"output point centre \(node \d+\): displacement \(([^,]+), ([^,]+), ([^)]+)\) m", out)
    newton = re.search(r"Newton: .*?, (\d+) iterations .*; ([0-9.]+) ms", out)
    if not (w and newton):
        raise RuntimeError(f"unexpected output of {' '.join(cmd)}:\n{out}")
    return {"w": float(w.group(3)), "iterations": int(newton.group(1)), "wall": wall, "cpu": cpu, "rss": rss,
            "solve": float(newton.group(2)) / 1e3}


def run_kratos(files, args, env):
    cmd = [args.kratos_python, os.path.join(HERE, "run_kratos.py"), files["kratos"]]
    out, _, wall, rss, cpu = timed(cmd, os.path.dirname(files["kratos"]), env, args.timeout)
    line = next((ln for ln in out.splitlines() if ln.startswith('{"solver": "kratos"')), None)
    if line is None:
        raise RuntimeError(f"no result line from Kratos:\n{out[-3000:]}")
    r = json.loads(line)
    return {"w": r["centre"][2], "iterations": sum(r["iterations"]), "wall": wall, "cpu": cpu, "rss": rss,
            "solve": r["solve_s"]}


def run_ccx(files, args, env):
    inp = files["ccx"]
    job = os.path.splitext(os.path.basename(inp))[0]
    cwd = os.path.dirname(inp)
    _, _, wall, rss, cpu = timed([args.ccx, "-i", job], cwd, env, args.timeout)
    with open(os.path.join(cwd, job + ".sta")) as f:
        rows = [ln.split() for ln in f if re.match(r"\s+\d+\s+\d+\s+\d+\s+\d+\s", ln)]
    if not rows or float(rows[-1][4]) < 1.0 - 1e-9:
        raise RuntimeError(f"ccx did not reach the full load (see {job}.sta)")
    with open(os.path.join(cwd, job + ".dat")) as f:
        dat = f.read()
    blocks = dat.split("displacements (vx,vy,vz) for set CENTRE")
    lines = [ln for ln in blocks[-1].splitlines() if ln.strip()]
    z = float(lines[1].split()[3])
    return {"w": z, "iterations": sum(int(r[3]) for r in rows), "wall": wall, "cpu": cpu, "rss": rss,
            "solve": None}


def estimate():
    """Centre deflection from the small-deflection series of the prestressed square membrane
    (w = 0.07367 p a^2 / N) combined with the stretching-only one-term estimate of a square
    membrane (Timoshenko: w = 0.802 (a/2) (p (a/2) / (E t))^(1/3)): k1 w + k3 w^3 = p."""
    a, p = sheet.SIDE, sheet.PRESSURE
    n_pre = sheet.PRESTRESS * sheet.THICKNESS
    k1 = n_pre / (0.07367 * a * a)
    k3 = sheet.YOUNG * sheet.THICKNESS / (0.802 ** 3 * (a / 2) ** 4)
    lo, hi = 0.0, 1.0
    for _ in range(200):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if k1 * mid + k3 * mid ** 3 < p else (lo, mid)
    return 0.07367 * p * a * a / n_pre, lo


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="27,83,259", help="nodes per side, odd (27: 2 k DOF, 83: 20 k, 259: 200 k, 577: 1 M)")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--solvers", default=",".join(SOLVERS))
    ap.add_argument("--threads", type=int, default=1, help="OMP_NUM_THREADS for the peers")
    ap.add_argument("--workdir", default=os.path.join(HERE, "out"))
    ap.add_argument("--bin", default=os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")), "release", "membrane-contact"))
    ap.add_argument("--kratos-python", default=os.environ.get("KRATOS_PYTHON", os.path.join(HERE, ".venv", "bin", "python")))
    ap.add_argument("--ccx", default="ccx")
    ap.add_argument("--timeout", type=float, default=4 * 3600)
    ap.add_argument("--json", help="append every run as a JSON line to this file")
    args = ap.parse_args()
    solvers = args.solvers.split(",")
    for s in solvers:
        if s not in SOLVERS:
            sys.exit(f"unknown solver {s!r}: one of {', '.join(SOLVERS)}")
    env = dict(os.environ, OMP_NUM_THREADS=str(args.threads), OMP_WAIT_POLICY="PASSIVE")
    sizes = [int(s) for s in args.sizes.split(",")]
    lin, est = estimate()
    print(f"estimates: small-deflection series {lin * 1e3:.2f} mm (prestress only), "
          f"series + stretching {est * 1e3:.2f} mm\n")
    for n in sizes:
        files = sheet.write_all(n, os.path.join(args.workdir, f"n{n}"))
        runs = {s: [] for s in solvers}
        for r in range(args.repeats):
            k = r % len(solvers)
            for s in solvers[k:] + solvers[:k]:
                if s in ("ours", "ours-plain"):
                    res = run_ours(files, s == "ours-plain", args, env)
                elif s == "kratos":
                    res = run_kratos(files, args, env)
                else:
                    res = run_ccx(files, args, env)
                res.update(solver=s, n=n, repeat=r)
                print(f"  n={n} repeat {r + 1} {s}: w={res['w'] * 1e3:.4f} mm, {res['iterations']} it, "
                      f"{res['wall']:.2f} s wall, {res['cpu']:.2f} s CPU, {res['rss']:.0f} MiB", file=sys.stderr, flush=True)
                if args.json:
                    with open(args.json, "a") as f:
                        f.write(json.dumps(res) + "\n")
                runs[s].append(res)
        table(n, solvers, runs, args.repeats)


def ratio(a, b):
    """a / b to three digits; a dash when b is below the clock's resolution."""
    return f"{a / b:.3g}" if b > 0 else "–"


def table(n, solvers, runs, repeats):
    free = 3 * (n - 2) ** 2
    ref = next((s for s in ("ours-plain", "ours") if s in solvers), solvers[0])
    med = {s: {key: statistics.median(r[key] for r in runs[s]) for key in ("wall", "cpu", "rss")} for s in solvers}
    for s in solvers:
        med[s]["w"] = runs[s][0]["w"]
        med[s]["iterations"] = runs[s][0]["iterations"]
        med[s]["per_it"] = med[s]["wall"] / med[s]["iterations"]
        med[s]["cpu_it"] = med[s]["cpu"] / med[s]["iterations"]
    print(f"### n = {n}: {3 * n * n} DOF ({free} free), {2 * (n - 1) ** 2} triangles, "
          f"median of {repeats}\n")
    print(f"| solver | centre w (mm) | vs {ref} | Newton iterations | wall (s) | CPU (s) | "
          f"CPU / iteration (s) | peak RSS (MiB) | wall / iteration ÷ {ref} | CPU / iteration ÷ {ref} | "
          f"wall ÷ {ref} | CPU ÷ {ref} |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    b = med[ref]
    for s in solvers:
        m = med[s]
        print(f"| {LABELS[s]} | {m['w'] * 1e3:.4f} | {100 * (m['w'] / b['w'] - 1):+.2f} % | "
              f"{m['iterations']} | {m['wall']:.2f} | {m['cpu']:.2f} | {m['cpu_it']:.4f} | {m['rss']:.0f} | "
              f"{ratio(m['per_it'], b['per_it'])} | {ratio(m['cpu_it'], b['cpu_it'])} | "
              f"{ratio(m['wall'], b['wall'])} | {ratio(m['cpu'], b['cpu'])} |")
    print()
    sys.stdout.flush()


if __name__ == "__main__":
    main()
