#!/usr/bin/python3
"""isohex smooth beside Mesquite's ShapeImprovementWrapper, the optimiser the paper used.

What it measures, per input mesh, with the boundary vertices fixed in both tools (Mesquite's
skin = isohex's `--fixed boundary`):

* isohex:   `isohex smooth IN -o OUT.vtk --untangle --fixed boundary --threads T --json R.json`
* Mesquite: `msq_smooth IN_ascii.vtk OUT.vtk --normalize --skin` (the peer's driver: Mesquite
  2.99's global untangling, then inverse-mean-ratio shape improvement by feasible Newton, set up
  as ShapeImprovementWrapper::run_wrapper sets them up; see PEER/README.md). Exit 3 = the wrapper
  refused (untangling left inverted hexes, feasible Newton would not start): "refused".

Whole-process wall seconds (time.perf_counter around the subprocess) and CPU seconds (user +
system, resource.getrusage(RUSAGE_CHILDREN) before/after), median of --runs, the two tools run
alternately (isohex, Mesquite, isohex, Mesquite, ...). The quality of BOTH outputs is counted the
same way, by `isohex quality OUT --json Q.json` (Verdict's scaled Jacobian): min, mean, the
hexes below 0.2 (inverted SJ < 0 + questionable 0 <= SJ < 0.2 + degenerate) and the inverted.
The goal checked per case where Mesquite completes: isohex >= 3x faster (median wall) with an
equal or better min SJ and an equal or smaller count below 0.2.

Cases: box40ij / box80ij (box grids of 40^3 / 80^3 unit cells, interior vertices jittered by
0.3 of a cell by PEER/driver/jitter_interior.py, boundary left flat), the ECR 2015 inputs
(DATA/hexmeshes/ecr2015_{block,bust,dragon,armadillo}_in.mesh) and headsq pillowed before
optimisation (`isohex mesh ... --no-smooth --boundary fixed`, the layout of
scripts/paper_table.py). Every input is also written as ASCII legacy VTK for Mesquite
(`isohex convert --ascii`), which refuses binary VTK.

Run (Mesquite is built first, once, into --build if BUILD/bin/msq_smooth is missing: about 4-9
minutes on 2 cores):

    /usr/bin/python3 bench/mesquite_side_by_side.py --cli build/bin/isohex --data ../shared/data \\
        [--peer ../shared/peers/mesquite] [--build /tmp/isohex-mesquite-build] \\
        [--work /tmp/isohex-mesquite-work] [--runs 3] [--only "block;bust"] [--threads 1] \\
        [--isohex-args=--no-worst] [--json OUT.json]

Mesquite is single-threaded; isohex runs with --threads T (default 1, the like-for-like
comparison). With --isohex-args=--no-worst isohex runs the wrapper's stages only
(untangling, then mean-ratio shape improvement), without its worst-element pass: the same
job, where the default goes on to raise the minimum. A benchmark, not a test: the timings are
only meaningful on an otherwise idle machine (the load average at the start and end is
printed; wall >> CPU means other jobs ran).
Mesquite is LGPL: it is built from the peer folder, nothing of it is in this project.
"""
import argparse
import hashlib
import json
import os
import platform
import re
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "scripts"))
from paper_table import HEADSQ  # noqa: E402  (headsq's raw layout, one list for every script)

BOX_JITTER = 0.3
BOX_SEED = 1
GOAL_SPEEDUP = 3.0


# ----------------------------------------------------------------------------- helpers

def log(msg):
    print(msg, file=sys.stderr, flush=True)


def run_checked(cmd, what, ok=(0,), out=None):
    """Run an untimed preparation command; raise with its stderr tail when it fails."""
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if r.returncode not in ok or (out is not None and not Path(out).exists()):
        tail = (r.stderr.strip() or r.stdout.strip())[-400:]
        raise RuntimeError(f"{what}: exit {r.returncode}: {tail}")
    return r


def timed(cmd, log_path):
    """Run cmd with stdout+stderr to log_path; (exit code, wall s, CPU s)."""
    with open(log_path, "w") as f:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t = time.perf_counter()
        rc = subprocess.run([str(c) for c in cmd], stdout=f, stderr=subprocess.STDOUT).returncode
        wall = time.perf_counter() - t
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return rc, wall, cpu


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def quality(cli, mesh, json_path, threads):
    """Scaled Jacobian of a mesh as `isohex quality` counts it."""
    run_checked([cli, "quality", mesh, "--json", json_path, "--threads", threads], f"isohex quality {mesh}",
                out=json_path)
    q = json.load(open(json_path))
    s = q["metrics"]["scaled_jacobian"]
    # inverted: SJ < 0; questionable: 0 <= SJ < 0.2; degenerate: Verdict could not evaluate the
    # hex (its 1e30 value; left out of min and mean). Disjoint, so their sum is "below 0.2".
    return {"hexes": q["hexes"], "min": s["min"], "mean": s["mean"], "inverted": s["inverted"],
            "questionable": s["questionable"], "degenerate": s["degenerate"],
            "below_0.2": s["inverted"] + s["questionable"] + s["degenerate"]}


def machine():
    model = "?"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        nproc = len(os.sched_getaffinity(0))
    except AttributeError:
        nproc = os.cpu_count()
    return {"nproc": nproc, "cpu_model": model, "platform": platform.platform(), "python": platform.python_version()}


def git_state():
    try:
        head = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(REPO), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True).stdout.strip()
        return head + ("+dirty" if dirty else "")
    except OSError:
        return "?"


# ----------------------------------------------------------------------------- cases

def case_list(data):
    """(name, kind, parameter); the inputs are made by prepare()."""
    out = [("box40ij", "box", 40), ("box80ij", "box", 80)]
    out += [(f"ecr2015_{n}_in", "file", data / "hexmeshes" / f"ecr2015_{n}_in.mesh")
            for n in ("block", "bust", "dragon", "armadillo")]
    out += [("headsq_pillowed", "headsq", data / "volumes" / "headsq_64x64x93_int16le.raw")]
    return out


def prepare(cli, peer, kind, param, name, work, threads):
    """Make the case's input: (isohex input, Mesquite's ASCII VTK input, description)."""
    d = work / name
    d.mkdir(parents=True, exist_ok=True)
    if kind == "box":
        n = param
        grid, grid_ascii, jittered = d / f"box{n}.vtk", d / f"box{n}_ascii.vtk", d / f"box{n}ij.vtk"
        # Unit cells (--size n over n cells): mean edge ~1, as the peer's README measures them.
        run_checked([cli, "generate", "box", "-n", n, "--size", n, "-o", grid], "isohex generate box", out=grid)
        run_checked([cli, "convert", "--ascii", grid, grid_ascii], "isohex convert --ascii", out=grid_ascii)
        run_checked([sys.executable, peer / "driver" / "jitter_interior.py", grid_ascii, jittered, BOX_JITTER,
                     BOX_SEED], "jitter_interior.py", out=jittered)
        src = jittered
        desc = f"box {n}^3 unit cells, interior vertices jittered {BOX_JITTER} (seed {BOX_SEED})"
    elif kind == "file":
        src = Path(param)
        if not src.exists():
            raise FileNotFoundError(f"missing {src}")
        desc = src.name
    elif kind == "headsq":
        vol = Path(param)
        if not vol.exists():
            raise FileNotFoundError(f"missing {vol}")
        src = d / "headsq_pillowed.vtk"
        # The pipeline up to pillowing (surface smoothing, pillow), no optimisation; the boundary
        # "fixed" as the optimisers below keep it. Exit 1 is a mesh a solver would refuse: expected here.
        run_checked([cli, "mesh", vol, "--iso", "1150", "--cell-size", "3.2"] + HEADSQ +
                    ["--no-smooth", "--boundary", "fixed", "--threads", threads, "-o", src,
                     "--json", d / "headsq_mesh.json"], "isohex mesh --no-smooth", ok=(0, 1), out=src)
        desc = "headsq bone iso 1150 h 3.2, pillowed, before optimisation (isohex mesh --no-smooth --boundary fixed)"
    else:
        raise ValueError(kind)
    ascii_in = d / f"{name}_ascii.vtk"
    run_checked([cli, "convert", "--ascii", src, ascii_in], "isohex convert --ascii", out=ascii_in)
    return src, ascii_in, desc


# ----------------------------------------------------------------------------- one case

MSQ_FIXED = re.compile(r"(\d+) fixed \[([^\]]*)\]")
MSQ_STAGES = re.compile(r"untangle: (\d+) iterations, ([\d.]+) s; shape: (\d+) iterations, ([\d.]+) s; optimise ([\d.]+) s")


def run_case(args, msq, name, src, ascii_in):
    d = args.work / name
    ih_out, ih_rep, ih_log = d / "isohex_out.vtk", d / "isohex_smooth.json", d / "isohex_smooth.log"
    mq_out, mq_log = d / "mesquite_out.vtk", d / "mesquite.log"
    ih_cmd = [args.cli, "smooth", src, "-o", ih_out, "--untangle", "--fixed", "boundary", "--threads", args.threads,
              "--json", ih_rep] + args.isohex_args.split()
    # --skin: the skin even where the file carries 'fixed' point data, i.e. exactly isohex's
    # --fixed boundary (the driver's default takes the file's flags when there are any).
    mq_cmd = [msq, ascii_in, mq_out, "--normalize", "--skin"]
    ih_runs, mq_runs = [], []
    for r in range(args.runs):
        for tool, cmd, out, lg, runs in (("isohex", ih_cmd, ih_out, ih_log, ih_runs),
                                         ("mesquite", mq_cmd, mq_out, mq_log, mq_runs)):
            for stale in (out, ih_rep if tool == "isohex" else None):
                if stale is not None and Path(stale).exists():
                    os.remove(stale)
            rc, wall, cpu = timed(cmd, lg)
            run = {"exit": rc, "wall": wall, "cpu": cpu,
                   "output_sha256": sha256(out) if Path(out).exists() else None}
            if tool == "isohex":
                # 0 done; 1 done with inverted hexes left (output written); else an error.
                run["status"] = "done" if rc == 0 else "inverted left" if rc == 1 and out.exists() else "error"
                if ih_rep.exists():
                    rep = json.load(open(ih_rep))
                    run["internal_seconds"] = rep.get("seconds")
                    run["fixed_vertices"] = rep.get("fixed_vertices")
            else:
                # 0 done; 3 the wrapper refused (the untangled state is written); else an error.
                run["status"] = "done" if rc == 0 else "refused" if rc == 3 else "error"
                text = Path(lg).read_text(errors="replace")
                m = MSQ_FIXED.search(text)
                if m:
                    run["fixed_vertices"], run["fixed_from"] = int(m.group(1)), m.group(2)
                m = MSQ_STAGES.search(text)
                if m:
                    run.update({"untangle_iterations": int(m.group(1)), "untangle_seconds": float(m.group(2)),
                                "shape_iterations": int(m.group(3)), "shape_seconds": float(m.group(4)),
                                "optimise_seconds": float(m.group(5))})
            runs.append(run)
            log(f"  {name} run {r + 1}/{args.runs} {tool}: {run['status']} (exit {rc}), "
                f"{wall:.2f} s wall, {cpu:.2f} s CPU")
    res = {}
    for tool, runs, out in (("isohex", ih_runs, ih_out), ("mesquite", mq_runs, mq_out)):
        statuses = {r["status"] for r in runs}
        status = "error" if "error" in statuses else "refused" if "refused" in statuses else \
            "inverted left" if "inverted left" in statuses else "done"
        t = {"status": status, "runs": runs,
             "median_wall": statistics.median(r["wall"] for r in runs),
             "median_cpu": statistics.median(r["cpu"] for r in runs),
             "identical_outputs": len({r["output_sha256"] for r in runs}) == 1,
             "fixed_vertices": runs[-1].get("fixed_vertices")}
        if out.exists():  # the last run's output (a refused Mesquite run writes its untangled state)
            t["quality"] = quality(args.cli, out, d / f"{tool}_quality.json", args.threads)
        res[tool] = t
    return res


def verdict(c):
    """The goal where Mesquite completes: >= 3x faster, min SJ and count below 0.2 equal or better."""
    ih, mq = c["isohex"], c["mesquite"]
    if ih["status"] == "error" or "quality" not in ih:
        return None, "isohex failed"
    if mq["status"] == "refused":
        return None, "n/a (Mesquite refused)"
    if mq["status"] == "error" or "quality" not in mq:
        return None, "n/a (Mesquite failed)"
    qi, qm = ih["quality"], mq["quality"]
    why = []
    if c["ratio_wall"] < GOAL_SPEEDUP:
        why.append(f"{c['ratio_wall']:.2f}x < {GOAL_SPEEDUP:g}x")
    if qi["min"] < qm["min"]:
        why.append("min SJ lower")
    if qi["below_0.2"] > qm["below_0.2"]:
        why.append("more < 0.2")
    return (not why), ("yes" if not why else "no: " + ", ".join(why))


# ----------------------------------------------------------------------------- table

def fmt_time(t):
    return f"{t['median_wall']:.2f} ({t['median_cpu']:.2f})"


def fmt_q(t):
    q = t.get("quality")
    if q is None:
        return "-"
    return f"{q['min']:.4f} / {q['mean']:.4f}, {q['below_0.2']} ({q['inverted']} inv.)"


def table(results):
    lines = ["| case | hexes | isohex s (CPU) | Mesquite s (CPU) | Mesquite / isohex | "
             "isohex min / mean SJ, #<0.2 (inv.) | Mesquite min / mean SJ, #<0.2 (inv.) | "
             f"goal: >= {GOAL_SPEEDUP:g}x, min SJ and #<0.2 no worse |",
             "|---|---|---|---|---|---|---|---|"]
    notes = []
    for c in results:
        if "error" in c:
            lines.append(f"| {c['name']} | - | - | - | - | - | - | {c['error']} |")
            continue
        ih, mq = c["isohex"], c["mesquite"]
        ih_t = fmt_time(ih) + ("" if ih["status"] == "done" else f" {ih['status']}")
        if mq["status"] == "done":
            mq_t = fmt_time(mq)
            ratio = f"{c['ratio_wall']:.2f} (CPU {c['ratio_cpu']:.2f})"
        else:
            mq_t = f"{mq['status']} after {fmt_time(mq)}"
            ratio = "-"
        mq_q = fmt_q(mq) + (" (untangled state)" if mq["status"] == "refused" and "quality" in mq else "")
        lines.append(f"| {c['name']} | {c['hexes']} | {ih_t} | {mq_t} | {ratio} | {fmt_q(ih)} | {mq_q} | "
                     f"{c['goal_text']} |")
        fi, fm = ih.get("fixed_vertices"), mq.get("fixed_vertices")
        if fi is not None and fm is not None and fi != fm:
            notes.append(f"{c['name']}: fixed vertices differ: isohex {fi}, Mesquite {fm}")
        for tool, t in (("isohex", ih), ("Mesquite", mq)):
            if not t["identical_outputs"]:
                notes.append(f"{c['name']}: {tool}'s outputs differ between runs")
            if "quality" in t and t["quality"]["hexes"] != c["hexes"]:
                notes.append(f"{c['name']}: {tool}'s output has {t['quality']['hexes']} hexes, input {c['hexes']}")
    return "\n".join(lines), notes


# ----------------------------------------------------------------------------- main

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=str(REPO / "build" / "bin" / "isohex"), help="the isohex binary")
    ap.add_argument("--data", default=str(REPO.parent / "shared" / "data"), help="shared data folder")
    ap.add_argument("--peer", default=str(REPO / ".." / "shared" / "peers" / "mesquite"),
                    help="the Mesquite peer folder (build.sh, driver/)")
    ap.add_argument("--build", default="/tmp/isohex-mesquite-build",
                    help="Mesquite build folder; built (JOBS=2 PEER/build.sh BUILD) if BUILD/bin/msq_smooth is missing")
    ap.add_argument("--work", default="/tmp/isohex-mesquite-work", help="scratch folder (inputs, outputs, logs)")
    ap.add_argument("--runs", type=int, default=3, help="runs per tool, median reported (default 3)")
    ap.add_argument("--only", default="", help='";"-separated substrings of case names, e.g. "block;bust"')
    ap.add_argument("--threads", type=int, default=1, help="isohex worker threads (default 1; Mesquite has one)")
    ap.add_argument("--isohex-args", default="",
                    help="more options of isohex smooth, e.g. --isohex-args=--no-worst: the same stages as the wrapper "
                         "(untangling, then mean-ratio shape improvement), without the worst-element pass")
    ap.add_argument("--json", help="write every result to this JSON file")
    args = ap.parse_args()
    if args.runs < 1:
        ap.error("--runs must be at least 1")
    args.cli = Path(args.cli).resolve()
    args.data = Path(args.data).resolve()
    args.peer = Path(args.peer).resolve()
    args.build = Path(args.build).resolve()
    args.work = Path(args.work).resolve()
    if not args.cli.exists():
        ap.error(f"no isohex binary at {args.cli}")

    msq = args.build / "bin" / "msq_smooth"
    if not msq.exists():
        log(f"building Mesquite into {args.build} (JOBS=2 {args.peer / 'build.sh'}; 4-9 minutes)...")
        args.build.mkdir(parents=True, exist_ok=True)
        with open(args.build / "build.log", "w") as f:
            rc = subprocess.run([str(args.peer / "build.sh"), str(args.build)], stdout=f, stderr=subprocess.STDOUT,
                                env=dict(os.environ, JOBS="2")).returncode
        if rc != 0 or not msq.exists():
            sys.exit(f"Mesquite build failed (exit {rc}); see {args.build / 'build.log'}")
    args.work.mkdir(parents=True, exist_ok=True)

    only = [s.strip() for s in args.only.split(";") if s.strip()]
    cases = [c for c in case_list(args.data) if not only or any(s in c[0] for s in only)]
    if not cases:
        sys.exit(f"no case matches --only {args.only!r}")

    mach = machine()
    load_start = os.getloadavg()
    version = subprocess.run([str(args.cli), "--version"], capture_output=True, text=True).stdout.strip()
    meta = {"machine": mach, "load_start": load_start, "isohex": str(args.cli), "isohex_version": version,
            "git": git_state(), "msq_smooth": str(msq), "threads_isohex": args.threads, "threads_mesquite": 1,
            "runs": args.runs, "work": str(args.work), "isohex_args": args.isohex_args,
            "commands": {"isohex": "isohex smooth IN -o OUT.vtk --untangle --fixed boundary --threads T --json R.json"
                                   + (" " + args.isohex_args if args.isohex_args else ""),
                         "mesquite": "msq_smooth IN_ascii.vtk OUT.vtk --normalize --skin",
                         "quality": "isohex quality OUT --json Q.json"}}

    results = []

    def dump():
        if args.json:
            with open(args.json, "w") as f:
                json.dump({**meta, "cases": results}, f, indent=1)

    for name, kind, param in cases:
        log(f"{name}: preparing the input...")
        c = {"name": name}
        try:
            src, ascii_in, desc = prepare(args.cli, args.peer, kind, param, name, args.work, args.threads)
            c.update({"description": desc, "input": str(src), "mesquite_input": str(ascii_in)})
            c["before"] = quality(args.cli, src, args.work / name / "input_quality.json", args.threads)
            c["hexes"] = c["before"]["hexes"]
            c.update(run_case(args, msq, name, src, ascii_in))
            ih, mq = c["isohex"], c["mesquite"]
            c["ratio_wall"] = mq["median_wall"] / ih["median_wall"] if ih["median_wall"] > 0 else float("nan")
            c["ratio_cpu"] = mq["median_cpu"] / ih["median_cpu"] if ih["median_cpu"] > 0 else float("nan")
            c["goal_met"], c["goal_text"] = verdict(c)
        except (RuntimeError, OSError, ValueError, KeyError) as e:  # a failed case does not stop the others
            c["error"] = str(e)
            log(f"{name}: {e}")
        results.append(c)
        dump()

    load_end = os.getloadavg()
    meta["load_end"] = load_end
    dump()

    text, notes = table(results)
    print(f"Machine: {mach['nproc']} CPUs (nproc), {mach['cpu_model']}; load average at start "
          f"{' '.join(f'{x:.2f}' for x in load_start)}, at end {' '.join(f'{x:.2f}' for x in load_end)}")
    print(f"isohex: {version} ({meta['git']}), --threads {args.threads}{' ' + args.isohex_args if args.isohex_args else ''}; Mesquite 2.99 (msq_smooth, single-threaded); "
          f"median of {args.runs} run(s), alternating")
    print()
    print("Seconds: whole-process wall (CPU = user + system). Mesquite / isohex: median wall ratio (CPU ratio). "
          "Quality of both outputs by `isohex quality` (scaled Jacobian); #<0.2 = inverted + questionable + "
          "degenerate.")
    print()
    print(text)
    for n in notes:
        print(f"\nNote: {n}")
    if args.json:
        print(f"\nresults: {args.json}")


if __name__ == "__main__":
    main()
