#!/usr/bin/python3
"""End-to-end benchmark of `isohex mesh` (issue 16): per case, the hexes, wall and CPU seconds,
seconds per stage and per part of the optimisation (from the JSON report), peak memory
(the report's, and bytes per hex), microseconds of wall per hex, and, over the cthead sizes,
the exponent b of wall time ~ hexes^b (least squares on the logs).

    /usr/bin/python3 bench/pipeline_bench.py --cli build/bin/isohex --data ../shared/data \\
        [--only "cthead h 4;headsq"] [--threads 2] [--json OUT.json]

The cases: cthead's skin at h 4, 3 and 2 (the size series), headsq's bone at h 3.2, the MR
head at h 4, and scripts/run.sh's CSG phantom (no shared data needed). A benchmark, not a test: the
figures depend on the machine and its load; report them with both (docs/benchmarks.md).
"""
import argparse
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts"))
from paper_table import CTHEAD, HEADSQ  # noqa: E402  (the scans' layouts, one list for both)


def cases(data):
    v = lambda f: os.path.join(data, "volumes", f)
    out = [(f"cthead h {h}", [v("cthead_256x256x113_int16be.raw")] + CTHEAD + ["--iso", "600", "--cell-size", str(h)])
           for h in (4, 3, 2)]
    out += [("headsq h 3.2", [v("headsq_64x64x93_int16le.raw")] + HEADSQ + ["--iso", "1150", "--cell-size", "3.2"]),
            ("MR head h 4", [v("HeadMRVolume.mhd"), "--iso", "40", "--cell-size", "4"])]
    phantom = "difference(union(sphere(0,0,0,1), torus(0,0,0, 1.2,0.35)), sphere(0,0,0,0.55))"
    return [(n, a) for n, a in out if os.path.exists(a[0])] + [("CSG phantom (scripts/run.sh)",
                                                               ["--shape", phantom, "--resolution", "32"])]


def optimisation_parts(opt):
    """Seconds of untangle / shape / worst, the band rounds' summed in."""
    parts = {k: opt.get(k, {}).get("seconds", 0.0) for k in ("untangle", "shape", "worst")}
    for rd in opt.get("boundary", {}).get("rounds", []):
        for k in parts:
            parts[k] += rd.get(k, {}).get("seconds", 0.0)
    return parts


def run_case(cli, args, threads, tmp):
    out, rep = os.path.join(tmp, "bench.vtu"), os.path.join(tmp, "bench.json")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.monotonic()
    run = subprocess.run([cli, "mesh"] + args + ["-o", out, "--json", rep, "--threads", str(threads)],
                         capture_output=True, text=True)
    wall = time.monotonic() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if run.returncode not in (0, 1) or not os.path.exists(rep):
        raise RuntimeError(f"isohex mesh exit {run.returncode}: {run.stderr.strip()[-300:]}")
    r = json.load(open(rep))
    os.remove(rep)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    stages = {s["stage"]: s["seconds"] for s in r["stages"]}
    return {"hexes": r["hexes"], "wall": wall, "cpu": cpu, "stages": stages,
            "optimisation": optimisation_parts(r["optimisation"]), "peak_mib": r["peak_memory_mib"],
            "min_sj": r["stages"][-1]["scaled_jacobian"]["min"], "below": r["stages"][-1]["below_0.2"]}


def exponent(points):
    """b of t = a n^b by least squares on (log n, log t)."""
    if len(points) < 2:
        return float("nan")
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(t) for _, t in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cli", default="build/bin/isohex")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data"))
    ap.add_argument("--only", default="", help="case names (prefixes), separated by ';'")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--json", default="", help="also write the figures as JSON")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="isohex-bench-")
    load = os.getloadavg()[0]
    print(f"machine: {os.cpu_count()} cores, load average {load:.2f} at the start, {args.threads} threads")
    print("| case | hexes | wall (s) | CPU (s) | µs wall / hex | extraction | surface smoothing | pillowing | "
          "untangle | shape | worst | peak MiB (B / hex) | min SJ, below 0.2 |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    results, series = {}, []
    for name, case_args in cases(args.data):
        if args.only and not any(name.startswith(o) for o in args.only.split(";")):
            continue
        try:
            r = run_case(args.cli, case_args, args.threads, tmp)
        except RuntimeError as e:
            print(f"| {name} | failed: {e} |||||||||||")
            continue
        results[name] = r
        if name.startswith("cthead h"):
            series.append((r["hexes"], r["wall"]))
        s, o = r["stages"], r["optimisation"]
        print(f"| {name} | {r['hexes']:,} | {r['wall']:.1f} | {r['cpu']:.1f} | {1e6 * r['wall'] / r['hexes']:.0f} | "
              f"{s.get('extraction', 0):.2f} | {s.get('surface smoothing', 0):.1f} | {s.get('pillowing', 0):.2f} | "
              f"{o['untangle']:.1f} | {o['shape']:.1f} | {o['worst']:.1f} | "
              f"{r['peak_mib']:.0f} ({r['peak_mib'] * 2**20 / r['hexes']:.0f}) | {r['min_sj']:.3f}, {r['below']} |",
              flush=True)
    if len(series) >= 2:
        print(f"\nwall time ~ hexes^{exponent(series):.2f} over the cthead sizes ({len(series)} points)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"load_average_start": load, "threads": args.threads, "cases": results,
                       "exponent": exponent(series)}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
