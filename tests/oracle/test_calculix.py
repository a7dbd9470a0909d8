#!/usr/bin/python3
"""Oracle test: CalculiX (ccx, a solver for Abaqus decks) solves on the .inp files isohex writes.

Each mesh file is used as it is, through `*INCLUDE, INPUT=mesh.inp` from a small static deck
with its own *HEADING (linear elastic material on ELSET ALLHEXES, a clamped end, a load on the
other end, *NODE PRINT of U); ccx must print "Job finished" and no *ERROR or *WARNING.

* A cantilever beam, L x b x h = 10 x 1 x 1, from `isohex generate box` written as .inp by
  `isohex convert`: clamped at x = 0, a total load P in -z on the x = L face (consistent nodal
  forces of a uniform traction). The mean tip deflection must match Timoshenko's beam
  theory, PL^3/(3EI) + PL/(kGA) with Cowper's k for a rectangle, within 3 % on 80 x 8 x 8 C3D8
  hexes; C3D8 with full integration is too stiff in bending (shear locking, and the clamped
  face also holds the Poisson contraction), so the coarser 40 x 4 x 4 mesh must be further
  off, from below. The same 40 x 4 x 4 beam in metres (lengths x 1e-3), moved to negative
  coordinates below 0.01 in size, needs the writer's short spellings (".0123...", "1.2e-5")
  of its coordinates: its deflection must be the first one's x 1000 (to 1e-5).
* Meshes of `isohex cut`: a 12^3 cube (side 2) carved by three overlapping spheres, and the
  cube cut by a plane into two conforming blocks: clamped at z = 0, loaded sideways at z = 2;
  det J > 0 at every Gauss point (numpy), ccx finishes, the top moves along the load; then a
  pressure on the surface CUT1 isohex wrote (the first sphere's cavity) pushes its nodes out.
* Unless ISOHEX_CCX_PIPELINE=0: the meshes of `isohex mesh` on the headsq and
  MR head rows of scripts/paper_table.py (its case list), written as .inp: the main part's
  bottom (z within 1 % of its height above its lowest node) clamped, a sideways load on its
  top (the same below its highest node), the small parts beside it held. The top's mean
  sideways motion must be positive (the load's work). The elements ccx refuses for a
  nonpositive Jacobian determinant must be those where numpy finds det J <= 0 at a 2 x 2 x 2
  Gauss point; they are listed, with how many are positive at all 8 corners (where the
  scaled Jacobian looks), and there must be none: ccx must finish the job.

Exits 77 (ctest: skipped) without ccx; the pipeline cases skip without the shared data.
"""
import os
import re
import shutil
import subprocess
import sys

from oracle_support import check, finish, oracle_args


E, NU = 1000.0, 0.3  # any consistent units


def run(cmd, cwd=None, timeout=600):
    p = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=timeout)
    return p.returncode, p.stdout


def read_inp(path):
    """Node id -> (x, y, z) and element id -> node ids of an Abaqus file (one line per element)."""
    nodes, elements, keyword = {}, {}, None
    for line in open(path):
        if line.startswith("**"):
            continue
        if line.startswith("*"):
            keyword = line[1:].split(",")[0].strip().upper()
            continue
        f = line.split(",")
        if keyword == "NODE" and line.strip():
            nodes[int(f[0])] = tuple(float(x) for x in f[1:4])
        elif keyword == "ELEMENT" and line.strip():
            elements[int(f[0])] = [int(x) for x in f[1:]]
    return nodes, elements


def components(nodes, elements):
    """The node sets of the parts connected through elements."""
    parent = {n: n for n in nodes}

    def root(n):
        while parent[n] != n:
            parent[n] = parent[parent[n]]
            n = parent[n]
        return n
    for ids in elements.values():
        for n in ids[1:]:
            a, b = root(ids[0]), root(n)
            if a != b:
                parent[b] = a
    parts = {}
    for n in nodes:
        parts.setdefault(root(n), []).append(n)
    return list(parts.values())


def id_lines(ids):
    ids = sorted(ids)
    return "".join(", ".join(str(i) for i in ids[k:k + 16]) + "\n" for k in range(0, len(ids), 16))


def solve(ccx, work, mesh_inp, clamped, loads, printed, step_lines=""):
    """Runs a static deck that includes `mesh_inp` (in `work`): `clamped` nodes held in x, y, z,
    `loads` {node: (dof, force)} (and `step_lines`, more loads), U printed for `printed`. Returns
    ccx's output and {node: (ux, uy, uz)} from job.dat (empty when ccx failed)."""
    # A deck of its own *HEADING: ccx refuses a second one in the included file.
    deck = (f"*HEADING\nisohex oracle test_calculix\n*INCLUDE, INPUT={os.path.basename(mesh_inp)}\n"
            f"*NSET, NSET=CLAMPED\n{id_lines(clamped)}*NSET, NSET=PRINTED\n{id_lines(printed)}"
            f"*MATERIAL, NAME=ELASTIC\n*ELASTIC\n{E!r}, {NU!r}\n*SOLID SECTION, ELSET=ALLHEXES, MATERIAL=ELASTIC\n"
            "*BOUNDARY\nCLAMPED, 1, 3, 0.\n*STEP\n*STATIC\n"
            + ("*CLOAD\n" + "".join(f"{n}, {dof}, {force!r}\n" for n, (dof, force) in sorted(loads.items())) if loads else "")
            + step_lines + "*NODE PRINT, NSET=PRINTED\nU\n*END STEP\n")
    with open(os.path.join(work, "job.inp"), "w") as f:
        f.write(deck)
    rc, out = run([ccx, "-i", "job"], cwd=work)
    with open(os.path.join(work, "ccx.log"), "w") as f:
        f.write(out)
    displacements = {}
    dat = os.path.join(work, "job.dat")
    if rc == 0 and "Job finished" in out and os.path.exists(dat):
        for line in open(dat):
            f = line.split()
            if len(f) == 4 and f[0].isdigit():
                displacements[int(f[0])] = tuple(float(x) for x in f[1:])
    return out, displacements


def accepted(out, what):
    """ccx finished the job without an error or a warning."""
    # A message is its *ERROR / *WARNING line and the indented lines after it.
    problems = [" ".join(m.split()) for m in re.findall(r"\*(?:ERROR|WARNING)[^\n]*(?:\n[ \t]+\S[^\n]*)*", out)]
    check("Job finished" in out and not problems,
          f"{what}: ccx says {problems[:3] or out[-800:]}" + (f" and {len(problems) - 3} more" if len(problems) > 3 else ""))
    return "Job finished" in out and not problems


# ---- the cantilever beam -------------------------------------------------------------------

def beam_deflection(cli, ccx, tmp, cells, scale=1.0, offset=(0.0, 0.0, 0.0)):
    """Mean -uz over the tip face of the box beam (`cells` hexes along x, y, z), its lengths
    times `scale` and moved by `offset`, under a total load P = 1 in -z. None if ccx failed."""
    name = "beam_{}x{}x{}".format(*cells) + ("" if scale == 1.0 else "_moved")
    work = os.path.join(tmp, name)
    os.makedirs(work, exist_ok=True)
    vtu, inp = os.path.join(work, "beam.vtu"), os.path.join(work, "beam.inp")
    size = [str(10 * scale), str(scale), str(scale)]
    rc, out = run([cli, "generate", "box", "-n", *map(str, cells), "--size", *size, "-o", vtu])
    if not check(rc == 0, f"{name}: isohex generate box: {out}"):
        return None
    if offset != (0.0, 0.0, 0.0):
        move_vtu(vtu, offset)
    rc, out = run([cli, "convert", vtu, inp])
    if not check(rc == 0, f"{name}: isohex convert to .inp: {out}"):
        return None
    nodes, _ = read_inp(inp)
    check(len(nodes) == (cells[0] + 1) * (cells[1] + 1) * (cells[2] + 1), f"{name}: {len(nodes)} nodes")
    if offset != (0.0, 0.0, 0.0):  # the spellings this placement is for
        text = open(inp).read()
        check(", -." in text and "e-" in text, f"{name}: coordinates written as '-.0...' and with exponents")
    # Faces found by the grid's own coordinates (the ends of each axis, as written and read).
    lo = [min(p[k] for p in nodes.values()) for k in range(3)]
    hi = [max(p[k] for p in nodes.values()) for k in range(3)]
    clamped = [n for n, p in nodes.items() if p[0] == lo[0]]
    tip = [n for n, p in nodes.items() if p[0] == hi[0]]
    if not check(len(clamped) == len(tip) == (cells[1] + 1) * (cells[2] + 1), f"{name}: end faces"):
        return None
    # Consistent nodal forces of a uniform traction on bilinear quads: weight 1/2 per face edge.
    weight = {n: (0.5 if nodes[n][1] in (lo[1], hi[1]) else 1.0) * (0.5 if nodes[n][2] in (lo[2], hi[2]) else 1.0)
              for n in tip}
    total = sum(weight.values())
    out, u = solve(ccx, work, inp, clamped, {n: (3, -weight[n] / total) for n in tip}, tip)
    if not accepted(out, name) or not check(set(u) == set(tip), f"{name}: U of every tip node in job.dat"):
        return None
    # Plain bending in x-z: no sideways motion (up to ccx's 7 printed digits).
    deflection = -sum(u[n][2] * weight[n] for n in tip) / total
    check(max(abs(u[n][1]) for n in tip) < 1e-4 * deflection, f"{name}: the tip moves sideways")
    return deflection


def move_vtu(path, offset):
    """Adds `offset` to every point of the .vtu at `path` (through VTK, not isohex)."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    grid = r.GetOutput()
    pts = vtk_to_numpy(grid.GetPoints().GetData()).astype("float64") + offset
    p = vtk.vtkPoints()
    p.SetData(numpy_to_vtk(pts, deep=True))
    grid.SetPoints(p)
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(path)
    w.SetInputData(grid)
    check(w.Write() == 1, f"VTK writes {path}")


def test_beam(cli, ccx, tmp):
    L, b, h, P = 10.0, 1.0, 1.0, 1.0
    G, area, inertia = E / (2 * (1 + NU)), b * h, b * h ** 3 / 12
    kappa = 10 * (1 + NU) / (12 + 11 * NU)  # Cowper's shear coefficient of a rectangle
    bending, shear = P * L ** 3 / (3 * E * inertia), P * L / (kappa * G * area)
    theory = bending + shear
    print(f"beam theory: tip deflection {theory:.6g} (bending {bending:.6g} + shear {shear:.6g})")
    errors = {}
    for cells in ((40, 4, 4), (80, 8, 8)):
        d = beam_deflection(cli, ccx, tmp, cells)
        if d is not None:
            errors[cells] = d / theory - 1
            print(f"{cells[0]} x {cells[1]} x {cells[2]} C3D8: tip deflection {d:.6g}, {100 * errors[cells]:+.2f} % "
                  "from beam theory")
    if len(errors) == 2:
        coarse, fine = errors[(40, 4, 4)], errors[(80, 8, 8)]
        check(abs(fine) <= 0.03, f"80 x 8 x 8 beam: {100 * fine:+.2f} % from beam theory (3 % allowed)")
        check(coarse < fine < 0, f"refining 40 x 4 x 4 -> 80 x 8 x 8 approaches beam theory from below "
                                 f"({100 * coarse:+.2f} % -> {100 * fine:+.2f} %)")
    # The same beam in metres at negative coordinates: every length x 1e-3, so x 1000 deflection.
    moved = beam_deflection(cli, ccx, tmp, (40, 4, 4), 1e-3, (-0.012345678901234567, -0.0045678901234567891,
                                                              -0.00098765432109876543))
    if moved is not None and (40, 4, 4) in errors:
        plain = (1 + errors[(40, 4, 4)]) * theory
        check(abs(moved * 1e-3 / plain - 1) < 1e-5,
              f"the beam in metres moved: deflection {moved:.7g} vs 1000 x {plain:.7g}")
        print(f"40 x 4 x 4 in metres at negative coordinates: deflection {moved:.7g} = 1000 x {moved * 1e-3:.7g}")


# ---- the pipeline's meshes -----------------------------------------------------------------

def gauss_point_jacobians(nodes, elements):
    """Element ids and det J of the trilinear map at the 2 x 2 x 2 Gauss points and at the
    corners (C3D8's node order is VTK's), by numpy: an independent check of ccx's list."""
    import numpy as np
    corners = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                        [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=np.float64)

    def shape_gradients(points):  # (points, 8 nodes, 3): dN_a/dxi at each point
        return np.array([[c * np.roll(1 + corners[a] * p, -1) * np.roll(1 + corners[a] * p, -2) / 8 for a, c in
                          enumerate(corners)] for p in points])
    ids = np.array(sorted(elements))
    index = {n: i for i, n in enumerate(nodes)}
    xyz = np.array(list(nodes.values()))
    x = xyz[np.array([[index[n] for n in elements[e]] for e in ids])]  # (elements, 8, 3)
    dets = [np.linalg.det(np.einsum("eai,gaj->egij", x, shape_gradients(points)))
            for points in (corners / np.sqrt(3), corners)]
    return ids, dets[0], dets[1]


PIPELINE_CASES = ("headsq (bone, h 3.2)", "MR head (iso 40, h 4)")  # rows of scripts/paper_table.py


def test_pipeline(cli, ccx, data, tmp):
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
    import paper_table
    cases = [c for c in paper_table.cases(data, tmp) if c[0] in PIPELINE_CASES]
    check(len(cases) == len(PIPELINE_CASES), f"paper_table.py has the cases {PIPELINE_CASES}")
    for name, _, mesh_args, prep in cases:
        work = os.path.join(tmp, re.sub(r"[^a-z0-9]+", "_", name.lower()).strip("_"))
        os.makedirs(work, exist_ok=True)
        if prep:
            run([cli] + prep)
        inp = os.path.join(work, "mesh.inp")
        rc, out = run([cli, "mesh"] + mesh_args + ["-o", inp], timeout=1800)
        if not check(rc == 0 and os.path.exists(inp), f"{name}: isohex mesh exit {rc}: {out[-600:]}"):
            continue
        nodes, elements = read_inp(inp)
        # The scans leave a few small parts beside the main one: those are held at every node
        # (a part held nowhere, or at one node, makes the system singular, and SPOOLES then
        # returns garbage without a word); the main one is clamped at its bottom and loaded
        # sideways on its top, P = 1 in total.
        parts = sorted(components(nodes, elements), key=len)
        main = parts.pop()
        z = [nodes[n][2] for n in main]
        low, high = min(z), max(z)
        top = [n for n in main if nodes[n][2] >= high - 0.01 * (high - low)]
        clamped = [n for n in main if nodes[n][2] <= low + 0.01 * (high - low)] + [n for p in parts for n in p]
        out, u = solve(ccx, work, inp, clamped, {n: (1, 1.0 / len(top)) for n in top}, top)
        jacobians = sorted({int(e) for e in re.findall(r"nonpositive jacobian\s+determinant in element\s+(\d+)", out)})
        ids, at_gauss, at_corners = gauss_point_jacobians(nodes, elements)
        bad = at_gauss.min(axis=1) <= 0
        check(jacobians == ids[bad].tolist(),
              f"{name}: ccx's nonpositive Jacobians {jacobians} are numpy's at the Gauss points {ids[bad].tolist()}")
        check(not jacobians and not bad.any(), f"{name}: every element has det J > 0 at its Gauss points")
        if bad.any():
            print(f"{name}: {int(bad.sum())} elements with det J <= 0 at {int((at_gauss[bad] <= 0).sum())} Gauss points, "
                  f"of which {int((at_corners[bad].min(axis=1) > 0).sum())} are positive at all 8 corners")
        print(f"{name}: {len(elements)} elements, {len(nodes)} nodes, {len(parts)} small parts beside the main one "
              f"({len(main)} nodes: {len(clamped) - len(nodes) + len(main)} clamped, {len(top)} loaded); ccx: "
              + (f"{len(jacobians)} elements with a nonpositive Jacobian determinant: {jacobians}" if jacobians
                 else "Job finished" if "Job finished" in out else out[-400:]))
        if accepted(out, name):
            # The load's work, mean ux here, is u'Ku > 0 for any solution of a sound system.
            check(len(u) == len(top) and sum(v[0] for v in u.values()) > 0, f"{name}: the loaded top moves along the load")


# ---- meshes cut by sheet insertion ---------------------------------------------------------

def test_cut(cli, ccx, tmp):
    """`isohex cut` meshes: a cube carved by three overlapping spheres, and the cube cut by a
    plane into two conforming blocks, clamped at z = 0 and loaded sideways on z = 2."""
    cube = os.path.join(tmp, "cut_cube.vtu")
    rc, out = run([cli, "generate", "box", "-n", "12", "--size", "2", "-o", cube])
    check(rc == 0, f"generate: {out}")
    cases = {"cube carved by three spheres": ["--keep", "outside", "--surface", "sphere(2,2,2,1.2)",
                                             "--surface", "sphere(2,0.8,1.0,0.75)", "--surface", "sphere(1.0,2,1.5,0.7)"],
             "cube cut by a plane, both blocks": ["--surface", "plane(1,1,1, 1,0.3,0.2)"]}
    for name, args in cases.items():
        work = os.path.join(tmp, re.sub(r"[^a-z0-9]+", "_", name.lower()).strip("_"))
        os.makedirs(work, exist_ok=True)
        inp = os.path.join(work, "mesh.inp")
        rc, out = run([cli, "cut", cube, "-o", inp] + args)
        if not check(rc == 0, f"{name}: isohex cut exit {rc}: {out[-600:]}"):
            continue
        nodes, elements = read_inp(inp)
        check(len(components(nodes, elements)) == 1, f"{name}: one connected part")
        clamped = [n for n, p in nodes.items() if p[2] == 0.0]
        top = [n for n, p in nodes.items() if p[2] == 2.0]
        out, u = solve(ccx, work, inp, clamped, {n: (1, 1.0 / len(top)) for n in top}, top)
        _, at_gauss, _ = gauss_point_jacobians(nodes, elements)
        check(at_gauss.min() > 0, f"{name}: det J > 0 at every Gauss point (numpy)")
        print(f"{name}: {len(elements)} elements, {len(clamped)} nodes clamped, {len(top)} loaded; ccx: "
              + ("Job finished" if "Job finished" in out else out[-400:]))
        if accepted(out, name):
            check(len(u) == len(top) and sum(v[0] for v in u.values()) > 0, f"{name}: the loaded top moves along the load")
    # A pressure on the first sphere's cavity through the surface CUT1 that isohex wrote: its
    # nodes move away from the sphere's centre (the faces are the right ones, facing out).
    work = os.path.join(tmp, "cube_carved_by_three_spheres")
    inp = os.path.join(work, "mesh.inp")
    if os.path.exists(inp):
        nodes, elements = read_inp(inp)
        centre, radius = (2.0, 2.0, 2.0), 1.2
        on_sphere = [n for n, p in nodes.items() if abs(sum((p[k] - centre[k]) ** 2 for k in range(3)) ** 0.5 - radius) < 1e-6]
        clamped = [n for n, p in nodes.items() if p[2] == 0.0]
        out, u = solve(ccx, work, inp, clamped, {}, on_sphere, "*DSLOAD\nCUT1, P, 1.0\n")
        if accepted(out, "pressure on the surface CUT1") and check(len(u) == len(on_sphere) > 20, "CUT1: U of its nodes"):
            outward = sum(sum(u[n][k] * (nodes[n][k] - centre[k]) for k in range(3)) for n in on_sphere)
            check(outward > 0, f"a pressure on CUT1 pushes its nodes away from the sphere's centre ({outward:.3g})")
            print(f"pressure on CUT1: {len(on_sphere)} nodes on the sphere, mean outward motion {outward / len(on_sphere):.3g}")


def main():
    args = oracle_args(__doc__.split("\n")[0], lambda ap: ap.add_argument(
        "--no-pipeline", action="store_true", help="the beam only (or ISOHEX_CCX_PIPELINE=0)"))
    ccx = shutil.which("ccx")
    if ccx is None:
        print("SKIP: ccx is not installed (scripts/install-deps.sh installs calculix-ccx)")
        return 77
    test_beam(args.cli, ccx, args.tmp)
    test_cut(args.cli, ccx, args.tmp)
    if not args.no_pipeline and os.environ.get("ISOHEX_CCX_PIPELINE") != "0":
        if os.path.isdir(os.path.join(args.data, "volumes")):
            test_pipeline(args.cli, ccx, args.data, args.tmp)
        else:
            print("SKIP (pipeline meshes only): no shared data")
    else:
        print("pipeline meshes not run (--no-pipeline or ISOHEX_CCX_PIPELINE=0)")
    return finish()


if __name__ == "__main__":
    sys.exit(main())
