#!/usr/bin/python3
"""Oracle test: the boundary quads that `isohex mesh` leaves after surface smoothing on real
scans, measured by VTK (vtkDataSetSurfaceFilter + vtkMeshQuality's quad scaled Jacobian).

For each case the pipeline runs up to pillowing (`--no-smooth`: the pillow keeps the surface
bit-identical, so this is the surface the optimiser gets, with the boundary fixed) and once
with no surface smoothing. VTK (quads) and numpy (fan margins: how well one direction points
into every quad corner at a vertex, the bound on the pillow hexes' corners there) must count
what the CLI's JSON reports, the smoothing must leave at most the documented number of
boundary quads below 0 and below 0.2 and fans below 0.2 (dual contouring leaves more than a
thousand of each on these scans), every boundary vertex must be on the
isosurface, the mesh valid, and the same bits with 1 and 2 threads. Exits non-zero on any
failure.
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy
from vtk_support import read_vtu

FAILURES = []


def check(ok, what):
    print(("ok:   " if ok else "FAIL: ") + what)
    if not ok:
        FAILURES.append(what)


def boundary(path):
    """The boundary quads' scaled Jacobians (VTK) and fan margins (numpy) of a mesh file."""
    s = vtk.vtkDataSetSurfaceFilter()
    s.SetInputData(read_vtu(path))
    s.Update()
    q = vtk.vtkMeshQuality()
    q.SetInputData(s.GetOutput())
    q.SetQuadQualityMeasureToScaledJacobian()
    q.Update()
    sj = vtk_to_numpy(q.GetOutput().GetCellData().GetArray("Quality"))
    poly = s.GetOutput()
    pts = vtk_to_numpy(poly.GetPoints().GetData())
    quads = vtk_to_numpy(poly.GetPolys().GetConnectivityArray()).reshape(-1, 4)
    return sj, fan_margins(pts, quads)


def fan_margins(pts, quads):
    """Per boundary vertex b: max over unit d of min over b's quad corners of c.d, c = (e1 x e2)
    / (|e1||e2|) with e1, e2 the corner's edges to the next and previous vertex (outward for
    quads counter-clockwise seen from outside). Approximated, as the definition says, by the
    best of the corners' own directions, their pairwise bisectors and their sum."""
    corners = {}
    for q in quads:
        for i in range(4):
            b, nxt, prv = q[i], q[(i + 1) % 4], q[(i + 3) % 4]
            e1, e2 = pts[nxt] - pts[b], pts[prv] - pts[b]
            l = np.linalg.norm(e1) * np.linalg.norm(e2)
            corners.setdefault(b, []).append(np.cross(e1, e2) / l if l > 0 else np.zeros(3))
    out = []
    for b, cs in corners.items():
        C = np.array(cs)
        if np.any(np.linalg.norm(C, axis=1) == 0):  # a collapsed edge: no direction helps
            out.append(0.0)
            continue
        U = C / np.maximum(np.linalg.norm(C, axis=1, keepdims=True), 1e-300)
        cand = [U.sum(0)] + list(U) + [U[i] + U[j] for i in range(len(U)) for j in range(i + 1, len(U))]
        best = -1.0
        for d in cand:
            n = np.linalg.norm(d)
            if n > 0:
                best = max(best, min(1.0, float((C @ (d / n)).min())))
        out.append(best)
    return np.array(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--data", required=True)
    ap.add_argument("--tmp", required=True)
    args = ap.parse_args()
    os.makedirs(args.tmp, exist_ok=True)
    v = lambda f: os.path.join(args.data, "volumes", f)
    # name, arguments, allowed boundary quads below 0 and below 0.2 and fans below 0.2 after
    # smoothing (measured 2026-11-23: headsq 1, 26 and 144 of 1,140 and 1,463 below 0.2 raw;
    # cthead 13, 158, 501 of 1,095 and 1,750, after the tunnel moves of the repair changed its
    # extraction; 6 folded before). Fans and quads compete: the fans bound the
    # pillow hexes' corners, so the smoothing trades some quads for them.
    cases = [
        ("headsq h 3.2", [v("headsq_64x64x93_int16le.raw"), "--iso", "1150", "--cell-size", "3.2", "--dims", "64", "64",
                          "93", "--type", "i16", "--spacing", "3.2", "3.2", "1.5"], 2, 40, 200),
        ("cthead h 4", [v("cthead_256x256x113_int16be.raw"), "--iso", "600", "--cell-size", "4", "--dims", "256", "256",
                        "113", "--type", "i16", "--endian", "big", "--spacing", "1", "1", "2"], 16, 220, 650),
    ]
    for name, mesh_args, max_folded, max_below, max_fans in cases:
        runs = {}
        for label, extra in (("raw", ["--no-surface-smoothing"]), ("smoothed", [])):
            out = os.path.join(args.tmp, f"surface-{label}.vtu")
            rep = os.path.join(args.tmp, f"surface-{label}.json")
            run = subprocess.run([args.cli, "mesh"] + mesh_args + extra + ["--no-smooth", "-o", out, "--json", rep],
                                 capture_output=True, text=True)
            check(run.returncode == 0, f"{name} {label}: isohex mesh exit {run.returncode} {run.stderr[-300:]}")
            if run.returncode != 0:
                break
            runs[label] = (boundary(out), json.load(open(rep)))
        if len(runs) < 2:
            continue
        (raw, raw_fans), _ = runs["raw"]
        (sj, fans), rep = runs["smoothed"]
        folded, below = int((sj < 0).sum()), int((sj < 0.2).sum())
        print(f"{name}: {len(sj)} boundary quads; below 0: {int((raw < 0).sum())} -> {folded}; "
              f"below 0.2: {int((raw < 0.2).sum())} -> {below}; min {raw.min():.3f} -> {sj.min():.3f}")
        s = rep["surface_smoothing"][0]
        check(s["after"]["boundary_quads_below_0.2"] == below,
              f"{name}: the CLI's count below 0.2 ({s['after']['boundary_quads_below_0.2']}) is VTK's ({below})")
        check(abs(s["after"]["boundary_quad_sj_min"] - float(sj.min())) <= 1e-9,
              f"{name}: the CLI's min quad SJ is VTK's")
        fans_below = int((fans < 0.2).sum())
        print(f"{name}: fans below 0.2: {int((raw_fans < 0.2).sum())} -> {fans_below}, min {raw_fans.min():.3f} -> "
              f"{fans.min():.3f}")
        check(s["after"]["fans_below_0.2"] == fans_below,
              f"{name}: the CLI's fans below 0.2 ({s['after']['fans_below_0.2']}) are numpy's ({fans_below})")
        check(int((raw < 0.2).sum()) > 4 * max(below, 1), f"{name}: the raw extraction had the bad quads to fix")
        check(fans_below <= max_fans, f"{name}: at most {max_fans} fans below 0.2 (got {fans_below})")
        check(folded <= max_folded, f"{name}: at most {max_folded} folded boundary quads (got {folded})")
        check(below <= max_below, f"{name}: at most {max_below} boundary quads below 0.2 (got {below})")
        check(rep["valid"] and rep["off_surface_vertices"] == 0 and rep["max_relative_distance"] <= 1e-6,
              f"{name}: valid, every boundary vertex on the isosurface")
        # The same bits for 1 and 2 threads (the max-min pass moves vertices in parallel).
        outs = []
        for t in ("1", "2"):
            out = os.path.join(args.tmp, f"surface-t{t}.vtu")
            subprocess.run([args.cli, "mesh"] + mesh_args + ["--no-smooth", "--threads", t, "-o", out],
                           capture_output=True, text=True)
            outs.append(open(out, "rb").read() if os.path.exists(out) else b"")
        check(outs[0] != b"" and outs[0] == outs[1], f"{name}: the same mesh bit for bit with 1 and 2 threads")
    if FAILURES:
        print(f"{len(FAILURES)} failure(s)")
        sys.exit(1)


if __name__ == "__main__":
    main()
