#!/usr/bin/python3
"""Oracle test: the solver formats isohex writes, read by the programs that consume them.

Two meshes with blocks (a ball from `isohex generate ball` split into blocks 3 and 8 with
some fixed vertices, and a jittered box whose blocks -7, 0, 993 need renumbering) are
written by VTK as .vtu and converted by `isohex convert` into every output format. Then:

* VTK's vtkExodusIIReader reads the .exo/.e/.ex2: element blocks (ids, names, members,
  connectivity in element id order), the side set "boundary" (VTK turns each (element,
  side) into a face with its own side tables: every face must be an outward boundary quad,
  and every boundary quad a face), the node set "boundary" and the node set "fixed".
* The gmsh command-line tool checks the .msh (ASCII and binary), re-saves it as MSH 2.2,
  whose physical groups, nodes, hexes and boundary quads are compared here; gmsh's Jacobian
  plugin must find every hex positive (and a mirrored copy negative, so the check can fail);
  gmsh's own MSH 4.1 output must read back through isohex.
* The Abaqus deck's ELSETs, NSET BOUNDARY and SURFACE BOUNDARY (face labels decoded with
  Abaqus' C3D8 face table) are checked against the boundary VTK's hexahedron faces give, and
  CalculiX (ccx, a solver for Abaqus decks) runs the deck and reports the surface's area,
  which must be the boundary's (and differs when the face labels are permuted).
* vtkXMLUnstructuredGridReader reads the .vtu; every format reads back through isohex
  into exactly the mesh it came from (the .inp: where 20 characters hold a coordinate).

The boundary reference comes from VTK's own hexahedron faces (vtkCell.GetFace), not from
isohex. Exits non-zero on any failure.
"""
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtk_support import read_vtu

from oracle_support import check, finish, oracle_args, parse_msh22


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return p.returncode, p.stdout


# ---- meshes and the VTK reference ----------------------------------------------------------

def write_vtu(grid, path):
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(path)
    w.SetInputData(grid)
    w.SetDataModeToBinary()
    check(w.Write() == 1, f"VTK writes {path}")


class Mesh:
    """Points, hex connectivity, block per hex and fixed flags of a VTK grid."""

    def __init__(self, grid):
        self.points = vtk_to_numpy(grid.GetPoints().GetData()).astype(np.float64)
        n = grid.GetNumberOfCells()
        self.cells = np.array([[grid.GetCell(c).GetPointId(k) for k in range(8)] for c in range(n)], dtype=np.int64)
        check(all(grid.GetCellType(c) == vtk.VTK_HEXAHEDRON for c in range(n)), "all cells are hexahedra")
        b = grid.GetCellData().GetArray("block")
        self.blocks = vtk_to_numpy(b).astype(np.int64) if b is not None else np.zeros(n, dtype=np.int64)
        f = grid.GetPointData().GetArray("fixed")
        self.fixed = vtk_to_numpy(f).astype(np.int64) if f is not None else np.zeros(len(self.points), dtype=np.int64)
        # Boundary: faces of VTK's vtkHexahedron used by one hex, in VTK's outward order.
        count, oriented = {}, {}
        for c in range(n):
            cell = grid.GetCell(c)
            for f_ in range(cell.GetNumberOfFaces()):
                ids = cell.GetFace(f_).GetPointIds()
                face = tuple(ids.GetId(k) for k in range(ids.GetNumberOfIds()))
                key = tuple(sorted(face))
                count[key] = count.get(key, 0) + 1
                oriented[key] = face
        self.boundary = {canonical(oriented[k]) for k, c in count.items() if c == 1}
        self.boundary_nodes = sorted({v for f_ in self.boundary for v in f_})


def canonical(face):
    """A quad as a tuple rotated to start at its smallest id: equal iff same quad, same orientation."""
    face = tuple(int(v) for v in face)
    i = face.index(min(face))
    return face[i:] + face[:i]


def ball_mesh(cli, tmp):
    """isohex's mapped ball, blocks 3 (x < 0) and 8 (x >= 0), vertices with z > 0.5 fixed."""
    src = os.path.join(tmp, "ball_plain.vtu")
    rc, out = run([cli, "generate", "ball", "-n", "5", "-o", src])
    check(rc == 0, f"generate ball: {out}")
    grid = read_vtu(src)
    pts = vtk_to_numpy(grid.GetPoints().GetData())
    blocks = []
    for c in range(grid.GetNumberOfCells()):
        ids = [grid.GetCell(c).GetPointId(k) for k in range(8)]
        blocks.append(3 if pts[ids].mean(axis=0)[0] < 0 else 8)
    arr = numpy_to_vtk(np.array(blocks, dtype=np.int32), deep=True, array_type=vtk.VTK_INT)
    arr.SetName("block")
    grid.GetCellData().AddArray(arr)
    fixed = numpy_to_vtk((pts[:, 2] > 0.5).astype(np.uint8), deep=True, array_type=vtk.VTK_UNSIGNED_CHAR)
    fixed.SetName("fixed")
    grid.GetPointData().AddArray(fixed)
    path = os.path.join(tmp, "ball.vtu")
    write_vtu(grid, path)
    return path


def box_grid(nx, ny, nz, mirrored=False):
    """A jittered box with blocks -7, 0, 993 and no fixed vertices; `mirrored` lists every
    hex with its two quads swapped (an inverted hex)."""
    rng = np.random.default_rng(3)
    vid = lambda i, j, k: i + (nx + 1) * (j + (ny + 1) * k)
    pts = np.array([[i, j, k] for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)], dtype=np.float64)
    pts = pts / 3.0 + rng.uniform(-0.04, 0.04, pts.shape)
    grid = vtk.vtkUnstructuredGrid()
    p = vtk.vtkPoints()
    p.SetData(numpy_to_vtk(pts, deep=True))
    grid.SetPoints(p)
    grid.Allocate(nx * ny * nz)
    blocks = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                c = [vid(i, j, k), vid(i + 1, j, k), vid(i + 1, j + 1, k), vid(i, j + 1, k),
                     vid(i, j, k + 1), vid(i + 1, j, k + 1), vid(i + 1, j + 1, k + 1), vid(i, j + 1, k + 1)]
                if mirrored:
                    c = c[4:] + c[:4]
                grid.InsertNextCell(vtk.VTK_HEXAHEDRON, 8, c)
                blocks.append([-7, 0, 993][i % 3])
    arr = numpy_to_vtk(np.array(blocks, dtype=np.int32), deep=True, array_type=vtk.VTK_INT)
    arr.SetName("block")
    grid.GetCellData().AddArray(arr)
    return grid


def same_bits(a, b):
    return a.shape == b.shape and np.array_equal(np.ascontiguousarray(a, dtype=np.float64).view(np.uint64),
                                                  np.ascontiguousarray(b, dtype=np.float64).view(np.uint64))


def same_in_20_characters(a, b):
    """Abaqus fields have 20 characters (CalculiX reads no more): a coordinate whose shortest
    exact spelling (Python's repr) fits must read back exactly, any other to 13 digits."""
    if a.shape != b.shape:
        return False
    fits = np.vectorize(lambda x: len(repr(float(x))) <= 20)(a)
    return same_bits(a[fits], b[fits]) and bool(np.all(np.abs(a - b) <= 5e-13 * np.abs(a)))


def compare_meshes(ref, got, what, keeps_fixed=True, in_20_characters=False):
    if in_20_characters:
        check(same_in_20_characters(ref.points, got.points), f"{what}: points exact where 20 characters hold them")
    else:
        check(same_bits(ref.points, got.points), f"{what}: points bit for bit")
    check(np.array_equal(ref.cells, got.cells), f"{what}: connectivity and hex order")
    check(np.array_equal(ref.blocks, got.blocks), f"{what}: blocks {sorted(set(got.blocks))}")
    if keeps_fixed:
        check(np.array_equal(ref.fixed, got.fixed), f"{what}: fixed flags")


# ---- Exodus II through VTK ----------------------------------------------------------------

def check_exodus(path, ref):
    E = vtk.vtkExodusIIReader
    r = E()
    r.SetFileName(path)
    r.UpdateInformation()
    for t in (E.ELEM_BLOCK, E.SIDE_SET, E.NODE_SET):
        for i in range(r.GetNumberOfObjects(t)):
            r.SetObjectStatus(t, i, 1)
    r.GenerateGlobalNodeIdArrayOn()
    r.GenerateGlobalElementIdArrayOn()
    r.Update()
    out = r.GetOutput()
    name = os.path.basename(path)
    values = sorted(set(int(b) for b in ref.blocks))
    ids = values if values[0] >= 1 else list(range(1, len(values) + 1))
    nblk = r.GetNumberOfObjects(E.ELEM_BLOCK)
    check([r.GetObjectId(E.ELEM_BLOCK, i) for i in range(nblk)] == ids, f"{name}: element block ids {ids}")
    check([r.GetObjectName(E.ELEM_BLOCK, i) for i in range(nblk)] == [f"block_{v}" for v in values],
          f"{name}: element block names")

    def grids(kind):
        group = out.GetBlock(kind)
        return [(group.GetMetaData(i).Get(vtk.vtkCompositeDataSet.NAME()), group.GetBlock(i))
                for i in range(group.GetNumberOfBlocks())]

    def node_ids(g):
        return vtk_to_numpy(g.GetPointData().GetArray("GlobalNodeId")).astype(np.int64) - 1

    seen = np.zeros(len(ref.cells), dtype=np.int64)
    for (bname, g), value in zip(grids(0), values):
        gid = node_ids(g)
        # vtkExodusIIReader hands out float coordinates: the doubles rounded must match.
        check(np.array_equal(vtk_to_numpy(g.GetPoints().GetData()), ref.points[gid].astype(np.float32)),
              f"{name}: {bname} coordinates")
        elem = vtk_to_numpy(g.GetCellData().GetArray("GlobalElementId")).astype(np.int64) - 1
        check(np.array_equal(ref.blocks[elem], np.full(len(elem), value)), f"{name}: {bname} holds block {value} hexes")
        check(int((ref.blocks == value).sum()) == g.GetNumberOfCells(), f"{name}: {bname} hex count")
        for c in range(g.GetNumberOfCells()):
            conn = [gid[g.GetCell(c).GetPointId(k)] for k in range(8)]
            if not check(conn == list(ref.cells[elem[c]]), f"{name}: element id {elem[c] + 1} connectivity"):
                break
            seen[elem[c]] += 1
    check(np.all(seen == 1), f"{name}: every hex once in the element blocks")

    side = grids(4)
    check([n for n, _ in side] == ["boundary"], f"{name}: side sets {[n for n, _ in side]}")
    if side:
        g = side[0][1]
        gid = node_ids(g)
        faces = [canonical(gid[g.GetCell(c).GetPointId(k)] for k in range(4)) for c in range(g.GetNumberOfCells())]
        check(len(faces) == len(ref.boundary), f"{name}: side set has {len(faces)} faces, boundary {len(ref.boundary)}")
        bad = [f for f in faces if f not in ref.boundary]
        check(not bad, f"{name}: side set faces that are no outward boundary quad: {bad[:3]}")
        check(set(faces) == ref.boundary, f"{name}: side set covers the boundary")

    nsets = dict(grids(7))
    want = ["boundary"] + (["fixed"] if ref.fixed.any() else [])
    check(sorted(nsets) == want, f"{name}: node sets {sorted(nsets)}")
    if "boundary" in nsets:
        check(sorted(node_ids(nsets["boundary"])) == ref.boundary_nodes, f"{name}: node set boundary")
    if "fixed" in nsets:
        check(sorted(node_ids(nsets["fixed"])) == list(np.flatnonzero(ref.fixed)), f"{name}: node set fixed")


# ---- Gmsh through the gmsh command-line tool ---------------------------------------------

def match_points(pts, ref_points):
    """For each row of `pts`, the index of the equal (to 1e-15 relative) row of `ref_points`;
    None unless that is a one-to-one correspondence."""
    if pts.shape != ref_points.shape:
        return None
    d = np.abs(pts[:, None, :] - ref_points[None, :, :]).max(axis=2)
    idx = d.argmin(axis=1)
    scale = np.maximum(1.0, np.abs(ref_points).max(axis=1))[idx]
    if not np.all(d[np.arange(len(pts)), idx] <= 1e-15 * scale) or len(set(idx.tolist())) != len(pts):
        return None
    return idx


def gmsh_min_jacobian(gmsh, path, tmp):
    """gmsh's smallest hex Jacobian determinant (AnalyseMeshQuality), or None."""
    geo = os.path.join(tmp, "jacobian.geo")
    with open(geo, "w") as f:
        f.write(f'Merge "{os.path.abspath(path)}";\n'
                "Plugin(AnalyseMeshQuality).JacobianDeterminant = 1;\n"
                "Plugin(AnalyseMeshQuality).CreateView = 0;\n"
                "Plugin(AnalyseMeshQuality).DimensionOfElements = 3;\n"
                "Plugin(AnalyseMeshQuality).Run;\n")
    rc, out = run([gmsh, geo, "-parse_and_exit"])
    m = re.search(r"minJ\s*=\s*([-+0-9.eE]+)", out)
    check(rc == 0 and m is not None, f"gmsh Jacobian plugin on {path}: {out[-500:]}")
    return float(m.group(1)) if m else None


def check_gmsh(gmsh, cli, path, ref, tmp):
    name = os.path.basename(path)
    rc, out = run([gmsh, path, "-check"])
    nquads = len(ref.boundary)
    check(rc == 0 and "Error" not in out, f"gmsh -check {name}: {out[-500:]}")
    check(f"{len(ref.points)} nodes" in out and f"{len(ref.cells) + nquads} elements" in out,
          f"gmsh -check {name} counts: {out[-400:]}")

    re22 = os.path.join(tmp, name + ".22.msh")
    rc, out = run([gmsh, path, "-save", "-format", "msh22", "-o", re22])
    if not check(rc == 0 and os.path.exists(re22), f"gmsh re-saves {name}: {out[-500:]}"):
        return
    names, nodes, elems = parse_msh22(re22)
    values = sorted(set(int(b) for b in ref.blocks))
    ids = values if values[0] >= 1 else list(range(1, len(values) + 1))
    want = {(3, i): f"block_{v}" for i, v in zip(ids, values)}
    want[(2, 1)] = "boundary"
    check(names == want, f"{name}: gmsh physical groups {names}")
    # gmsh renumbers nodes when it saves (and prints 16 digits): match them by position.
    tags = sorted(nodes)
    to_ref = match_points(np.array([nodes[t] for t in tags]), ref.points)
    if not check(to_ref is not None, f"{name}: gmsh's nodes are the mesh's points, one to one"):
        return
    node = dict(zip(tags, to_ref))
    hexes = sorted((phys, tuple(node[v] for v in vs)) for t, phys, vs in elems if t == 5)
    want_hexes = sorted((ids[values.index(int(b))], tuple(int(x) for x in c)) for c, b in zip(ref.cells, ref.blocks))
    check(hexes == want_hexes, f"{name}: gmsh hexes with their physical volumes")
    quads = [(phys, canonical(node[v] for v in vs)) for t, phys, vs in elems if t == 3]
    check(all(p == 1 for p, _ in quads) and len(quads) == nquads and {q for _, q in quads} == ref.boundary,
          f"{name}: gmsh physical surface 'boundary' is the outward boundary")
    check(len(elems) == len(ref.cells) + nquads, f"{name}: gmsh element count {len(elems)}")

    minj = gmsh_min_jacobian(gmsh, path, tmp)
    check(minj is not None and minj > 0, f"{name}: gmsh finds every hex positive (minJ {minj})")

    # gmsh's own MSH 4.1 output must read back through isohex's reader.
    re41 = os.path.join(tmp, name + ".41.msh")
    back = os.path.join(tmp, name + ".41.vtu")
    rc, out = run([gmsh, path, "-save", "-format", "msh41", "-o", re41])
    check(rc == 0, f"gmsh saves {name} as MSH 4.1: {out[-300:]}")
    rc, out = run([cli, "convert", re41, back])
    if check(rc == 0, f"isohex reads gmsh's MSH 4.1 of {name}: {out}"):
        got = Mesh(read_vtu(back))
        to_ref = match_points(got.points, ref.points)
        if check(to_ref is not None, f"{name}: isohex reads gmsh's 4.1 points"):
            cells = sorted((int(b), tuple(int(to_ref[v]) for v in c)) for c, b in zip(got.cells, got.blocks))
            want = sorted((int(b), tuple(int(x) for x in c)) for c, b in zip(ref.cells, ref.blocks))
            check(cells == want, f"{name}: isohex reads gmsh's 4.1 hexes with their blocks")


def check_gmsh_mirrored(gmsh, cli, tmp):
    """The Jacobian check must be able to fail: inverted hexes give a negative minJ."""
    src = os.path.join(tmp, "mirrored.vtu")
    write_vtu(box_grid(2, 2, 1, mirrored=True), src)
    msh = os.path.join(tmp, "mirrored.msh")
    rc, out = run([cli, "convert", src, msh])
    check(rc == 0, f"convert mirrored: {out}")
    minj = gmsh_min_jacobian(gmsh, msh, tmp)
    check(minj is not None and minj < 0, f"gmsh sees inverted hexes as negative (minJ {minj})")


# ---- Abaqus -----------------------------------------------------------------------------

# Abaqus C3D8 faces by label (1-based nodes), as its element library lists them: S1 1-2-3-4,
# S2 5-8-7-6, S3 1-5-6-2, S4 2-6-7-3, S5 3-7-8-4, S6 4-8-5-1. Each list runs counter-clockwise
# seen from inside the element, so reversed it is the outward quad.
ABAQUS_FACES = {1: (1, 2, 3, 4), 2: (5, 8, 7, 6), 3: (1, 5, 6, 2), 4: (2, 6, 7, 3), 5: (3, 7, 8, 4), 6: (4, 8, 5, 1)}


def check_abaqus(path, ref):
    name = os.path.basename(path)
    keyword, params = None, {}
    elements, elsets, nsets, surface = {}, {}, {}, []
    for raw in open(path):
        line = raw.strip()
        if not line or line.startswith("**"):
            continue
        if line.startswith("*"):
            parts = [p.strip() for p in line[1:].split(",")]
            keyword = parts[0].upper()
            params = {p.split("=")[0].upper(): (p.split("=")[1] if "=" in p else True) for p in parts[1:]}
            continue
        fields = [f.strip() for f in line.split(",") if f.strip()]
        if keyword == "ELEMENT":
            elements[int(fields[0])] = [int(x) - 1 for x in fields[1:]]
            elsets.setdefault(params["ELSET"], []).append(int(fields[0]))
        elif keyword == "ELSET" and params.get("GENERATE"):
            a, b, s = (int(x) for x in fields)
            elsets.setdefault(params["ELSET"], []).extend(range(a, b + 1, s))
        elif keyword == "NSET":
            nsets.setdefault(params["NSET"], []).extend(int(x) - 1 for x in fields)
        elif keyword == "SURFACE":
            check(params.get("NAME") == "BOUNDARY" and params.get("TYPE") == "ELEMENT", f"{name}: *SURFACE {params}")
            surface.append((int(fields[0]), fields[1]))
    for v in sorted(set(int(b) for b in ref.blocks)):
        members = sorted(elsets.get(f"EB{v}", []))
        check(members == [h + 1 for h in np.flatnonzero(ref.blocks == v)], f"{name}: ELSET EB{v}")
    check(sorted(elsets.get("ALLHEXES", [])) == list(range(1, len(ref.cells) + 1)), f"{name}: ELSET ALLHEXES")
    check(sorted(nsets.get("BOUNDARY", [])) == ref.boundary_nodes, f"{name}: NSET BOUNDARY")
    faces = []
    for e, label in surface:
        m = re.fullmatch(r"S([1-6])", label)
        if not check(m is not None and e in elements, f"{name}: surface entry {e}, {label}"):
            return
        faces.append(canonical(elements[e][k - 1] for k in reversed(ABAQUS_FACES[int(m.group(1))])))
    check(len(faces) == len(ref.boundary) and set(faces) == ref.boundary,
          f"{name}: SURFACE BOUNDARY is the outward boundary ({len(faces)} faces, {len(ref.boundary)} expected)")


def quad_area(points, quad):
    """Area of a bilinear quad by 2x2 Gauss points, the rule CalculiX integrates faces with."""
    p = points[list(quad)]
    g = 1.0 / np.sqrt(3.0)
    area = 0.0
    for s_ in (-g, g):
        for t in (-g, g):
            ds = 0.25 * (-(1 - t) * p[0] + (1 - t) * p[1] + (1 + t) * p[2] - (1 + t) * p[3])
            dt = 0.25 * (-(1 - s_) * p[0] - (1 + s_) * p[1] + (1 + s_) * p[2] + (1 - s_) * p[3])
            area += np.linalg.norm(np.cross(ds, dt))
    return area


def calculix_surface(ccx, deck_text, tmp, name):
    """Runs CalculiX on isohex's deck (included) with a gravity step and *SECTION PRINT of the
    surface BOUNDARY; returns (area, mean normal) as CalculiX reports them, or None."""
    work = os.path.join(tmp, "ccx_" + name)
    os.makedirs(work, exist_ok=True)
    with open(os.path.join(work, "mesh.inp"), "w") as f:
        f.write(deck_text)
    with open(os.path.join(work, "job.inp"), "w") as f:
        f.write("*INCLUDE, INPUT=mesh.inp\n*MATERIAL, NAME=STEEL\n*DENSITY\n7.8e-9\n*ELASTIC\n210000., 0.3\n"
                "*SOLID SECTION, ELSET=ALLHEXES, MATERIAL=STEEL\n*BOUNDARY\nBOUNDARY, 1, 3, 0.\n*STEP\n*STATIC\n"
                "*DLOAD\nALLHEXES, GRAV, 9.81, 0., 0., -1.\n*SECTION PRINT, SURFACE=BOUNDARY, NAME=SP1\nSOF, SOAREA\n"
                "*END STEP\n")
    p = subprocess.run([ccx, "-i", "job"], cwd=work, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       timeout=300)
    dat = os.path.join(work, "job.dat")
    if not check(p.returncode == 0 and os.path.exists(dat), f"CalculiX runs {name}: {p.stdout[-600:]}"):
        return None
    lines = [l.split() for l in open(dat).read().split("\n")]
    text = [" ".join(l) for l in lines]
    try:
        cog = text.index("center of gravity and mean normal") + 1
        while not lines[cog]:
            cog += 1
        at = next(i for i, t in enumerate(text) if t.startswith("area, normal force")) + 1
        while not lines[at]:
            at += 1
        return float(lines[at][0]), np.array([float(x) for x in lines[cog][3:6]])
    except (StopIteration, ValueError, IndexError):
        check(False, f"CalculiX {name}: no surface statistics in job.dat")
        return None


def check_calculix(ccx, path, ref, tmp):
    """CalculiX, an Abaqus-deck solver, integrates SURFACE BOUNDARY: its area must be the
    outward boundary's and its mean normal zero (a closed surface); a deck whose face labels
    are permuted must give another area, so the check can fail."""
    name = os.path.basename(path)
    deck = open(path).read()
    want = sum(quad_area(ref.points, q) for q in ref.boundary)
    got = calculix_surface(ccx, deck, tmp, name)
    if got is not None:
        area, normal = got
        check(abs(area - want) <= 1e-6 * want, f"{name}: CalculiX surface area {area} vs boundary {want}")
        check(np.abs(normal).max() < 1e-9, f"{name}: CalculiX mean normal of the closed boundary {normal}")
    swapped = re.sub(r", S([35])\n", lambda m: ", S" + ("5" if m.group(1) == "3" else "3") + "\n", deck)
    got = calculix_surface(ccx, swapped, tmp, name + "_swapped")
    if got is not None:
        check(abs(got[0] - want) > 1e-3 * want, f"{name}: CalculiX sees permuted face labels ({got[0]} vs {want})")


# ---- driver -------------------------------------------------------------------------------

FORMATS = [  # (file name suffix, extra convert arguments, keeps fixed flags)
    (".exo", [], True), (".e", [], True), (".ex2", [], True), (".msh", [], False),
    ("_bin.msh", ["--msh-binary"], False), (".inp", [], True), (".mesh", [], True),
    (".vtu", [], True), (".vtk", [], True),
]


def test_mesh(cli, gmsh, ccx, src, tmp):
    ref = Mesh(read_vtu(src))
    stem = os.path.splitext(src)[0]
    print(f"{os.path.basename(src)}: {len(ref.points)} points, {len(ref.cells)} hexes, blocks "
          f"{sorted(set(ref.blocks.tolist()))}, {len(ref.boundary)} boundary quads")
    for suffix, extra, keeps_fixed in FORMATS:
        out = stem + suffix
        rc, msg = run([cli, "convert", *extra, src, out])
        if not check(rc == 0, f"convert {src} -> {out}: {msg}"):
            continue
        back = out + ".back.vtu"
        rc, msg = run([cli, "convert", out, back])
        if check(rc == 0, f"isohex reads {out}: {msg}"):
            compare_meshes(ref, Mesh(read_vtu(back)), f"round trip through {suffix}", keeps_fixed, suffix == ".inp")
        if suffix in (".exo", ".e", ".ex2"):
            check_exodus(out, ref)
        elif suffix.endswith(".msh"):
            if gmsh:
                check_gmsh(gmsh, cli, out, ref, tmp)
        elif suffix == ".inp":
            check_abaqus(out, ref)
            if ccx:
                check_calculix(ccx, out, ref, tmp)
        elif suffix == ".vtu":
            compare_meshes(ref, Mesh(read_vtu(out)), "vtkXMLUnstructuredGridReader on isohex's .vtu")
        # Deterministic output: a second conversion gives the same bytes.
        again = stem + ".again" + suffix
        run([cli, "convert", *extra, src, again])
        check(open(out, "rb").read() == open(again, "rb").read(), f"{suffix}: same bytes on a second write")


def test_errors(cli, tmp):
    garbage = os.path.join(tmp, "garbage.exo")
    with open(garbage, "w") as f:
        f.write("this is not netCDF\n")
    rc, msg = run([cli, "convert", garbage, os.path.join(tmp, "x.vtu")])
    check(rc == 2 and "garbage.exo" in msg, f"garbage .exo: exit {rc}: {msg}")
    old = os.path.join(tmp, "old.msh")
    with open(old, "w") as f:
        f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n")
    rc, msg = run([cli, "convert", old, os.path.join(tmp, "x.vtu")])
    check(rc == 2 and "old.msh: line 2" in msg and "4.1" in msg, f"MSH 2.2 input: exit {rc}: {msg}")
    src = os.path.join(tmp, "ball.vtu")
    for ext in (".exo", ".msh", ".inp"):
        target = os.path.join(tmp, "no_such_dir", "x" + ext)
        rc, msg = run([cli, "convert", src, target])
        check(rc == 2 and target in msg and not os.path.exists(os.path.dirname(target)), f"{ext} to a missing folder: {msg}")
    leftovers = [n for n in os.listdir(tmp) if n.startswith(".")]
    check(not leftovers, f"temporary files left behind: {leftovers}")


def main():
    args = oracle_args(__doc__)
    gmsh = shutil.which("gmsh")
    if gmsh is None:
        print("SKIP (gmsh checks only): the gmsh command is not installed (scripts/install-deps.sh installs it)")
    ccx = shutil.which("ccx")
    if ccx is None:
        print("SKIP (CalculiX checks only): ccx is not installed (scripts/install-deps.sh installs calculix-ccx)")
    ball = ball_mesh(args.cli, args.tmp)
    box = os.path.join(args.tmp, "box.vtu")
    write_vtu(box_grid(4, 3, 2), box)
    for src in (ball, box):
        test_mesh(args.cli, gmsh, ccx, src, args.tmp)
    if gmsh:
        check_gmsh_mirrored(gmsh, args.cli, args.tmp)
    test_errors(args.cli, args.tmp)
    return finish()


if __name__ == "__main__":
    sys.exit(main())
