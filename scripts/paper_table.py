#!/usr/bin/python3
"""The paper's table (Shepherd et al. 2006, figures 9-15) with isohex: runs `isohex mesh` (the
whole pipeline) on the paper-like cases in ../shared/data and prints, per case, the hexes
before/after pillowing, the elements below 0.2 before (after surface smoothing, the paper's
"original mesh") and after (pillowing + optimisation), inverted, min scaled Jacobian and time,
beside the paper's figures. Writes the Markdown table to --out (default docs/paper-table.md).

    /usr/bin/python3 scripts/paper_table.py --cli build/bin/isohex --data ../shared/data [--other-sizes]

Each row also has what a solver sees: hexes not certified valid inside and with det J <= 0 at
a Gauss point, the smallest jacobian ratio (min/max det J) with the count below 0.1, the largest
edge ratio, the volume excess of the hexes' |det J| over the enclosed volume (overlap) and the
vertices outside the sampled domain.
"""
import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile

# The paper's figures: (hexes before, hexes after pillowing, < 0.2 before, < 0.2 after).
PAPER = {
    "knee": (1338, 2682, 367, 0),
    "head": (6583, 9487, 1025, 1),
    "head in sphere": (13352, 19412, 2485, 0),
    "mAChE": (70913, 90937, 7298, 111),
}

CTHEAD = ["--dims", "256", "256", "113", "--type", "i16", "--endian", "big", "--spacing", "1", "1", "2"]
HEADSQ = ["--dims", "64", "64", "93", "--type", "i16", "--spacing", "3.2", "3.2", "1.5"]


def cases(data, tmp):
    v = lambda f: os.path.join(data, "volumes", f)
    mache = os.path.join(tmp, "mache.vti")
    return [
        # name, paper row, isohex mesh arguments, preparation command (or None)
        ("cthead (skin, h 4)", "head", [v("cthead_256x256x113_int16be.raw"), "--iso", "600", "--cell-size", "4"] + CTHEAD, None),
        ("headsq (bone, h 3.2)", "head", [v("headsq_64x64x93_int16le.raw"), "--iso", "1150", "--cell-size", "3.2"] + HEADSQ, None),
        ("cthead in a sphere (h 8)", "head in sphere",
         [v("cthead_256x256x113_int16be.raw"), "--iso", "600", "--cell-size", "8", "--region", "outside",
          "--outer", "sphere:127.5,127.5,112,160"] + CTHEAD, None),
        ("mAChE (iso 1, h 1)", "mAChE", [mache, "--iso", "1", "--cell-size", "1"],
         ["volume", "molecule", os.path.join(data, "molecules", "mache_1MAH.pqr"), "-o", mache]),
        ("MR head (iso 40, h 4)", None, [v("HeadMRVolume.mhd"), "--iso", "40", "--cell-size", "4"], None),
        # The same scans on the smoothing cubic B-spline of their samples (--interpolation
        # smooth-cubic): the boundary lies on that isosurface instead of the trilinear one.
        ("cthead (skin, h 4, smooth-cubic)", "head", [v("cthead_256x256x113_int16be.raw"), "--iso", "600", "--cell-size", "4",
                                               "--interpolation", "smooth-cubic"] + CTHEAD, None),
        ("headsq (bone, h 3.2, smooth-cubic)", "head", [v("headsq_64x64x93_int16le.raw"), "--iso", "1150", "--cell-size",
                                                 "3.2", "--interpolation", "smooth-cubic"] + HEADSQ, None),
        ("MR head (iso 40, h 4, smooth-cubic)", None, [v("HeadMRVolume.mhd"), "--iso", "40", "--cell-size", "4",
                                                "--interpolation", "smooth-cubic"], None),
        # The paper's fixed boundary in the optimisation (`--boundary fixed`) instead of the
        # default, where boundary vertices slide on their surfaces (isosurface, outer sphere).
        ("cthead (skin, h 4, fixed boundary)", "head", [v("cthead_256x256x113_int16be.raw"), "--iso", "600", "--cell-size",
                                                 "4", "--boundary", "fixed"] + CTHEAD, None),
        ("headsq (bone, h 3.2, fixed boundary)", "head", [v("headsq_64x64x93_int16le.raw"), "--iso", "1150", "--cell-size",
                                                   "3.2", "--boundary", "fixed"] + HEADSQ, None),
        ("cthead in a sphere (h 8, fixed boundary)", "head in sphere",
         [v("cthead_256x256x113_int16be.raw"), "--iso", "600", "--cell-size", "8", "--region", "outside",
          "--outer", "sphere:127.5,127.5,112,160", "--boundary", "fixed"] + CTHEAD, None),
        ("mAChE (iso 1, h 1, fixed boundary)", "mAChE", [mache, "--iso", "1", "--cell-size", "1", "--boundary", "fixed"],
         ["volume", "molecule", os.path.join(data, "molecules", "mache_1MAH.pqr"), "-o", mache]),
        ("MR head (iso 40, h 4, fixed boundary)", None, [v("HeadMRVolume.mhd"), "--iso", "40", "--cell-size", "4",
                                                  "--boundary", "fixed"], None),
    ]


def other_sizes(data):
    """Other cell sizes of the same scans (issue 15: a default that holds off the table's rows)."""
    v = lambda f: os.path.join(data, "volumes", f)
    return [
        ("cthead (skin, h 3)", None, [v("cthead_256x256x113_int16be.raw"), "--iso", "600", "--cell-size", "3"] + CTHEAD, None),
        ("cthead (skin, h 2)", None, [v("cthead_256x256x113_int16be.raw"), "--iso", "600", "--cell-size", "2"] + CTHEAD, None),
        ("headsq (bone, h 2)", None, [v("headsq_64x64x93_int16le.raw"), "--iso", "1150", "--cell-size", "2"] + HEADSQ, None),
        ("headsq (bone, h 4)", None, [v("headsq_64x64x93_int16le.raw"), "--iso", "1150", "--cell-size", "4"] + HEADSQ, None),
        ("MR head (iso 40, h 3)", None, [v("HeadMRVolume.mhd"), "--iso", "40", "--cell-size", "3"], None),
        # The other volumes of scripts/pillow_table.py, and a bone isosurface thinner than a cell.
        ("bucky (iso 51, h 1)", None, [v("bucky_32x32x32_uint8.raw"), "--dims", "32", "32", "32", "--type", "u8",
                                       "--iso", "51", "--cell-size", "1"], None),
        ("ironProt (iso 128, h 1)", None, [v("ironProt.vtk"), "--iso", "128", "--cell-size", "1"], None),
        ("cthead (bone, iso 1200, h 5)", None, [v("cthead_256x256x113_int16be.raw"), "--iso", "1200", "--cell-size", "5"]
         + CTHEAD, None),
    ]


def inside_measures(cli, mesh, tmp):
    """What a solver sees (issue 15): hexes not valid inside, det J <= 0 at a Gauss point, the
    smallest jacobian ratio and how many are below 0.1, the largest edge ratio, the volume
    excess of |det J| over the enclosed volume: from `isohex check` and `isohex quality`."""
    chk, qj = os.path.join(tmp, "check.json"), os.path.join(tmp, "quality.json")
    subprocess.run([cli, "check", mesh, "--json", chk], capture_output=True)
    subprocess.run([cli, "quality", mesh, "--metric", "edge_ratio", "--json", qj], capture_output=True)
    c, q = json.load(open(chk)), json.load(open(qj))
    v = q["validity"]
    return {"invalid": v["not_valid_inside"], "gauss": v["gauss_nonpositive"], "ratio": v["jacobian_ratio_min"],
            "poor": v["jacobian_ratio_poor"] + v["not_valid_inside"], "edge_ratio": q["metrics"]["edge_ratio"]["max"],
            "excess": c["volume"]["excess"]}


def row_of(stages, name):
    for s in stages:
        if s["stage"] == name:
            return s
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cli", default="build/bin/isohex")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data"))
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "..", "docs", "paper-table.md"))
    ap.add_argument("--only", default="", help="case names (prefixes), separated by ';' (names contain commas)")
    ap.add_argument("--other-sizes", action="store_true", help="also other cell sizes of the same scans")
    args = ap.parse_args()
    if not os.path.isdir(os.path.join(args.data, "volumes")):
        sys.exit(f"{args.data}: no volumes/ folder (the shared data)")
    tmp = tempfile.mkdtemp(prefix="isohex-paper-")
    lines = ["| case | hexes before → after pillowing | < 0.2 before → after | inverted after | min SJ after | "
             "mean SJ after | not valid inside / det J ≤ 0 at a Gauss point | min jacobian ratio (< 0.1) | "
             "max edge ratio | volume excess | outside the domain | time (s) | paper: hexes | paper: < 0.2 |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, paper, mesh_args, prep in cases(args.data, tmp) + (other_sizes(args.data) if args.other_sizes else []):
        if args.only and not any(name.startswith(o) for o in args.only.split(";")):
            continue
        if prep:
            subprocess.run([args.cli] + prep, check=True, capture_output=True)
        rep = os.path.join(tmp, "report.json")
        run = subprocess.run([args.cli, "mesh"] + mesh_args + ["-o", os.path.join(tmp, "mesh.vtu"), "--json", rep],
                             capture_output=True, text=True)
        if not os.path.exists(rep):
            print(f"{name}: isohex mesh failed ({run.returncode}): {run.stdout[-500:]} {run.stderr[-500:]}")
            continue
        j = json.load(open(rep))
        os.remove(rep)
        m = inside_measures(args.cli, os.path.join(tmp, "mesh.vtu"), tmp)
        st = j["stages"]
        before = row_of(st, "surface smoothing") or row_of(st, "extraction")
        pil, final = row_of(st, "pillowing"), st[-1]
        sj = final["scaled_jacobian"]
        p = PAPER.get(paper) if paper else None
        line = (f"| {name} | {before['hexes']:,} → {pil['hexes'] if pil else final['hexes']:,} | "
                f"{before['below_0.2']:,} → {final['below_0.2']:,} | {sj['inverted'] + sj['degenerate']:,} | "
                f"{sj['min']:.3f} | {sj['mean']:.3f} | {m['invalid']:,} / {m['gauss']:,} | {m['ratio']:.3f} ({m['poor']:,}) | "
                f"{m['edge_ratio']:.1f} | {m['excess']:.1e} | {j['outside_domain_vertices']:,} | {j['seconds']:.1f} | "
                + (f"{p[0]:,} → {p[1]:,} ({paper}) | {p[2]:,} → {p[3]:,} |" if p else "– | – |"))
        print(line, flush=True)
        lines.append(line)
    header = (f"Measured {datetime.date.today()} on {platform.node()} ({os.cpu_count()} cores) with "
              f"`/usr/bin/python3 scripts/paper_table.py --cli {args.cli}`; 'before' is the mesh after extraction "
              f"and surface smoothing (the paper's geometric-flow mesh), 'after' after boundary pillowing, untangling "
              f"and mean-ratio optimisation (the boundary sliding on its surfaces, or fixed where the row says). The paper's figures are from its figures 9-15 "
              f"(LBIE-Mesher's adaptive meshes of other scans, optimised with Mesquite).\n\n")
    # The commentary after the table is written by hand: keep what the old file has there.
    commentary = ""
    if os.path.exists(args.out):
        old = open(args.out).read().split("\n")
        rows = [i for i, l in enumerate(old) if l.startswith("|")]
        if rows:
            commentary = "\n".join(old[rows[-1] + 1:]).rstrip("\n")
    with open(args.out, "w") as f:
        f.write("# The paper's table, reproduced\n\n" + header + "\n".join(lines) + "\n" +
                (commentary + "\n" if commentary else ""))
    print(f"written: {args.out}")


if __name__ == "__main__":
    main()
