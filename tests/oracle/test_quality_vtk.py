#!/usr/bin/python3
"""Oracle test: `isohex quality --per-element` against VTK 9.1's vtkMeshQuality and numpy.

Random hexes (well shaped, affine, perturbed, inverted, nearly flat, exactly degenerate) are
written with VTK's own XML writer; every hex of every shared mesh is read both by isohex and
by VTK (or, for .mesh/.inp, by a few lines of python). For each metric VTK has, the CLI's
per-element values must agree with vtkMeshQuality to 1e-12 relative (absolute floor 1e-2 for
dimensionless metrics, 1e-2 * size^3 for jacobian and volume), and degenerate markers must
match. VTK is given each hex translated to its centroid (an exact translation: p - c is exact
for the nearby c): its Verdict sums raw coordinates (P1+P2+P5+P6-P0-...), which on a mesh far
from the origin loses digits that the metric itself does not. A file whose points VTK reads as
float32 (legacy "float") is handed to VTK as `isohex convert`ed .vtu, so that both see the
same doubles. Two documented differences are handled, not hidden:
  * VTK 9.1 bundles a Verdict older than 1.4.4: no normalisation, degeneracy threshold 1e-30
    on raw squared lengths instead of 2.22e-15 on normalised ones. Elements whose lengths
    (or corner determinants, for shape) lie between the two thresholds are left out of the
    comparison and counted; exactly degenerate ones (a zero-length edge) must be 1e30 in both.
  * VTK 9.1's hex volume is the centre-Jacobian estimate; Verdict 1.4+ and isohex return the
    exact trilinear volume. Volume is checked against numpy's 2x2x2 Gauss quadrature of the
    trilinear Jacobian (exact), and against VTK on parallelepipeds, where both are exact.
mean_ratio (not in VTK) is checked against an independent numpy formula. Exits non-zero on
any failure.
"""
import argparse
import os
import subprocess
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray, vtk_to_numpy
from vtk_support import hex_quality

DBL_MIN_NEW = 2.2204460492503131e-15  # Verdict >= 1.4.4, on normalised coordinates
DBL_MIN_OLD = 1e-30                   # VTK 9.1's Verdict, on raw coordinates
DBL_MAX = 1e30
REL = 1e-12
VTK_MEASURE = {"scaled_jacobian": "ScaledJacobian", "jacobian": "Jacobian", "edge_ratio": "EdgeRatio",
               "shape": "Shape", "skew": "Skew", "taper": "Taper", "volume": "Volume"}
DIMENSIONAL = {"jacobian", "volume"}
CORNERS = [(1, 3, 4), (2, 0, 5), (3, 1, 6), (0, 2, 7), (7, 5, 0), (4, 6, 1), (5, 7, 2), (6, 4, 3)]
EDGES = [(0, 1), (1, 2), (3, 2), (0, 3), (4, 5), (5, 6), (7, 6), (4, 7), (0, 4), (1, 5), (3, 7), (2, 6)]
FAILURES = []


def check(ok, what):
    if not ok:
        FAILURES.append(what)
        print("FAIL:", what)


# ---- geometry in numpy (P: n x 8 x 3, VTK node order) ---------------------------------

def centre_axes(P):
    x1 = (P[:, 1] - P[:, 0]) + (P[:, 2] - P[:, 3]) + (P[:, 5] - P[:, 4]) + (P[:, 6] - P[:, 7])
    x2 = (P[:, 2] - P[:, 0]) + (P[:, 3] - P[:, 1]) + (P[:, 6] - P[:, 4]) + (P[:, 7] - P[:, 5])
    x3 = (P[:, 4] - P[:, 0]) + (P[:, 5] - P[:, 1]) + (P[:, 6] - P[:, 2]) + (P[:, 7] - P[:, 3])
    return x1, x2, x3


def cross_derivatives(P):
    e12 = (P[:, 0] - P[:, 1]) + (P[:, 2] - P[:, 3]) + (P[:, 4] - P[:, 5]) + (P[:, 6] - P[:, 7])
    e13 = (P[:, 0] - P[:, 1]) + (P[:, 3] - P[:, 2]) + (P[:, 5] - P[:, 4]) + (P[:, 6] - P[:, 7])
    e23 = (P[:, 0] - P[:, 2]) + (P[:, 1] - P[:, 3]) + (P[:, 6] - P[:, 4]) + (P[:, 7] - P[:, 5])
    return e12, e13, e23


def frames(P):
    """The 9 scaled-Jacobian triples: centre axes, then the 8 corner frames."""
    out = [centre_axes(P)]
    for k, (a, b, c) in enumerate(CORNERS):
        out.append((P[:, a] - P[:, k], P[:, b] - P[:, k], P[:, c] - P[:, k]))
    return out


def normalised(P):
    lo, hi = P.min(axis=1), P.max(axis=1)
    diag = np.sqrt(((hi - lo) ** 2).sum(axis=1))
    centre = P.sum(axis=1) / 8
    tiny = diag < DBL_MIN_NEW
    centre[tiny] = 0
    diag = np.where(tiny, 1.0, diag)
    return (P - centre[:, None, :]) / diag[:, None, None], diag


def sq(v):
    return (v * v).sum(axis=1)


def det3(a, b, c):
    return (a * np.cross(b, c)).sum(axis=1)


def size_of(P):
    return np.sqrt(((P.max(axis=1) - P.min(axis=1)) ** 2).sum(axis=1))


def gap_and_exact(P, metric):
    """Per hex: (in the threshold gap between the two Verdict versions, exactly degenerate).

    An element is in the gap when one of its edges or scaled-Jacobian vectors has a squared
    length between the two degeneracy thresholds (with a factor 10 of margin on each side):
    one Verdict calls it degenerate, the other does not, and normalising such an element
    costs the short vector its leading digits, so none of its metrics is compared to 1e-12.
    For shape the same holds for a corner determinant, for skew and taper for an axis length.
    Exactly degenerate: one of the vectors the metric tests is exactly zero (both give 1e30)."""
    n = len(P)
    if metric == "jacobian":  # no threshold, no normalisation: compared everywhere
        return np.zeros(n, bool), np.zeros(n, bool)
    Q, _ = normalised(P)
    near = lambda nrm, raw: ((nrm <= 10 * DBL_MIN_NEW) | (raw <= 10 * DBL_MIN_OLD)) & (raw > 0)
    gap, exact = np.zeros(n, bool), np.zeros(n, bool)
    for (a, b, c), (qa, qb, qc) in zip(frames(P), frames(Q)):
        for raw, nrm in ((a, qa), (b, qb), (c, qc)):
            gap |= near(sq(nrm), sq(raw))
            if metric == "scaled_jacobian":
                exact |= sq(raw) == 0
    for i, j in EDGES:
        raw, nrm = P[:, j] - P[:, i], Q[:, j] - Q[:, i]
        gap |= near(sq(nrm), sq(raw))
        if metric == "edge_ratio":
            exact |= sq(raw) == 0
    if metric == "shape":
        for k, (a, b, c) in enumerate(CORNERS):
            raw = det3(P[:, a] - P[:, k], P[:, b] - P[:, k], P[:, c] - P[:, k])
            nrm = det3(Q[:, a] - Q[:, k], Q[:, b] - Q[:, k], Q[:, c] - Q[:, k])
            gap |= (np.abs(nrm) <= 10 * DBL_MIN_NEW) & (np.abs(raw) > 0)
    elif metric in ("skew", "taper"):
        for raw, nrm in zip(centre_axes(P), centre_axes(Q)):
            gap |= near(np.sqrt(sq(nrm)), np.sqrt(sq(raw)))
            exact |= sq(raw) == 0
    return gap & ~exact, exact


def trilinear_volume(P):
    """Exact volume of the trilinear hex: 2x2x2 Gauss integrates its Jacobian exactly."""
    xi = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
    g = 1 / np.sqrt(3.0)
    vol = np.zeros(len(P))
    for r in (-g, g):
        for s in (-g, g):
            for t in (-g, g):
                dN = np.stack([xi[:, 0] * (1 + xi[:, 1] * s) * (1 + xi[:, 2] * t),
                               xi[:, 1] * (1 + xi[:, 0] * r) * (1 + xi[:, 2] * t),
                               xi[:, 2] * (1 + xi[:, 0] * r) * (1 + xi[:, 1] * s)], axis=1) / 8
                J = np.einsum("nic,id->ncd", P, dN)
                vol += np.linalg.det(J)
    return vol


def mean_ratio(P):
    """Knupp's corner mean ratio 3 det^(2/3) / |A|_F^2, averaged over the 8 corners (0 where
    det <= 0, capped at 1), on the raw corners; plus the rounding slack of corners whose
    determinant is within rounding of 0 (det^(2/3) turns eps into eps^(2/3))."""
    total, slack = np.zeros(len(P)), np.zeros(len(P))
    eps = np.finfo(float).eps
    for k, (a, b, c) in enumerate(CORNERS):
        A = np.stack([P[:, a] - P[:, k], P[:, b] - P[:, k], P[:, c] - P[:, k]], axis=2)
        det = np.linalg.det(A)
        frob = (A * A).sum(axis=(1, 2))
        with np.errstate(invalid="ignore", divide="ignore"):
            term = np.minimum(1.0, 3 * np.cbrt(det * det) / frob)
        total += np.where(det > 0, term, 0.0)
        noise = 64 * eps * np.prod(np.sqrt((A * A).sum(axis=1)), axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            slack += np.where(np.abs(det) <= noise, 3 * np.cbrt(noise * noise) / frob / 8, 0.0)
    return total / 8, np.nan_to_num(slack)


# ---- VTK and the CLI -----------------------------------------------------------------

def vtk_grid(points, hexes):
    grid = vtk.vtkUnstructuredGrid()
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float64), deep=True))
    grid.SetPoints(pts)
    cells = vtk.vtkCellArray()
    conn = np.hstack([np.full((len(hexes), 1), 8, np.int64), hexes.astype(np.int64)]).ravel()
    cells.SetCells(len(hexes), numpy_to_vtkIdTypeArray(conn, deep=True))
    grid.SetCells(vtk.VTK_HEXAHEDRON, cells)
    return grid


def vtk_quality(grid, metric):
    return hex_quality(grid, VTK_MEASURE[metric])


def cli_values(cli, mesh, metric, out_csv, n, extra=()):
    r = subprocess.run([cli, "quality", mesh, "--metric", metric, "--per-element", out_csv, *extra],
                       capture_output=True, text=True)
    if r.returncode != 0:
        check(False, f"{os.path.basename(mesh)} {metric}: isohex failed: {r.stdout}{r.stderr}")
        return None
    with open(out_csv) as f:
        header = f.readline().strip()
        check(header == "id,value", f"{out_csv}: header {header!r}")
        data = np.loadtxt(f, delimiter=",", ndmin=2)
    if data.shape != (n, 2) or not np.array_equal(data[:, 0], np.arange(n)):
        check(False, f"{os.path.basename(mesh)} {metric}: {data.shape[0]} rows / ids, expected {n}")
        return None
    return data[:, 1]


def compare(label, ours, ref, scale, skip=None, exact=None):
    """|ours - ref| <= 1e-12 * max(|ref|, floor) outside `skip`; both 1e30 where `exact`."""
    n = len(ref)
    skip = np.zeros(n, bool) if skip is None else skip
    exact = np.zeros(n, bool) if exact is None else exact
    check(np.all(ours[exact] >= DBL_MAX) and np.all(ref[exact] >= DBL_MAX),
          f"{label}: {np.count_nonzero(exact)} exactly degenerate hexes must be 1e30 in both")
    use = ~skip & ~exact
    deg_o, deg_r = np.abs(ours) >= DBL_MAX, np.abs(ref) >= DBL_MAX
    both_deg = use & deg_o & deg_r
    check(np.all(ours[both_deg] == ref[both_deg]), f"{label}: degenerate markers differ in sign")
    one_deg = use & (deg_o != deg_r)
    check(not one_deg.any(), f"{label}: {np.count_nonzero(one_deg)} hexes degenerate in only one "
          f"(first {np.flatnonzero(one_deg)[:5]})")
    val = use & ~deg_o & ~deg_r
    tol = REL * np.maximum(np.abs(ref[val]), scale[val])
    err = np.abs(ours[val] - ref[val])
    bad = err > tol
    worst = (err / np.maximum(np.abs(ref[val]), scale[val])).max(initial=0.0)
    check(not bad.any(), f"{label}: {np.count_nonzero(bad)} of {np.count_nonzero(val)} differ by more than "
          f"1e-12 (first {np.flatnonzero(val)[bad][:5]}, worst {worst:.2e})")
    print(f"  {label:44s} compared {np.count_nonzero(val):7d}  worst rel {worst:.1e}  "
          f"gap-skipped {np.count_nonzero(skip & ~exact):4d}  exact-degenerate {np.count_nonzero(exact):5d}")


def check_mesh(cli, label, mesh_file, P, tmp, extra=(), affine=None):
    """All metrics of one mesh (P: its hexes' corners, in the file's hex order)."""
    n = len(P)
    L = size_of(P)
    centred = P - (P.sum(axis=1) / 8)[:, None, :]
    grid = vtk_grid(centred.reshape(-1, 3), np.arange(8 * n).reshape(-1, 8))
    for metric in ["scaled_jacobian", "jacobian", "edge_ratio", "shape", "skew", "taper", "volume", "mean_ratio"]:
        ours = cli_values(cli, mesh_file, metric, os.path.join(tmp, f"{label}-{metric}.csv"), n, extra)
        if ours is None:
            continue
        floor = np.maximum(1e-2 * L ** 3, 1e-300) if metric in DIMENSIONAL else np.full(n, 1e-2)
        if metric == "mean_ratio":
            ref, slack = mean_ratio(P)
            err = np.abs(ours - ref)
            bad = (err > REL * np.maximum(ref, 1e-2) + slack) & ~gap_and_exact(P, "shape")[0]
            check(not bad.any(), f"{label} mean_ratio: {np.count_nonzero(bad)} differ from numpy "
                  f"(first {np.flatnonzero(bad)[:5]})")
            print(f"  {label + ' mean_ratio vs numpy':44s} compared {n:7d}")
            continue
        if metric == "volume":
            compare(f"{label} volume vs numpy trilinear", ours, trilinear_volume(P), floor)  # no thresholds
            if affine is not None and affine.any():
                v = vtk_quality(grid, metric)
                compare(f"{label} volume vs VTK (parallelepipeds)", ours[affine], v[affine], floor[affine])
            continue
        gap, exact = gap_and_exact(P, metric)
        ref = vtk_quality(grid, metric)
        compare(f"{label} {metric} vs VTK", ours, ref, floor, gap, exact)
        if metric in ("scaled_jacobian", "edge_ratio") and gap.any():
            # Inside the gap Verdict 1.4.4+ (and isohex) calls the element degenerate, VTK 9.1 does not.
            check(np.all(ours[gap] >= DBL_MAX), f"{label} {metric}: gap elements must be 1e30 in isohex")
            check(np.all(np.abs(ref[gap]) < DBL_MAX), f"{label} {metric}: gap elements are finite in VTK 9.1")


# ---- inputs --------------------------------------------------------------------------

def random_hexes(n, rng):
    """n hexes with their own 8 points each; returns (corners n x 8 x 3, parallelepiped mask)."""
    cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    kind = np.arange(n) % 8
    P = np.repeat(cube[None], n, axis=0)
    amp = np.choose(kind, [0.05, 0.3, 0.6, 0.15, 0.15, 0.0, 0.1, 0.1])
    P += amp[:, None, None] * rng.uniform(-1, 1, P.shape)
    inverted = kind == 3
    P[inverted, 6] = [0.3, 0.3, 0.3] + 0.05 * rng.uniform(-1, 1, (np.count_nonzero(inverted), 3))
    flat = kind == 4
    P[flat, :, 2] *= 10.0 ** rng.uniform(-6, -3, (np.count_nonzero(flat), 1))
    # Every 50th well-shaped hex gets an edge of 1e-8 times its size: degenerate for Verdict
    # 1.4.4+ (squared length below 2.2e-15 of the squared diagonal), not for VTK 9.1's 1e-30.
    short = (kind == 0) & (np.arange(n) % 400 == 0)
    d = rng.normal(size=(np.count_nonzero(short), 3))
    P[short, 1] = P[short, 0] + 1e-8 * d / np.linalg.norm(d, axis=1)[:, None]
    affine = kind == 5
    A = np.eye(3)[None] + 0.4 * rng.uniform(-1, 1, (n, 3, 3))
    P[affine] = np.einsum("nij,nkj->nki", A[affine], P[affine])
    collapsed = kind == 6  # one edge collapsed (its second node onto its first)
    for h in np.flatnonzero(collapsed):
        i, j = EDGES[h % 12]
        P[h, j] = P[h, i]
    point = kind == 7
    P[point & (np.arange(n) % 64 == 7)] = 0.25  # a few with all 8 nodes at one point
    face = point & (np.arange(n) % 64 != 7)     # the rest: the top face collapsed onto one node
    P[face, 4:8] = P[face, 4][:, None, :]
    scale = 10.0 ** rng.uniform(-3, 3, n)
    offset = rng.uniform(-1, 1, (n, 3)) * scale[:, None]
    P = P * scale[:, None, None] + offset[:, None, :]
    return P, affine


def read_medit(path):
    with open(path) as f:
        tok = f.read().split()
    i, pts, hexes = 0, None, None
    while i < len(tok):
        key = tok[i]
        if key == "Vertices":
            m = int(tok[i + 1])
            pts = np.array(tok[i + 2:i + 2 + 4 * m], float).reshape(m, 4)[:, :3]
            i += 2 + 4 * m
        elif key == "Hexahedra":
            m = int(tok[i + 1])
            hexes = np.array(tok[i + 2:i + 2 + 9 * m], np.int64).reshape(m, 9)[:, :8] - 1
            i += 2 + 9 * m
        elif key in ("Quadrilaterals", "Triangles", "Edges", "Tetrahedra"):
            m, per = int(tok[i + 1]), {"Quadrilaterals": 5, "Triangles": 4, "Edges": 3, "Tetrahedra": 5}[key]
            i += 2 + per * m
        else:
            i += 1
    return pts, hexes


def read_abaqus(path):
    nodes, elems, mode = {}, [], None
    with open(path) as f:
        for line in f:
            s = line.strip()
            if not s or s.startswith("**"):
                continue
            if s.startswith("*"):
                kw = s.split(",")[0].strip().upper()
                mode = "node" if kw == "*NODE" else "elem" if kw == "*ELEMENT" else None
                continue
            v = [x for x in s.split(",") if x.strip()]
            if mode == "node":
                nodes[int(v[0])] = [float(x) for x in v[1:4]]
            elif mode == "elem":
                elems.append([int(x) for x in v[1:9]])
    ids = sorted(nodes)
    index = {k: i for i, k in enumerate(ids)}
    return np.array([nodes[k] for k in ids]), np.array([[index[k] for k in e] for e in elems], np.int64)


def read_with_vtk(path):
    """Points (as read: float32 or float64), hex connectivity (type-12 cells only, in file
    order) and the number of other cells, as VTK reads them."""
    r = vtk.vtkXMLUnstructuredGridReader() if path.endswith(".vtu") else vtk.vtkUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    pts = vtk_to_numpy(g.GetPoints().GetData())
    hexes = []
    for c in range(g.GetNumberOfCells()):
        if g.GetCellType(c) == vtk.VTK_HEXAHEDRON:
            ids = g.GetCell(c).GetPointIds()
            hexes.append([ids.GetId(i) for i in range(8)])
    return pts, np.array(hexes, np.int64), g.GetNumberOfCells() - len(hexes)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--data", required=True)
    ap.add_argument("--tmp", required=True)
    a = ap.parse_args()
    os.makedirs(a.tmp, exist_ok=True)

    print("random hexes:")
    P, affine = random_hexes(120_000, np.random.default_rng(2024))
    grid = vtk_grid(P.reshape(-1, 3), np.arange(len(P) * 8).reshape(-1, 8))
    path = os.path.join(a.tmp, "random_hexes.vtu")
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(path)
    w.SetInputData(grid)
    w.SetDataModeToAppended()
    check(w.Write() == 1, "VTK could not write random_hexes.vtu")
    check_mesh(a.cli, "random", path, P, a.tmp, affine=affine)

    meshes = []
    for d in ("hexmeshes", os.path.join("hexmeshes", "mesquite")):
        folder = os.path.join(a.data, d)
        if os.path.isdir(folder):
            meshes += [os.path.join(folder, f) for f in sorted(os.listdir(folder))
                       if os.path.splitext(f)[1] in (".vtu", ".vtk", ".mesh", ".inp")]
    if not meshes:
        print("no shared meshes found under", a.data, "(skipped)")
    for path in meshes:
        name = os.path.basename(path)
        print(name + ":")
        extra = ()
        if path.endswith(".mesh"):
            pts, hexes = read_medit(path)
        elif path.endswith(".inp"):
            pts, hexes = read_abaqus(path)
        else:
            pts, hexes, others = read_with_vtk(path)
            if others:
                extra = ("--skip-non-hex",)
            if pts.dtype != np.float64:
                converted = os.path.join(a.tmp, os.path.splitext(name)[0] + "-converted.vtu")
                r = subprocess.run([a.cli, "convert", path, converted, *extra], capture_output=True, text=True)
                check(r.returncode == 0, f"{name}: isohex convert failed: {r.stdout}{r.stderr}")
                pts, hexes, _ = read_with_vtk(converted)
                print(f"  (VTK reads float32 points here; using isohex's doubles via {os.path.basename(converted)})")
        check(len(hexes) > 0, f"{name}: no hexes read")
        check_mesh(a.cli, os.path.splitext(name)[0], path, pts.astype(np.float64)[hexes], a.tmp, extra)

    print(f"{len(FAILURES)} failed" if FAILURES else "all quality checks passed")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
