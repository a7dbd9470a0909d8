#!/usr/bin/python3
"""isohex mesh against VTK's marching cubes on the real volumes.

For each case the CLI meshes the volume; the result must be a valid conformal mesh
(`isohex check`), its boundary (extracted by VTK) a closed manifold with every surface
vertex on the isosurface (the CLI's own measure), and its enclosed volume, number of boundary
components and Euler characteristic must match the marching-cubes surface that VTK
(vtkFlyingEdges3D) extracts from the same field at the same resolution:

* the field is the volume resampled trilinearly on the mesher's grid (cell size h, centred
  in the volume's box, as isohex::contour::make_grid), so both see the same samples;
* VTK counts value >= iso as inside, isohex value > iso; VTK runs at iso + 1e-6·range so
  both agree on which samples are inside (the data are integers);
* the solid is closed by the volume's box: a layer of padding whose values put the crossing
  exactly on the box face;
* surfaces of zero volume are not compared: a cavity whose samples all equal the isovalue
  exactly (integer scans have them: a sample at 40 amid tissue on the MR head) has the
  isosurface {f = iso} of a point (segments, flat squares), which the mesher fills
  (repair_edits of kind "degenerate"), while VTK at iso + 1e-6·range makes a tiny closed
  surface around it. The test finds these cavities in the field itself (zero_volume_cavities),
  requires the mesher's degenerate flips to be exactly those samples, and compares with
  marching cubes on the field with them filled: a component count lower by one per cavity,
  and a volume change below 1e-6 of the total (printed with the area discarded).

The expected agreement is 1 % in volume and exact topology; cases that cannot meet it are
listed in KNOWN_TOPOLOGY_DIFFERENCES with the reason, and the measured difference is printed.
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np
import vtk
from vtk.util import numpy_support as ns
from vtk_support import read_vtu

VOL = "volumes"

# name: (CLI volume arguments, numpy loader, isovalue, cell size)
def raw(path, dims, dtype, spacing):
    def load(data):
        a = np.fromfile(os.path.join(data, VOL, path), dtype=dtype).astype(np.float64)
        return a.reshape(dims[2], dims[1], dims[0]), np.array(spacing, float), np.zeros(3)
    return load


def via_cli_volume(cli, tmp, path, args):
    """Converts any volume to .nrrd with isohex and reads the raw values back."""
    out = os.path.join(tmp, os.path.basename(path) + ".vti")
    subprocess.run([cli, "volume", "convert", path, out, "--float"] + args, check=True, capture_output=True)
    r = vtk.vtkXMLImageDataReader()
    r.SetFileName(out)
    r.Update()
    img = r.GetOutput()
    nx, ny, nz = img.GetDimensions()
    a = ns.vtk_to_numpy(img.GetPointData().GetScalars()).astype(np.float64).reshape(nz, ny, nx)
    return a, np.array(img.GetSpacing()), np.array(img.GetOrigin())


def make_grid(lo, hi, h):
    """isohex::contour::make_grid."""
    ext = hi - lo
    n = np.floor(ext / h * (1 + 1e-12) + 1e-9).astype(int) + 1
    origin = lo + 0.5 * np.maximum(0, ext - (n - 1) * h)
    return n, origin


def resample(a, spacing, origin, n, gorigin, h):
    """Trilinear values of volume a (z, y, x) at the grid points (x fastest)."""
    coords = []
    for ax in range(3):
        g = (gorigin[ax] + h * np.arange(n[ax]) - origin[ax]) / spacing[ax]
        dim = a.shape[2 - ax]
        g = np.clip(g, 0, dim - 1)
        i0 = np.minimum(np.floor(g).astype(int), max(dim - 2, 0))
        t = g - i0
        i1 = np.minimum(i0 + 1, dim - 1)
        coords.append((i0, i1, t))
    (x0, x1, tx), (y0, y1, ty), (z0, z1, tz) = coords
    def at(zi, yi, xi):
        return a[np.ix_(zi, yi, xi)]
    tx, ty, tz = tx[None, None, :], ty[None, :, None], tz[:, None, None]
    c00 = at(z0, y0, x0) * (1 - tx) + at(z0, y0, x1) * tx
    c10 = at(z0, y1, x0) * (1 - tx) + at(z0, y1, x1) * tx
    c01 = at(z1, y0, x0) * (1 - tx) + at(z1, y0, x1) * tx
    c11 = at(z1, y1, x0) * (1 - tx) + at(z1, y1, x1) * tx
    return (c00 * (1 - ty) + c10 * ty) * (1 - tz) + (c01 * (1 - ty) + c11 * ty) * tz


def surface_stats(poly):
    """Enclosed volume, connected components and Euler characteristic of a closed surface."""
    # Quads split along a fixed diagonal (vtkTriangleFilter drops zero-area triangles of
    # degenerate quads, which would open the surface).
    tris = vtk.vtkCellArray()
    for c in range(poly.GetNumberOfCells()):
        ids = poly.GetCell(c).GetPointIds()
        n = ids.GetNumberOfIds()
        for k in range(1, n - 1):
            tris.InsertNextCell(3, [ids.GetId(0), ids.GetId(k), ids.GetId(k + 1)])
    surf = vtk.vtkPolyData()
    surf.SetPoints(poly.GetPoints())
    surf.SetPolys(tris)
    mp = vtk.vtkMassProperties()
    mp.SetInputData(surf)
    mp.Update()
    conn = vtk.vtkPolyDataConnectivityFilter()
    conn.SetInputData(surf)
    conn.SetExtractionModeToAllRegions()
    conn.Update()
    edges = vtk.vtkExtractEdges()
    edges.SetInputData(surf)
    edges.Update()
    fe = vtk.vtkFeatureEdges()
    fe.SetInputData(surf)
    fe.BoundaryEdgesOn()
    fe.NonManifoldEdgesOn()
    fe.FeatureEdgesOff()
    fe.ManifoldEdgesOff()
    fe.Update()
    used = set()
    for c in range(surf.GetNumberOfCells()):
        ids = surf.GetCell(c).GetPointIds()
        for k in range(ids.GetNumberOfIds()):
            used.add(ids.GetId(k))
    chi = len(used) - edges.GetOutput().GetNumberOfLines() + surf.GetNumberOfCells()
    return {"volume": mp.GetVolume(), "area": mp.GetSurfaceArea(), "components": conn.GetNumberOfExtractedRegions(), "euler": chi,
            "open_edges": fe.GetOutput().GetNumberOfLines()}


def grid_field(a, spacing, origin, h):
    """The volume resampled on the mesher's grid (z, y, x), its points per axis and origin."""
    lo = origin
    hi = origin + spacing * (np.array(a.shape[::-1]) - 1)
    n, gorigin = make_grid(lo, hi, h)
    return resample(a, spacing, origin, n, gorigin, h), n, gorigin


# The 18-neighbourhood (offsets with one or two nonzero coordinates): marching cubes' adjacency
# of the outside samples, as in isohex's repair.
N18 = [(dz, dy, dx) for dz in (-1, 0, 1) for dy in (-1, 0, 1) for dx in (-1, 0, 1)
       if 1 <= (dz != 0) + (dy != 0) + (dx != 0) <= 2]


def zero_volume_cavities(f, iso):
    """Grid points (i, j, k) of the cavities of zero volume, found independently of the mesher:
    18-connected parts of the outside samples (f <= iso; beyond the grid is outside too) that
    are enclosed by inside samples (f > iso), in which every sample is exactly iso, and that
    contain no whole cell. Their isosurface is a point, segments or flat squares."""
    nz, ny, nx = f.shape
    cand = set(map(tuple, np.argwhere(f == iso).tolist()))
    seen, found = set(), set()
    for s in sorted(cand):
        if s in seen:
            continue
        part, stack, ok = [s], [s], True
        seen.add(s)
        while stack:
            k, j, i = stack.pop()
            for dz, dy, dx in N18:
                q = (k + dz, j + dy, i + dx)
                if not (0 <= q[0] < nz and 0 <= q[1] < ny and 0 <= q[2] < nx):
                    ok = False
                elif f[q] > iso:
                    continue
                elif q not in cand:
                    ok = False
                elif q not in seen:
                    seen.add(q)
                    part.append(q)
                    stack.append(q)
        if ok and not any(all((k + dz, j + dy, i + dx) in cand for dz in (0, 1) for dy in (0, 1) for dx in (0, 1))
                          for k, j, i in part):
            found.update((i, j, k) for k, j, i in part)
    return found


def marching_cubes(a, spacing, origin, iso, h, rng, edits=()):
    """The marching-cubes surface of the resampled field, with the samples in `edits` (the
    mesher's repair_edits) first moved to the side of the isovalue the mesher put them on."""
    lo = origin
    hi = origin + spacing * (np.array(a.shape[::-1]) - 1)
    f, n, gorigin = grid_field(a, spacing, origin, h)
    iso_vtk = iso + 1e-6 * rng
    # A sample's last flip decides its side; one flipped back to where it was keeps its value
    # (a pinch fill can undo a carve: the value at the isovalue would move the surface).
    final = {}
    for e in edits:
        final[tuple(e["grid"])] = e["inside"]
    # A sample at the isovalue is moved off it by little (a pinch: its surface of zero width
    # there), others to 1e-3 of the range beyond it.
    for (i, j, k), inside in final.items():
        if (f[k, j, i] > iso_vtk) != inside:
            d = 1e-5 if abs(f[k, j, i] - iso) <= 1e-6 * rng else 1e-3
            f[k, j, i] = iso_vtk + (d if inside else -d) * rng
    # Padding: put the crossing from an inside boundary sample exactly on the box face.
    p = np.pad(f, 1, mode="edge")
    for ax in range(3):
        arr_ax = 2 - ax
        for side in (0, -1):
            off = (gorigin[ax] - lo[ax]) if side == 0 else (hi[ax] - (gorigin[ax] + (n[ax] - 1) * h))
            t = max(off / h, 1e-9)
            sl = [slice(None)] * 3
            sl[arr_ax] = side
            inner = [slice(None)] * 3
            inner[arr_ax] = 1 if side == 0 else -2
            edge_vals = p[tuple(inner)]
            pad = np.where(edge_vals >= iso_vtk, edge_vals + (iso_vtk - edge_vals) / t, np.minimum(edge_vals, iso_vtk - 1))
            cur = p[tuple(sl)]
            p[tuple(sl)] = np.minimum(cur, pad)  # box corners: the lower of the two faces
    img = vtk.vtkImageData()
    img.SetDimensions(int(n[0]) + 2, int(n[1]) + 2, int(n[2]) + 2)
    img.SetSpacing(h, h, h)
    img.SetOrigin(*(gorigin - h))
    img.GetPointData().SetScalars(ns.numpy_to_vtk(np.ascontiguousarray(p).ravel(), deep=1))
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(img)
    fe.SetValue(0, iso_vtk)
    fe.ComputeNormalsOff()
    fe.Update()
    return surface_stats(fe.GetOutput())


def hex_boundary(mesh_file):
    s = vtk.vtkDataSetSurfaceFilter()
    s.SetInputData(read_vtu(mesh_file))
    s.Update()
    return surface_stats(s.GetOutput())


# The repair flips samples where an inside component's complement in a cell falls apart.
# Simple flips, cavity moves (a one-sample cavity removed and made again nearby) and tunnel
# moves (a tunnel closed and another opened beside it) keep marching cubes' topology, which the test checks by running marching cubes on the samples
# with those flips applied. Where neither finds a fix, the flip is forced and may change the
# topology; the mesh must then still match marching cubes on the samples with every flip
# applied, and the case is listed here with the largest difference allowed (components,
# Euler characteristic) and the measured reason, so that a regression still fails.
KNOWN_TOPOLOGY_DIFFERENCES = {
    # Pinch fills (RepairKind::pinch): cavities that touch another one, or the outside, only at a
    # sample exactly at the isovalue (8-bit data at 40) come apart, and the forced fills after
    # them; marching cubes with every flip has the mesh's topology (checked above).
    "mrhead": (2, 12, "14 pinch fills at samples at the isovalue (components 325 -> 327, Euler 580 -> 592)"),
    "cthead-h1": (1, 4, "5 pinch fills (components 433 -> 434, Euler -252 -> -248)"),
}
# Both surfaces have their vertices on the isosurface and chord it in between; with one vertex
# per cell instead of one per cell edge the quads chord it about 1.7 times deeper than marching
# cubes' triangles (measured on analytic balls and spherical holes of radius 2.5-8 cells:
# -1.60 % vs -0.93 % at radius 8). At one voxel per cell on the two small, feature-dense
# volumes that is just over 1 % apart (bucky: isohex -0.8 %, marching cubes -1.9 % from the
# volume marching cubes converges to at 1/4 voxel; ironProt: -1.5 % and -0.4 %); at half a
# voxel both are within 0.3 % (the -h0.5 cases, held to 1 %), and with --refine-boundary 0.02
# (the -refined cases, held to 1 % of marching cubes at h/3) within 0.4 %. Bounded here so
# that a regression still fails.
KNOWN_VOLUME_DIFFERENCE = {"bucky": 0.0115, "ironProt": 0.0113}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--data", required=True)
    ap.add_argument("--tmp", required=True)
    ap.add_argument("--only", default="")
    args = ap.parse_args()
    if not os.path.isdir(os.path.join(args.data, VOL)):
        print("no shared data: skipped")
        return 0
    os.makedirs(args.tmp, exist_ok=True)
    V = lambda f: os.path.join(args.data, VOL, f)
    mache = os.path.join(args.tmp, "mache.vti")
    subprocess.run([args.cli, "volume", "molecule", os.path.join(args.data, "molecules", "mache_1MAH.pqr"), "-o", mache],
                   check=True, capture_output=True)
    headsq_raw = ["--dims", "64", "64", "93", "--type", "i16", "--spacing", "3.2", "3.2", "1.5"]
    cthead_raw = ["--dims", "256", "256", "113", "--type", "i16", "--endian", "big", "--spacing", "1", "1", "2"]
    cases = [
        # name, volume file, raw options, isovalue, cell size
        ("headsq", V("headsq_64x64x93_int16le.raw"), headsq_raw, 1150, 3.2),
        ("bucky", V("bucky_32x32x32_uint8.raw"), ["--dims", "32", "32", "32", "--type", "u8"], 51, 1.0),
        ("ironProt", V("ironProt.vtk"), [], 128, 1.0),
        # The same two at half a voxel, where the features are 4-10 cells across.
        ("bucky-h0.5", V("bucky_32x32x32_uint8.raw"), ["--dims", "32", "32", "32", "--type", "u8"], 51, 0.5),
        ("ironProt-h0.5", V("ironProt.vtk"), [], 128, 0.5),
        # MR head: 40 lies in the valley between the background noise (0-30) and tissue (50+).
        ("mrhead", V("HeadMRVolume.mhd"), [], 40, 4.0),
        # CT head, spacing not stated: 1 1 2 assumed. 600 is the skin (between air, < 200, and
        # soft tissue, 1000-1200); the scan is cut at the neck, so the box closes it.
        ("cthead", V("cthead_256x256x113_int16be.raw"), cthead_raw, 600, 2.0),
        ("mache", mache, [], 1.0, 1.0),
        # cthead at one voxel (3.9 M hexes): the most repair flips of all the cases.
        ("cthead-h1", V("cthead_256x256x113_int16be.raw"), cthead_raw, 600, 1.0),
        # Boundary refinement (--refine-boundary): the hexes under quads that chord the
        # isosurface deeper than 0.02 h are refined by 3, so the boundary there is h/3 across;
        # the volume is compared with marching cubes at h/3, the topology with it at h.
        ("bucky-refined", V("bucky_32x32x32_uint8.raw"), ["--dims", "32", "32", "32", "--type", "u8"], 51, 1.0,
         ["--refine-boundary", "0.02"]),
        ("ironProt-refined", V("ironProt.vtk"), [], 128, 1.0, ["--refine-boundary", "0.02"]),
        ("mache-refined", mache, [], 1.0, 1.0, ["--refine-boundary", "0.1"]),
    ]
    failures = []
    for name, path, raw_args, iso, h, *extra in cases:
        if args.only and name not in args.only.split(","):
            continue
        extra = extra[0] if extra else []
        out = os.path.join(args.tmp, name + ".vtu")
        rep = os.path.join(args.tmp, name + ".json")
        # --thin-features 0: the carving of one-sample wisps and specks changes the topology on
        # purpose (tests/contour_thin_test.cpp); this test holds the extraction to marching cubes.
        run = subprocess.run([args.cli, "mesh", path, "--no-surface-smoothing", "--no-pillow", "--no-smooth", "--min-component", "0", "--thin-features", "0", "--iso", str(iso), "--cell-size", str(h), "-o", out, "--json", rep]
                             + raw_args + extra, capture_output=True, text=True)
        if run.returncode != 0:
            failures.append(f"{name}: isohex mesh exit {run.returncode}: {run.stdout[-800:]} {run.stderr}")
            continue
        report = json.load(open(rep))
        # The raw extraction's topology (its inverted hexes are the untangler's to repair).
        chk = subprocess.run([args.cli, "check", "--topology", out], capture_output=True, text=True)
        a, spacing, origin = via_cli_volume(args.cli, args.tmp, path, raw_args)
        rng = float(a.max() - a.min())
        edits = report["repair_edits"]
        kind = lambda e: e.get("kind", "simple" if e["simple"] else "forced")
        # Zero-volume cavities: checked against the field, then filled in marching cubes' field
        # too (the comparison below is with that surface).
        degenerate = [e for e in edits if kind(e) == "degenerate"]
        expected = zero_volume_cavities(grid_field(a, spacing, origin, h)[0], iso)
        got = {tuple(e["grid"]) for e in degenerate}
        if got != expected or not all(e["inside"] for e in degenerate):
            failures.append(f"{name}: degenerate flips are not the zero-volume cavities of the field: "
                            f"{len(got)} flipped, {len(expected)} in the field, {len(got ^ expected)} apart")
        # Pinches (samples at the isovalue where the two sides touch with zero width, which
        # several dual vertices would share) are filled whatever the topology: marching cubes'
        # surface passes through such a sample with zero width there. Applied to its field (in
        # the order made, after the flips before them), they must change its volume by nothing
        # measurable; the topology they change is listed in KNOWN_TOPOLOGY_DIFFERENCES.
        pinch = [e for e in edits if kind(e) == "pinch"]
        mc_raw = marching_cubes(a, spacing, origin, iso, h, rng)
        mc = marching_cubes(a, spacing, origin, iso, h, rng, degenerate) if degenerate else mc_raw
        simple = [e for e in edits if kind(e) in ("simple", "relocated", "zero_level")]
        hb = hex_boundary(out)
        refined = "refinement" in report
        mc_vol = marching_cubes(a, spacing, origin, iso, h / 3, rng)["volume"] if refined else mc["volume"]
        dv = abs(hb["volume"] - mc_vol) / mc_vol
        refined_line = ""
        if refined:
            rf = report["refinement"]
            refined_line = (f"  refined: {rf['coarse_quads']} coarse quads, {rf['hexes_before']} -> {rf['hexes_after']} hexes, "
                  f"deepest chord {rf['max_chord_before']:.3g} h -> {rf['max_chord_after']:.3g} h; volume vs MC at h "
                  f"{100 * (hb['volume'] - mc['volume']) / mc['volume']:+.3f} %, vs MC at h/3 "
                  f"{100 * (hb['volume'] - mc_vol) / mc_vol:+.3f} %")
        sj = report["scaled_jacobian"]
        print(f"{name}: {report['hexes']} hexes, SJ min {sj['min']:.3f} mean {sj['mean']:.3f} "
              f"<0 {sj['inverted']} <0.2 {sj['questionable']}; flips {len(report['repair_edits'])} "
              f"({report.get('relocated_points', 0)} relocated, {report['forced_points']} forced, "
              f"{report.get('degenerate_points', 0)} degenerate, {report.get('zero_level_points', 0)} zero-level); "
              f"volume {hb['volume']:.6g} vs MC {mc_vol:.6g} ({100 * dv:.3f} %); components {hb['components']} "
              f"vs {mc['components']}; Euler {hb['euler']} vs {mc['euler']}; max dist {report['max_relative_distance']:.2g}; "
              f"box vertices {report['box_vertices']}")
        if refined_line:
            print(refined_line)
        if degenerate:
            print(f"  {report['degenerate_components']} zero-volume cavities ({len(degenerate)} samples) filled; "
                  f"marching cubes without them: components {mc_raw['components']} -> {mc['components']}, Euler "
                  f"{mc_raw['euler']} -> {mc['euler']}, area discarded {mc_raw['area'] - mc['area']:.3g} "
                  f"({(mc_raw['area'] - mc['area']) / (h * h * report['degenerate_components']):.2g} h^2 each), "
                  f"volume {mc_raw['volume'] - mc['volume']:.3g}")
            if (mc_raw["components"] - mc["components"] != report["degenerate_components"]
                    or abs(mc_raw["volume"] - mc["volume"]) > 1e-6 * mc_raw["volume"]):
                failures.append(f"{name}: the zero-volume cavities are not {report['degenerate_components']} marching-"
                                f"cubes components of no volume")
        if pinch:
            # Each is a sample at the isovalue, or a carve undone (a sample inside in the field);
            # applied to the field alone they move marching cubes' surface by at most a cell's
            # volume each (measured: the MR head 95 for 14, 0.1 h^3 each; cthead h 1 0.04 for 5).
            f_at = grid_field(a, spacing, origin, h)[0]
            odd = [e["grid"] for e in pinch
                   if not (abs(f_at[e["grid"][2], e["grid"][1], e["grid"][0]] - iso) <= 1e-6 * rng
                           or f_at[e["grid"][2], e["grid"][1], e["grid"][0]] > iso)]
            mc_p = marching_cubes(a, spacing, origin, iso, h, rng, degenerate + pinch)
            print(f"  {len(pinch)} pinch fills; marching cubes with them: components {mc['components']} -> "
                  f"{mc_p['components']}, Euler {mc['euler']} -> {mc_p['euler']}, volume {mc_p['volume'] - mc['volume']:.3g}, "
                  f"area {mc_p['area'] - mc['area']:.3g}")
            if odd or abs(mc_p["volume"] - mc["volume"]) > len(pinch) * h ** 3:
                failures.append(f"{name}: pinch fills not of zero width: {len(odd)} neither at the isovalue nor "
                                f"inside, volume change {mc_p['volume'] - mc['volume']:.3g}")
        sys.stdout.flush()
        if chk.returncode != 0:
            failures.append(f"{name}: isohex check failed: {chk.stdout[-500:]}")
        if hb["open_edges"] != 0 or mc["open_edges"] != 0:
            failures.append(f"{name}: open or non-manifold edges: hex boundary {hb['open_edges']}, MC {mc['open_edges']}")
        if report["max_relative_distance"] > 1e-6 or report["off_surface_vertices"] != 0:
            failures.append(f"{name}: boundary vertices off the isosurface ({report['max_relative_distance']:.3g})")
        if dv > KNOWN_VOLUME_DIFFERENCE.get(name, 0.01):
            failures.append(f"{name}: enclosed volume differs from marching cubes by {100 * dv:.2f} %")
        if simple:
            mc_simple = marching_cubes(a, spacing, origin, iso, h, rng, degenerate + simple)
            if (mc_simple["components"], mc_simple["euler"]) != (mc["components"], mc["euler"]):
                failures.append(f"{name}: the {len(simple)} simple, zero-level and relocated flips change marching cubes' topology: components "
                                f"{mc_simple['components']} vs {mc['components']}, Euler {mc_simple['euler']} vs {mc['euler']}")
        if len(simple) + len(degenerate) + len(pinch) != len(edits):
            mc_all = marching_cubes(a, spacing, origin, iso, h, rng, edits)
            print(f"  {len(edits) - len(simple) - len(degenerate)} forced flips; marching cubes with every flip: components "
                  f"{mc_all['components']}, Euler {mc_all['euler']}")
            if (hb["components"], hb["euler"]) != (mc_all["components"], mc_all["euler"]):
                failures.append(f"{name}: topology differs from marching cubes on the repaired samples: components "
                                f"{hb['components']} vs {mc_all['components']}, Euler {hb['euler']} vs {mc_all['euler']}")
        dc, de = abs(hb["components"] - mc["components"]), abs(hb["euler"] - mc["euler"])
        max_dc, max_de, _ = KNOWN_TOPOLOGY_DIFFERENCES.get(name, (0, 0, ""))
        if dc > max_dc or de > max_de:
            failures.append(f"{name}: topology differs from marching cubes: components {hb['components']} vs "
                            f"{mc['components']}, Euler {hb['euler']} vs {mc['euler']} (allowed: {max_dc}, {max_de})")
    for f in failures:
        print("FAIL", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
