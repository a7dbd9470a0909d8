#!/usr/bin/python3
"""The paper's cases through the whole pipeline, checked by VTK: `isohex mesh` with its defaults
on the five default rows of scripts/paper_table.py (cthead, headsq, the head in a sphere,
mAChE, the MR head) must leave no hex inverted and every hex valid inside: det J > 0 at the
2x2x2 Gauss points by numpy (where a solver integrates) and `isohex check` (certified over the
whole element) passing. Below 0.2 none (issue 15's target: headsq kept 2 of 37,987 and the MR
head 1 until the worst pass held the ratio terms while it raised the scaled Jacobian), and no
certified jacobian ratio below 0.1 (the MR head had 0.001 where two dual vertices coincided at
a sample at the isovalue). The scaled Jacobian is
VTK 9.1's vtkMeshQuality (Verdict), not the CLI's; the CLI's own count must agree with it.
Every released boundary vertex must be within the band (the CLI's report:
`released_max_distance` at most 0.3 cells), and no vertex outside the domain.

The case list is paper_table.py's (one list for the table and the test)."""
import argparse
import json
import os
import subprocess
import sys

import numpy as np
from vtk.util.numpy_support import vtk_to_numpy

from vtk_support import hex_quality, read_vtu

MAX_BELOW = 0  # of the hexes
MIN_RATIO = 0.1  # the smallest certified jacobian ratio (Gmsh's minJ/maxJ) allowed


def gauss_det_min(grid):
    """The smallest det J of each hex at its 2x2x2 Gauss points (trilinear map, VTK order)."""
    p = vtk_to_numpy(grid.GetPoints().GetData()).astype(np.float64)
    c = vtk_to_numpy(grid.GetCells().GetConnectivityArray()).reshape(-1, 8)
    x = p[c]  # (hexes, 8, 3)
    g = (1 - 1 / np.sqrt(3)) / 2
    out = np.full(len(c), np.inf)
    for u in (g, 1 - g):
        for v in (g, 1 - g):
            for w in (g, 1 - g):
                xu = ((1-v)*(1-w)*(x[:, 1]-x[:, 0]) + v*(1-w)*(x[:, 2]-x[:, 3]) + (1-v)*w*(x[:, 5]-x[:, 4]) + v*w*(x[:, 6]-x[:, 7]))
                xv = ((1-u)*(1-w)*(x[:, 3]-x[:, 0]) + u*(1-w)*(x[:, 2]-x[:, 1]) + (1-u)*w*(x[:, 7]-x[:, 4]) + u*w*(x[:, 6]-x[:, 5]))
                xw = ((1-u)*(1-v)*(x[:, 4]-x[:, 0]) + u*(1-v)*(x[:, 5]-x[:, 1]) + u*v*(x[:, 6]-x[:, 2]) + (1-u)*v*(x[:, 7]-x[:, 3]))
                out = np.minimum(out, np.einsum("ij,ij->i", xu, np.cross(xv, xw)))
    return out

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import paper_table  # noqa: E402


def unnamed_cases(data):
    """Cases off the default rows (from paper_table.other_sizes()): (name, isohex mesh arguments)."""
    return [(n, a) for n, _, a, _ in paper_table.other_sizes(data) if n.startswith("cthead (bone")]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--data", required=True)
    ap.add_argument("--tmp", required=True)
    ap.add_argument("--only", default="", help="comma-separated case name prefixes")
    args = ap.parse_args()
    if not os.path.isdir(os.path.join(args.data, "volumes")):
        print("no shared data: skipped")
        return 0
    os.makedirs(args.tmp, exist_ok=True)
    failures = []
    ran = 0
    for name, _, mesh_args, prep in paper_table.cases(args.data, args.tmp):
        if "smooth-cubic" in name or "fixed boundary" in name:
            continue  # the default rows only
        if args.only and not any(name.startswith(o) for o in args.only.split(",")):
            continue
        ran += 1
        if prep:
            subprocess.run([args.cli] + prep, check=True, capture_output=True)
        out, rep = os.path.join(args.tmp, "case.vtu"), os.path.join(args.tmp, "case.json")
        run = subprocess.run([args.cli, "mesh"] + mesh_args + ["-o", out, "--json", rep], capture_output=True, text=True)
        if run.returncode != 0:
            failures.append(f"{name}: isohex mesh exit {run.returncode}: {run.stdout[-600:]} {run.stderr[-300:]}")
            continue
        j = json.load(open(rep))
        grid = read_vtu(out)
        sj = hex_quality(grid)
        gauss_bad = int((gauss_det_min(grid) <= 0).sum())
        below, inverted = int((sj < 0.2).sum()), int((sj < 0).sum())
        h = j["cell_size"]
        print(f"{name}: {len(sj)} hexes; VTK: min SJ {sj.min():.4f}, below 0.2 {below}, inverted {inverted}; "
              f"CLI: below 0.2 {j['scaled_jacobian']['questionable'] + j['scaled_jacobian']['inverted']}; "
              f"released {j['released_vertices']} within {j['released_max_distance'] / h:.3f} cells; "
              f"det J <= 0 at a Gauss point {gauss_bad}; not valid inside {j['validity']['not_valid_inside']}; "
              f"jacobian ratio min {j['validity']['jacobian_ratio_min']:.3f}; {j['seconds']:.1f} s",
              flush=True)
        if inverted or below > MAX_BELOW * len(sj):
            failures.append(f"{name}: {below} hexes below 0.2 ({inverted} inverted) by VTK's scaled Jacobian")
        if j["validity"]["jacobian_ratio_min"] < MIN_RATIO:
            failures.append(f"{name}: {j['validity']['jacobian_ratio_poor']} hexes with a jacobian ratio below "
                            f"{MIN_RATIO} (min {j['validity']['jacobian_ratio_min']:.4f})")
        if gauss_bad:
            failures.append(f"{name}: {gauss_bad} hexes with det J <= 0 at a Gauss point (numpy)")
        if j["outside_domain_vertices"]:
            failures.append(f"{name}: {j['outside_domain_vertices']} vertices outside the domain")
        if j["scaled_jacobian"]["questionable"] + j["scaled_jacobian"]["inverted"] != below:
            failures.append(f"{name}: the CLI's count below 0.2 differs from VTK's ({below})")
        if not j["valid"] or j["off_surface_vertices"] != 0:
            failures.append(f"{name}: invalid, or a vertex off its surface that was not released")
        if j["released_max_distance"] > 0.3 * h * 1.001:
            failures.append(f"{name}: a released vertex {j['released_max_distance']} from its surface (band {0.3 * h})")
        chk = subprocess.run([args.cli, "check", out], capture_output=True, text=True)
        if chk.returncode != 0:
            failures.append(f"{name}: isohex check failed: {chk.stdout[-400:]}")
    # Off the table (a bone isosurface at a cell size thicker than the bone; it keeps a hex that
    # is not valid inside, docs/validity.md): whatever the mesh, `isohex mesh` must fail the run
    # exactly when `isohex check` finds a hex that is not valid inside.
    for name, mesh_args in unnamed_cases(args.data):
        if args.only and not any(name.startswith(o) for o in args.only.split(",")):
            continue
        ran += 1
        out = os.path.join(args.tmp, "unnamed.vtu")
        run = subprocess.run([args.cli, "mesh"] + mesh_args + ["-o", out], capture_output=True, text=True)
        chk = subprocess.run([args.cli, "check", out], capture_output=True, text=True)
        print(f"{name}: isohex mesh exit {run.returncode}, isohex check exit {chk.returncode}", flush=True)
        if run.returncode not in (0, 1) or chk.returncode not in (0, 1) or run.returncode != chk.returncode:
            failures.append(f"{name}: isohex mesh exit {run.returncode} but isohex check exit {chk.returncode}: "
                            f"{chk.stdout[-400:]}")
    for f in failures:
        print("FAIL:", f)
    failed = len({f.split(": ")[0] for f in failures})  # each failure starts with its case's name
    print(f"{ran - failed} passed, {failed} failed")
    return 1 if failures or ran == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
