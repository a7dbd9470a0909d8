#!/usr/bin/python3
"""Oracle test: isohex's certified validity of hexes against Gmsh's Plugin(AnalyseMeshQuality).

For every hex, `isohex quality --metric jacobian_ratio --metric gauss_jacobian --per-element`
must give the same verdict as Gmsh (Debian's `gmsh` 4.8.4) on whether det J > 0 everywhere in
the element, and the same min det J / max det J to within the two programs' tolerances.

What Gmsh computes (Plugin/AnalyseMeshQuality.cpp and Mesh/qualityMeasuresJacobian.cpp at tag
gmsh_4_8_4, and checked here on single elements): jacobianBasedQuality::
minMaxJacobianDeterminant() takes the Bezier coefficients of det J (degree 2 in each
direction for a trilinear hex, the 27 coefficients isohex uses too) and subdivides adaptively
until, with minL / maxL the smallest / largest det J at the corners of all sub-boxes (values
det J takes) and tol = 1e-3 * max(|minL|, |maxL|): the sign is decided (minL <= 0 or the
smallest coefficient minB > 0, and likewise for the max), and minL - minB < tol and
maxB - maxL < tol (it stops silently after 999 subdivisions: its "Max subdivision" message
tests k == 1000, which the loop never reaches; an element left unconverged would show up
here as a disagreement, not be hidden). It returns
minJ = min over sub-boxes of minB and maxJ = max of maxB: certified bounds, minJ below the
true minimum and maxJ above the true maximum, each within 1e-3 * max|det J| of it — the same
kind of numbers as isohex's min_lower / max_upper (isohex: gap <= 1e-3 * max |det J| sampled,
at most 512 subdivisions). Gmsh's reference hex is [-1,1]^3, so its det J is 1/8 of isohex's;
the ratio does not depend on it. The plugin's view ("minJ/maxJ 3D", CreateView = 1) holds per
element q = minJ/maxJ if maxJ > 0, maxJ/minJ if maxJ < 0 (an element negative everywhere gets
a POSITIVE q, 1 for a mirrored cube), 0 if maxJ = 0; it is not clamped (q < -1 happens).
The view has no minJ, so the sign of the elements with q > 0 (det J has one sign throughout
them) comes from Gmsh's mesh statistics export: SIGE (det J over the edge lengths, sampled at
the 8 corners) and SICN (inverse condition number, sampled), both negative exactly when det J
is negative there. (Not Disto: that is the smallest Bezier coefficient of the scaled
Jacobian, without subdivision, and is negative for many valid hexes.)

How the numbers are obtained: a .geo script merges the .msh (MSH 4.1 as isohex writes it),
runs the plugin with JacobianDeterminant = 1, CreateView = 1, DimensionOfElements = 3, saves
View[0] as .pos (8 corner coordinates and q with 16 digits per hex, in Gmsh's element order)
and the mesh as .pos with Print.PostElement, PostSICN and PostSIGE (tag, SICN, SIGE).
The view's hexes are matched to isohex's hex order by their 8 corners (to 1e-12; by
centroids if the order differed), the statistics' by element tag, checked against corners.

Per element, with r = isohex's jacobian_ratio, g = gauss_jacobian, q as above:
* verdict: r > 0 iff Gmsh says valid (q > 0 and SIGE > 0). Allowed difference, counted and
  reported: isohex not certified (r <= 0) while 0 < q <= 1e-3. Reason: isohex stops once
  min det J is known to 1e-3 * max|det J| without insisting on its sign, so a valid element
  whose true minimum is below that is left "not certified"; then Gmsh's minJ <= true minimum
  <= 1e-3 * max|det J| <= 1e-3 * maxJ. Gmsh certified-invalid and isohex certified-valid can
  never both be right: no tolerance for that.
* elements negative everywhere (Gmsh: q > 0, SIGE < 0): r == -1.
* otherwise |r - clamp(q, -1, 1)| <= 2e-3: both minima lie in [m - t, m] and both maxima in
  [M, M + t] (m, M the true extremes, t = 1e-3 max|det J|), so the two ratios differ by at most
  t (|m| + M + t) / (M (M + t)) < 2e-3 (and < 1e-3 once clamped at -1).
* numpy, independently: g equals det J at the 2x2x2 Gauss points; g <= 0 implies r <= 0 and
  Gmsh not valid; det J sampled on a 9x9x9 lattice: a negative sample implies both not valid,
  all samples negative implies both "negative everywhere", and for valid elements r and q are
  at most the sampled min/max (both are certified lower bounds of the true ratio).
Meshes: jittered boxes (jitter 0.3-0.45, 3000 hexes, over 10 % not valid inside), hand-made
hexes (cube, parallelepiped, mirrored cube, the bow tie whose corners and centre are positive
but det J < 0 inside, the path from the cube to the bow tie, flat and collapsed hexes, tapered
ones with min det J down to 1e-4 of the max, a twisted one, two hexes folded inside an edge
(all 27 lattice values positive) scaled to min/max = +-1e-3 ... +-1e-6, which need subdivision
in both programs and land in the tolerance band above, randomly perturbed cubes), a ball, and
third-party meshes from ../shared/data/hexmeshes (skipped if absent). `isohex check` must
exit 1 and name hex 1 for a mesh whose hex 1 is the bow tie, exit 1 with the same hexes as
the per-element ratios on a jittered box, and exit 0 on a clean box. Exits non-zero on any
failure; without gmsh only the checks that do not need it run.
"""
import json
import os
import re
import shutil
import subprocess
import sys
import time

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk

from oracle_support import check, finish, oracle_args

BAND = 0.0    # |Gmsh minJ/maxJ| below which isohex may leave a valid element not certified (none: both refine until the sign is decided)
RTOL = 2e-3   # |isohex ratio - Gmsh ratio|, from the two 1e-3 tolerances (see above)
TOTAL = {"compared": 0, "agree": 0, "band": 0, "inverted": 0, "invalid": 0, "maxdiff": 0.0}


def run(cmd, timeout=300):
    # The CLI may be relinked by a build running beside the tests: wait for it a little.
    for _ in range(30):
        if os.path.exists(cmd[0]):
            break
        time.sleep(1)
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=timeout)
    return p.returncode, p.stdout


# ---- meshes --------------------------------------------------------------------------------

def read_msh41(path):
    """Points, hexes (0-based point indices, VTK = Gmsh node order) and hex tags of an ASCII
    MSH 4.1 file as isohex writes it."""
    lines = open(path).read().split("\n")
    i = lines.index("$Nodes") + 1
    nblocks = int(lines[i].split()[0])
    i += 1
    tags, coords = [], []
    for _ in range(nblocks):
        _, _, parametric, n = (int(x) for x in lines[i].split())
        check(parametric == 0, f"{path}: parametric nodes")
        tags += [int(lines[i + 1 + k]) for k in range(n)]
        coords += [[float(x) for x in lines[i + 1 + n + k].split()[:3]] for k in range(n)]
        i += 1 + 2 * n
    index = {t: k for k, t in enumerate(tags)}
    i = lines.index("$Elements") + 1
    nblocks = int(lines[i].split()[0])
    i += 1
    hexes, htags = [], []
    for _ in range(nblocks):
        _, _, etype, n = (int(x) for x in lines[i].split())
        for k in range(n):
            f = [int(x) for x in lines[i + 1 + k].split()]
            if etype == 5:
                htags.append(f[0])
                hexes.append([index[v] for v in f[1:9]])
        i += 1 + n
    return np.array(coords, np.float64), np.array(hexes, np.int64), np.array(htags, np.int64)


def write_hexes(P, path_vtu):
    """Disjoint hexes P (n x 8 x 3, VTK order), written by VTK."""
    grid = vtk.vtkUnstructuredGrid()
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(P.reshape(-1, 3).copy(), deep=True))
    grid.SetPoints(pts)
    grid.Allocate(len(P))
    for h in range(len(P)):
        grid.InsertNextCell(vtk.VTK_HEXAHEDRON, 8, list(range(8 * h, 8 * h + 8)))
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(path_vtu)
    w.SetInputData(grid)
    check(w.Write() == 1, f"VTK writes {path_vtu}")


CUBE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], np.float64)
BOW3, BOW7 = np.array([0.31, 0.177, 0.416]), np.array([0.945, 0.808, -0.639])


def bow_tie(t=1.0):
    """The unit cube with corners 3 and 7 moved the fraction t of the way to the bow tie."""
    p = CUBE.copy()
    p[3] += t * (BOW3 - CUBE[3])
    p[7] += t * (BOW7 - CUBE[7])
    return p


NEAR_ZERO = [np.array(p) for p in (
    [[0.37, -0.28, 0.44], [0.6, 0.29, 0.31], [1.28, 1.25, 0.26], [0.34, 0.6, -0.09], [-0.14, -0.14, 0.6],
     [0.87, -0.18, 0.64], [0.94, 1.12, 1.3], [0.17, 0.9, 0.98]],
    [[-0.33, -0.1, 0.4], [0.84, -0.43, 0.22], [0.84, 0.66, -0.17], [-0.18, 1.16, -0.2], [0.1, -0.28, 0.59],
     [0.86, 0.31, 1.32], [1.04, 0.94, 0.83], [-0.38, 0.59, 0.75]])]


def min_max(p):
    """min det J (located on a 17^3 lattice, then refined by shrinking 7^3 lattices around it:
    a value det J takes, within ~1e-12 of the true minimum) and the largest sample of the hex."""
    L = lattice(17)
    d = det_j(p[None], *L)[0]
    x = np.array(L)[:, d.argmin()]
    best, h, t = d.min(), 1 / 16, np.linspace(-1, 1, 7)
    for _ in range(16):
        U, V, W = np.meshgrid(*(np.clip(x[a] + h * t, 0, 1) for a in range(3)), indexing="ij")
        e = det_j(p[None], U.ravel(), V.ravel(), W.ravel())[0]
        j = e.argmin()
        x, best, h = np.array([U.ravel()[j], V.ravel()[j], W.ravel()[j]]), min(best, e[j]), h / 2.5
    return best, d.max()


def hand_made():
    """(name, hex) pairs: each kind of element the verdict can meet."""
    out = [("cube", CUBE), ("bow tie", bow_tie())]
    A = np.array([[1.2, 0.3, -0.2], [-0.1, 0.8, 0.4], [0.25, -0.3, 1.1]])
    out.append(("parallelepiped", CUBE @ A.T + [0.5, -2, 7]))
    out.append(("mirrored cube", CUBE * [-1, 1, 1]))
    out.append(("mirrored bow tie", bow_tie() * [1, 1, -1]))
    out += [(f"cube to bow tie t={t:.3f}", bow_tie(t)) for t in np.linspace(0, 1, 41)[1:-1]]
    flat = CUBE.copy()
    flat[4:, 2] = 0
    out.append(("flat", flat))
    collapsed = CUBE.copy()
    collapsed[5] = collapsed[4]  # edge 4-5 collapsed: det J = 0 along it
    out.append(("collapsed edge", collapsed))
    for h in (1e-1, 1e-2, 1e-3, 1e-4, 0.0, -1e-4, -1e-2):
        tapered = CUBE.copy()
        tapered[6, 2] = tapered[7, 2] = h  # top face sloping down to height h: det J = h at y = 1
        out.append((f"tapered to {h:g}", tapered))
    twisted = CUBE.copy()
    c, s = np.cos(np.radians(100)), np.sin(np.radians(100))
    twisted[4:, :2] = (CUBE[4:, :2] - 0.5) @ np.array([[c, s], [-s, c]]) + 0.5  # top face turned 100 degrees
    out.append(("top face twisted 100 deg", twisted))
    # Along the path from the cube to the bow tie, det J first reaches 0 at corner 7 (a
    # Bernstein coefficient that is a value): hexes just before and after that t (bisection on
    # a 41^3 lattice of det J) have min det J within a hair of 0, decided exactly by both.
    lo, hi = 0.0, 1.0
    L = lattice(41)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if det_j(bow_tie(mid)[None], *L).min() <= 0 else (mid, hi)
    for dt in (-1e-2, -1e-3, -1e-4, -1e-5, -1e-6, 0, 1e-6, 1e-5, 1e-4, 1e-3):
        out.append((f"bow tie threshold {dt:+g}", bow_tie(hi + dt)))
    # Two perturbed cubes whose det J is positive on the 3x3x3 lattice (the Bernstein
    # coefficients' own points) but negative inside an edge; scaled back towards the cube
    # (p = cube + s (p1 - cube)) until min det J / max det J is +-1e-3 ... +-1e-6: undecidable
    # from the 27 coefficients alone, these need subdivision in both programs.
    for k, p1 in enumerate(NEAR_ZERO):
        for level in (1e-3, 1e-4, 1e-5, 1e-6, -1e-6, -1e-5, -1e-4, -1e-3):
            lo, hi = 0.0, 1.0
            for _ in range(44):
                mid = 0.5 * (lo + hi)
                m, M = min_max(CUBE + mid * (p1 - CUBE))
                lo, hi = (lo, mid) if m / M <= level else (mid, hi)
            out.append((f"edge fold {k} at min/max {level:+g}", CUBE + (lo if level > 0 else hi) * (p1 - CUBE)))
    rng = np.random.default_rng(11)
    for k in range(400):
        out.append((f"random cube {k}", CUBE + rng.uniform(-0.4, 0.4, (8, 3))))
    return out


# ---- det J in numpy ------------------------------------------------------------------------

def det_j(P, u, v, w):
    """det J of the trilinear hexes P (n x 8 x 3) at parameters (u, v, w) in [0,1]^3 (arrays of
    length k): n x k, in isohex's units (the unit cube has 1)."""
    Q = P - P[:, :1, :]
    p = [Q[:, i, None, :] for i in range(8)]
    u, v, w = (np.asarray(a, np.float64)[None, :, None] for a in (u, v, w))
    xu = (1 - v) * (1 - w) * (p[1] - p[0]) + v * (1 - w) * (p[2] - p[3]) + (1 - v) * w * (p[5] - p[4]) + v * w * (p[6] - p[7])
    xv = (1 - u) * (1 - w) * (p[3] - p[0]) + u * (1 - w) * (p[2] - p[1]) + (1 - u) * w * (p[7] - p[4]) + u * w * (p[6] - p[5])
    xw = (1 - u) * (1 - v) * (p[4] - p[0]) + u * (1 - v) * (p[5] - p[1]) + u * v * (p[6] - p[2]) + (1 - u) * v * (p[7] - p[3])
    return np.einsum("nkc,nkc->nk", xu, np.cross(xv, xw))


def lattice(n):
    t = np.linspace(0, 1, n)
    u, v, w = np.meshgrid(t, t, t, indexing="ij")
    return u.ravel(), v.ravel(), w.ravel()


G = (1 - 1 / np.sqrt(3)) / 2
GAUSS = tuple(np.array([[G, 1 - G][(c >> a) & 1] for c in range(8)]) for a in range(3))


def sampled(P, n=9, chunk=2000):
    """Smallest and largest det J on an n x n x n lattice, and the smallest at the Gauss points."""
    lo, hi, gauss = [], [], []
    L = lattice(n)
    for s in range(0, len(P), chunk):
        d = det_j(P[s:s + chunk], *L)
        lo.append(d.min(axis=1))
        hi.append(d.max(axis=1))
        gauss.append(det_j(P[s:s + chunk], *GAUSS).min(axis=1))
    return np.concatenate(lo), np.concatenate(hi), np.concatenate(gauss)


# ---- isohex and gmsh -------------------------------------------------------------------------

def isohex_values(cli, msh, tmp):
    """isohex's jacobian_ratio and gauss_jacobian per hex, and the --json validity summary."""
    stem = os.path.join(tmp, os.path.basename(msh))
    csv, js = stem + ".iso.csv", stem + ".iso.json"
    rc, out = run([cli, "quality", msh, "--metric", "jacobian_ratio", "--metric", "gauss_jacobian",
                   "--per-element", csv, "--json", js])
    if not check(rc == 0 and os.path.exists(csv), f"isohex quality {msh}: exit {rc}: {out[-800:]}"):
        return None
    with open(csv) as f:
        header = f.readline().strip()
        data = np.loadtxt(f, delimiter=",", ndmin=2)
    check(header == "id,jacobian_ratio,gauss_jacobian", f"{msh}: CSV header {header!r}")
    check(data.shape[1] == 3 and np.array_equal(data[:, 0], np.arange(len(data))), f"{msh}: CSV ids")
    validity = json.load(open(js)).get("validity", {})
    return data[:, 1], data[:, 2], validity


POS_HEX = re.compile(r"^SH\(([^)]*)\)\{([^}]*)\};", re.M)


def parse_pos_hexes(path):
    """(corners n x 8 x 3, values n x k) of the SH elements of a .pos file."""
    corners, values = [], []
    for m in POS_HEX.finditer(open(path).read()):
        corners.append([float(x) for x in m.group(1).split(",")])
        values.append([float(x) for x in m.group(2).split(",")])
    return np.array(corners).reshape(-1, 8, 3), np.array(values)


def gmsh_values(gmsh, msh, tmp):
    """Gmsh's per-element q (view "minJ/maxJ 3D") and SICN, SIGE (mesh statistics), in Gmsh's
    orders, with the corners of each: (view corners, q, stats corners, tags, sicn, sige, log)."""
    stem = os.path.join(tmp, os.path.basename(msh))
    view, stats, geo = stem + ".view.pos", stem + ".stats.pos", stem + ".geo"
    with open(geo, "w") as f:
        f.write(f'Merge "{os.path.abspath(msh)}";\n'
                "Plugin(AnalyseMeshQuality).JacobianDeterminant = 1;\n"
                "Plugin(AnalyseMeshQuality).IGEMeasure = 0;\n"
                "Plugin(AnalyseMeshQuality).ICNMeasure = 0;\n"
                "Plugin(AnalyseMeshQuality).CreateView = 1;\n"
                "Plugin(AnalyseMeshQuality).Recompute = 1;\n"
                "Plugin(AnalyseMeshQuality).DimensionOfElements = 3;\n"
                "Plugin(AnalyseMeshQuality).Run;\n"
                f'Save View[0] "{view}";\n'
                "Print.PostElementary = 0; Print.PostElement = 1; Print.PostSICN = 1;\n"
                "Print.PostSIGE = 1; Print.PostGamma = 0; Print.PostEta = 0; Print.PostDisto = 0;\n"
                f'Save "{stats}";\n')
    rc, out = run([gmsh, geo, "-parse_and_exit"])
    if not check(rc == 0 and os.path.exists(view) and os.path.exists(stats), f"gmsh on {msh}: exit {rc}: {out[-800:]}"):
        return None
    vc, vq = parse_pos_hexes(view)
    sc, sv = parse_pos_hexes(stats)
    ok = vq.shape[1:] == (8,) and np.all(vq == vq[:, :1]) and sv.shape[1:] == (24,)
    if not check(ok, f"gmsh {msh}: unexpected .pos layout {vq.shape} {sv.shape}"):
        return None
    return vc, vq[:, 0], sc, sv[:, 0].astype(np.int64), sv[:, 8], sv[:, 16], out


def match_order(corners, P):
    """For each Gmsh element (corners k x 8 x 3), the index of the isohex hex with the same 8
    corners in the same order, or None."""
    scale = max(1.0, float(np.abs(P).max()))
    if corners.shape == P.shape and np.abs(corners - P).max() <= 1e-12 * scale:
        return np.arange(len(P))
    print("  (Gmsh lists the hexes in another order: matching them by centroids)")
    c_iso, c_gmsh = P.mean(axis=1), corners.mean(axis=1)
    idx = np.empty(len(corners), np.int64)
    for s in range(0, len(corners), 500):
        d = ((c_gmsh[s:s + 500, None, :] - c_iso[None, :, :]) ** 2).sum(axis=2)
        idx[s:s + 500] = d.argmin(axis=1)
    if len(set(idx.tolist())) != len(P) or np.abs(corners - P[idx]).max() > 1e-12 * scale:
        return None
    return idx


def fmt_hex(p):
    return "[" + ", ".join("(" + ", ".join(f"{x:.17g}" for x in c) + ")" for c in p) + "]"


def compare_mesh(name, cli, gmsh, msh, tmp, names=None, min_invalid=0):
    """Compares isohex with Gmsh and numpy on every hex of the .msh; returns (r, g, q) (q None
    without Gmsh's values) or None."""
    pts, hexes, htags = read_msh41(msh)
    P = pts[hexes]
    n = len(P)
    got = isohex_values(cli, msh, tmp)
    if got is None:
        return None
    r, g, validity = got
    if not check(len(r) == n, f"{name}: isohex gives {len(r)} values for {n} hexes"):
        return None
    label = (lambda k: f"hex {k} ({names[k]})") if names else (lambda k: f"hex {k}")

    # The summary isohex prints agrees with its per-element values.
    check(validity.get("not_valid_inside") == int(np.sum(~(r > 0))) and
          validity.get("certified_valid") == int(np.sum(r > 0)) and
          validity.get("gauss_nonpositive") == int(np.sum(~(g > 0))) and
          abs(validity.get("jacobian_ratio_min", np.nan) - r.min()) <= 1e-15,
          f"{name}: --json validity {validity} vs per-element ratios")

    # numpy: Gauss points and a 9x9x9 lattice.
    s_lo, s_hi, s_gauss = sampled(P)
    scale = np.maximum(np.abs(s_lo), np.abs(s_hi))
    bad = np.flatnonzero(np.abs(g - s_gauss) > 1e-10 * scale + 1e-300)
    check(bad.size == 0, f"{name}: gauss_jacobian differs from numpy's det J at the Gauss points for "
          f"{bad.size} hexes, e.g. {label(bad[0]) if bad.size else ''}: {g[bad[:1]]} vs {s_gauss[bad[:1]]}")
    bad = np.flatnonzero(~(g > 0) & (r > 0))
    check(bad.size == 0, f"{name}: {bad.size} hexes with det J <= 0 at a Gauss point are certified valid, "
          f"e.g. {label(bad[0]) + ' ' + fmt_hex(P[bad[0]]) if bad.size else ''}")
    neg = s_lo < -1e-12 * scale
    bad = np.flatnonzero(neg & (r > 0))
    check(bad.size == 0, f"{name}: {bad.size} hexes with a negative det J sample are certified valid, e.g. "
          f"{label(bad[0]) + ' ' + fmt_hex(P[bad[0]]) if bad.size else ''}")
    allneg = s_hi < -1e-12 * scale
    bad = np.flatnonzero(allneg & (r != -1))
    check(bad.size == 0, f"{name}: {bad.size} hexes negative everywhere without ratio -1, e.g. "
          f"{label(bad[0]) + ' ratio ' + repr(r[bad[0]]) if bad.size else ''}")
    pos = r > 0
    bad = np.flatnonzero(pos & (r > s_lo / np.where(s_hi > 0, s_hi, 1) * (1 + 1e-12) + 1e-12))
    check(bad.size == 0, f"{name}: {bad.size} certified ratios above the sampled min/max (not a lower bound), "
          f"e.g. {label(bad[0]) + ' ' + repr(r[bad[0]]) + ' > ' + repr(s_lo[bad[0]] / s_hi[bad[0]]) if bad.size else ''}")
    n_invalid = int(np.sum(~pos))
    check(n_invalid >= min_invalid, f"{name}: only {n_invalid} hexes not valid inside (expected >= {min_invalid})")

    if gmsh is None:
        print(f"  {name}: {n} hexes, {n_invalid} not valid inside (isohex; gmsh skipped)")
        return r, g, None
    gv = gmsh_values(gmsh, msh, tmp)
    if gv is None:
        return r, g, None
    vc, vq, sc, stags, sicn, sige, log = gv
    check("Max subdivision" not in log and "Error" not in log, f"{name}: gmsh reports errors: "
          f"{[l for l in log.splitlines() if 'Error' in l or 'Max subdivision' in l][:3]}")
    order = match_order(vc, P)
    if not check(order is not None and len(vc) == n, f"{name}: Gmsh's {len(vc)} hexes are not isohex's {n} (corners)"):
        return r, g, None
    q = np.full(n, np.nan)
    q[order] = vq
    by_tag = {int(t): k for k, t in enumerate(htags)}
    sidx = np.array([by_tag.get(int(t), -1) for t in stags])
    ok = len(sidx) == n and np.all(sidx >= 0) and len(set(sidx.tolist())) == n
    ok = ok and np.all(np.abs(sc - P[np.maximum(sidx, 0)]) <= 1e-5 * np.maximum(1.0, np.abs(P).max()))
    if not check(ok, f"{name}: Gmsh's statistics elements (tags) are not isohex's hexes"):
        return r, g, None
    d, c = np.full(n, np.nan), np.full(n, np.nan)
    d[sidx], c[sidx] = sige, sicn

    # q > 0: det J has one sign throughout; SIGE (det J / edge lengths at the corners, sampled
    # values) and SICN (sampled too) say which.
    g_inverted = (q > 0) & (d < 0)        # negative everywhere (q = maxJ/minJ)
    g_valid = (q > 0) & (d > 0)
    bad = np.flatnonzero((q > 0) & ~((d > 0) & (c > 0) | (d < 0) & (c < 0)))
    check(bad.size == 0, f"{name}: {bad.size} hexes with Gmsh q > 0 where SIGE and SICN do not share a sign, "
          f"e.g. {bad[:3]}: {d[bad[:3]]}, {c[bad[:3]]}")
    i_valid = r > 0
    agree = g_valid == i_valid
    band = ~agree & ~i_valid & g_valid & (q <= BAND)
    wrong = np.flatnonzero(~agree & ~band)
    for k in wrong[:5]:
        print(f"  disagreement {name} {label(k)}: isohex ratio {r[k]!r}, gmsh q {q[k]!r} (SIGE {d[k]:g}), "
              f"sampled det J [{s_lo[k]:.6g}, {s_hi[k]:.6g}], corners {fmt_hex(P[k])}")
    check(wrong.size == 0, f"{name}: {wrong.size} hexes where isohex and Gmsh disagree on validity inside")
    for k in np.flatnonzero(band)[:3]:
        print(f"  within Gmsh's tolerance of 0: {name} {label(k)}: isohex {r[k]:.3g}, gmsh q {q[k]:.3g}")
    bad = np.flatnonzero(g_inverted & (r != -1))
    check(bad.size == 0, f"{name}: {bad.size} hexes Gmsh finds negative everywhere without isohex ratio -1, e.g. "
          f"{label(bad[0]) + ' ' + repr(r[bad[0]]) if bad.size else ''}")
    bad = np.flatnonzero((~(g > 0) | neg) & g_valid)
    check(bad.size == 0, f"{name}: {bad.size} hexes with det J <= 0 at a Gauss point or a negative sample "
          f"that Gmsh finds valid")
    bad = np.flatnonzero(allneg & ~g_inverted)
    check(bad.size == 0, f"{name}: {bad.size} hexes negative at every sample that Gmsh does not find negative everywhere")
    bad = np.flatnonzero(g_valid & (q > s_lo / np.where(s_hi > 0, s_hi, 1) * (1 + 1e-12) + 1e-12))
    check(bad.size == 0, f"{name}: {bad.size} Gmsh ratios above the sampled min/max")
    cmp_ = ~g_inverted
    diff = np.abs(r - np.clip(q, -1, 1))
    diff[~cmp_] = 0
    far = np.flatnonzero(diff > RTOL)
    for k in far[:5]:
        print(f"  ratio differs {name} {label(k)}: isohex {r[k]!r}, gmsh {q[k]!r}, corners {fmt_hex(P[k])}")
    check(far.size == 0, f"{name}: {far.size} hexes whose ratios differ by more than {RTOL} (max {diff.max():.3g})")
    k = int(diff.argmax())
    print(f"  {name}: {n} hexes compared, {int(agree.sum())} same verdict, {int(band.sum())} within {BAND} of 0, "
          f"{int((~i_valid).sum())} not valid inside ({int(g_inverted.sum())} negative everywhere, "
          f"{int((~(g > 0)).sum())} with det J <= 0 at a Gauss point), "
          f"max |ratio diff| {diff.max():.3g} ({label(k)}: isohex {r[k]:.6g}, gmsh {q[k]:.6g})")
    TOTAL["compared"] += n
    TOTAL["agree"] += int(agree.sum())
    TOTAL["band"] += int(band.sum())
    TOTAL["inverted"] += int(g_inverted.sum())
    TOTAL["invalid"] += int((~i_valid).sum())
    TOTAL["maxdiff"] = max(TOTAL["maxdiff"], float(diff.max()))
    return r, g, q


# ---- isohex check ---------------------------------------------------------------------------

def check_command(cli, msh, tmp, want_rc, want_hexes, name):
    js = os.path.join(tmp, os.path.basename(msh) + ".check.json")
    rc, out = run([cli, "check", msh, "--json", js])
    check(rc == want_rc, f"isohex check {name}: exit {rc}, expected {want_rc}: {out[-600:]}")
    if not check(os.path.exists(js), f"isohex check {name}: no --json"):
        return
    rep = json.load(open(js))
    listed = rep.get("not_valid_inside_hexes")
    print(f"  isohex check {name}: exit {rc}, {rep.get('not_valid_inside')} not valid inside, listed {listed}")
    check(rep.get("not_valid_inside") == len(want_hexes), f"isohex check {name}: not_valid_inside "
          f"{rep.get('not_valid_inside')}, per-element ratios give {len(want_hexes)}")
    check(isinstance(listed, list) and listed == list(want_hexes[:len(listed)]) and
          len(listed) >= min(len(want_hexes), 20), f"isohex check {name}: not_valid_inside_hexes {listed}")
    for h in want_hexes[:3]:
        check(re.search(rf"hex {h}: not valid inside", out) is not None, f"isohex check {name}: no 'hex {h}: not valid inside'")
    if not want_hexes:
        check(re.search(r"hex \d+: not valid inside", out) is None, f"isohex check {name} names hexes: {out[-400:]}")


def main():
    a = oracle_args(__doc__)
    gmsh = shutil.which("gmsh")
    if gmsh is None:
        print("SKIP (Gmsh comparisons only): the gmsh command is not installed (scripts/install-deps.sh installs it)")

    def generate(args, out):
        path = os.path.join(a.tmp, out)
        rc, msg = run([a.cli, "generate", *args, "-o", path])
        check(rc == 0, f"isohex generate {' '.join(args)}: {msg}")
        return path

    # (1) jittered boxes: a good fraction of the hexes fold inside.
    print("jittered boxes:")
    boxes = []
    for jitter, seed, min_invalid in (("0.3", "1", 5), ("0.4", "2", 100), ("0.45", "3", 180)):
        msh = generate(["box", "-n", "10", "--jitter", jitter, "--seed", seed], f"box_j{jitter}.msh")
        got = compare_mesh(f"box jitter {jitter}", a.cli, gmsh, msh, a.tmp, min_invalid=min_invalid)
        boxes.append((msh, got))

    # (2) hand-made hexes, disjoint, 3 apart along x.
    print("hand-made hexes:")
    made = hand_made()
    P = np.array([p + [3.0 * k, 0, 0] for k, (_, p) in enumerate(made)])
    vtu = os.path.join(a.tmp, "hand_made.vtu")
    write_hexes(P, vtu)
    msh = os.path.join(a.tmp, "hand_made.msh")
    rc, msg = run([a.cli, "convert", vtu, msh])
    if check(rc == 0, f"convert hand-made hexes: {msg}"):
        names = [nm for nm, _ in made]
        got = compare_mesh("hand-made", a.cli, gmsh, msh, a.tmp, names=names)
        if got is not None:
            r = dict(zip(names, got[0]))
            check(abs(r["cube"] - 1) <= 1e-12 and abs(r["parallelepiped"] - 1) <= 1e-12,
                  f"affine hexes: ratios {r['cube']!r}, {r['parallelepiped']!r} (expected 1)")
            check(r["bow tie"] < 0 and r["mirrored bow tie"] < 0, f"bow tie: ratio {r['bow tie']!r} (expected < 0)")
            check(r["mirrored cube"] == -1, f"mirrored cube: ratio {r['mirrored cube']!r} (expected -1)")
            check(r["flat"] == 0 and r["collapsed edge"] <= 0, f"flat {r['flat']!r}, collapsed {r['collapsed edge']!r}")
            check(r["tapered to 0.0001"] > 0, f"tapered to 1e-4 is valid: ratio {r['tapered to 0.0001']!r}")
            # The corners and the centre of the bow tie are positive: Verdict's nine samples pass it.
            c = det_j(bow_tie()[None], [0, 1, 1, 0, 0, 1, 1, 0, 0.5], [0, 0, 1, 1, 0, 0, 1, 1, 0.5],
                      [0, 0, 0, 0, 1, 1, 1, 1, 0.5])
            check(np.all(c > 0), f"bow tie: corner and centre det J {c} should all be positive")
            if got[2] is not None:
                q = dict(zip(names, got[2]))
                check(q["bow tie"] < 0, f"Gmsh's minJ/maxJ for the bow tie {q['bow tie']!r} (expected < 0)")

    # (3) a ball (a cube grid mapped onto a sphere: flattened hexes along the diagonals).
    print("ball:")
    compare_mesh("ball", a.cli, gmsh, generate(["ball", "-n", "10"], "ball.msh"), a.tmp)

    # (4) third-party meshes, some tangled.
    print("third-party meshes:")
    folder = os.path.join(a.data, "hexmeshes")
    picks = ["mesquite/hex_5_tangled.vtk", "mesquite/pave3.e.vtk", "rockarm.vtk", "ecr2015_block_in.mesh",
             "ecr2015_hanger_stresstest_in.mesh"]
    present = [p for p in picks if os.path.exists(os.path.join(folder, p))]
    if not present:
        print(f"  SKIP: no third-party meshes under {folder}")
    for p in present:
        msh = os.path.join(a.tmp, os.path.basename(p) + ".msh")
        rc, msg = run([a.cli, "convert", os.path.join(folder, p), msh])
        if check(rc == 0, f"convert {p}: {msg}"):
            compare_mesh(os.path.basename(p), a.cli, gmsh, msh, a.tmp)

    # isohex check: fails on an element not valid inside, naming it; passes a clean box.
    print("isohex check:")
    trio = os.path.join(a.tmp, "bow_tie_trio.vtu")
    write_hexes(np.array([CUBE, bow_tie() + [3, 0, 0], CUBE + [6, 0, 0]]), trio)
    trio_msh = os.path.join(a.tmp, "bow_tie_trio.msh")
    rc, msg = run([a.cli, "convert", trio, trio_msh])
    if check(rc == 0, f"convert bow tie trio: {msg}"):
        check_command(a.cli, trio_msh, a.tmp, 1, [1], "bow tie as hex 1")
    check_command(a.cli, generate(["box", "-n", "4"], "clean_box.msh"), a.tmp, 0, [], "clean box")
    msh, got = boxes[1]
    if got is not None:
        check_command(a.cli, msh, a.tmp, 1, np.flatnonzero(~(got[0] > 0)).tolist(), "box jitter 0.4")

    if gmsh is not None:
        t = TOTAL
        print(f"summary: {t['compared']} hexes compared with Gmsh, {t['agree']} with the same verdict, "
              f"{t['band']} within {BAND} of 0 (isohex not certified, Gmsh valid), {t['invalid']} not valid inside "
              f"({t['inverted']} negative everywhere), max |ratio difference| {t['maxdiff']:.3g} (tolerance {RTOL})")
    return finish()


if __name__ == "__main__":
    sys.exit(main())
