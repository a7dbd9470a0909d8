#!/usr/bin/python3
"""Oracle test: the arrays isohex writes beside its meshes, read by VTK.

`isohex mesh` (.vtu, .vtk and Exodus, there as element and nodal variables), `isohex cut` and
`isohex convert --quality-fields` (ASCII .vtk and .vtu) write each hex's `scaled_jacobian` and `jacobian_ratio` as cell arrays, and `isohex mesh`
each vertex's `surface` and `released` as point arrays. VTK's readers must find them; the
scaled Jacobian must equal vtkMeshQuality's (Verdict) to 1e-12; the jacobian ratio must lie in
(0, 1] for these valid meshes; the vertices marked on the surface must lie on the sphere and
every boundary vertex (VTK's surface filter) must be marked on it, the others inside. With the
shared data, headsq's bone: the vertices marked on the isosurface and not released must be on
it (numpy's own trilinear interpolation of the file), and some must be marked released. Exits non-zero on any failure.
"""
import os
import subprocess
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy
from oracle_support import check, finish, oracle_args
from vtk_support import hex_quality, read_vtu, trilinear


def run(cli, *args):
    p = subprocess.run([cli, *args], capture_output=True, text=True, timeout=600)
    check(p.returncode == 0, f"isohex {' '.join(args)}: exit {p.returncode}: {p.stdout[-500:]} {p.stderr[-500:]}")


def read(path):
    if path.endswith(".vtu"):
        return read_vtu(path)
    r = vtk.vtkUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def array(data, name):
    a = data.GetArray(name)
    return None if a is None else vtk_to_numpy(a)


def check_quality(path, g):
    sj, ratio = array(g.GetCellData(), "scaled_jacobian"), array(g.GetCellData(), "jacobian_ratio")
    check(sj is not None and ratio is not None, f"{path}: no scaled_jacobian / jacobian_ratio cell arrays")
    if sj is None or ratio is None:
        return
    verdict = hex_quality(g)
    check(len(sj) == g.GetNumberOfCells(), f"{path}: {len(sj)} scaled Jacobians for {g.GetNumberOfCells()} cells")
    err = np.abs(sj - verdict).max()
    check(err <= 1e-12, f"{path}: scaled_jacobian differs from VTK's by {err}")
    check(ratio.min() > 0 and ratio.max() <= 1 + 1e-12, f"{path}: jacobian_ratio in [{ratio.min()}, {ratio.max()}]")
    print(f"{path}: {len(sj)} hexes, scaled Jacobian within {err:.1e} of VTK's, jacobian ratio {ratio.min():.3f}..{ratio.max():.3f}")


def check_exodus(path):
    """vtkExodusIIReader: the element variables per block beside VTK's own scaled Jacobian (the
    reader hands the points over as floats: 1e-5), the nodal variables."""
    r = vtk.vtkExodusIIReader()
    r.SetFileName(path)
    r.UpdateInformation()
    r.SetAllArrayStatus(vtk.vtkExodusIIReader.ELEM_BLOCK, 1)
    r.SetAllArrayStatus(vtk.vtkExodusIIReader.NODAL, 1)
    r.Update()
    it = r.GetOutput().NewIterator()
    it.InitTraversal()
    blocks = 0
    while not it.IsDoneWithTraversal():
        g = it.GetCurrentDataObject()
        sj = array(g.GetCellData(), "scaled_jacobian")
        ratio = array(g.GetCellData(), "jacobian_ratio")
        check(sj is not None and ratio is not None, f"{path}: block {blocks + 1} has no element variables")
        check(array(g.GetPointData(), "surface") is not None, f"{path}: block {blocks + 1} has no nodal variable surface")
        if sj is not None:
            err = np.abs(sj - hex_quality(g)).max()
            check(err <= 1e-5, f"{path}: block {blocks + 1}: scaled_jacobian differs from VTK's by {err}")
        blocks += 1
        it.GoToNextItem()
    check(blocks == 2, f"{path}: {blocks} element blocks, expected the cut's 2")
    print(f"{path}: {blocks} blocks with their element and nodal variables")


def check_places(path, g):
    surface, released = array(g.GetPointData(), "surface"), array(g.GetPointData(), "released")
    check(surface is not None and released is not None, f"{path}: no surface / released point arrays")
    if surface is None or released is None:
        return
    pts = vtk_to_numpy(g.GetPoints().GetData())
    r = np.linalg.norm(pts, axis=1)
    on = surface == 0
    # On the isosurface of the sphere's sampled distance (hexes of about 0.16): within 5e-3 of the
    # exact sphere; the interior vertices are farther in.
    check(on.sum() > 100 and np.abs(r[on] - 1).max() < 5e-3, f"{path}: vertices marked on the sphere off it by {np.abs(r[on] - 1).max()}")
    check(r[~on].max() < 1 - 5e-3, f"{path}: a vertex marked inside lies {r[~on].max()} from the centre")
    f = vtk.vtkDataSetSurfaceFilter()
    f.SetInputData(g)
    f.PassThroughPointIdsOn()
    f.Update()
    ids = vtk_to_numpy(f.GetOutput().GetPointData().GetArray("vtkOriginalPointIds"))
    check(bool(np.all(surface[ids] == 0)), f"{path}: {np.sum(surface[ids] != 0)} boundary vertices not marked on the surface")
    check(bool(np.all(np.isin(released, [0, 1]))), f"{path}: released flags other than 0 and 1")
    print(f"{path}: {on.sum()} vertices on the sphere (all {len(ids)} boundary vertices), {int(released.sum())} released")


def check_released(cli, data, t):
    """headsq's bone at h 3.2 releases knife-edge vertices into the band: the flags must say which."""
    raw = os.path.join(data, "volumes", "headsq_64x64x93_int16le.raw")
    run(cli, "mesh", raw, "--dims", "64", "64", "93", "--type", "i16", "--spacing", "3.2", "3.2", "1.5",
        "--iso", "1150", "--cell-size", "3.2", "-o", t("headsq.vtu"))
    g = read(t("headsq.vtu"))
    surface, released = array(g.GetPointData(), "surface"), array(g.GetPointData(), "released")
    if surface is None or released is None:
        check(False, "headsq.vtu: no surface / released point arrays")
        return
    vol = np.fromfile(raw, dtype="<i2").reshape(93, 64, 64).astype(float)
    pts = vtk_to_numpy(g.GetPoints().GetData())
    off = np.abs(trilinear(vol, np.array([3.2, 3.2, 1.5]), pts) - 1150) / (vol.max() - vol.min())
    on = (surface == 0) & (released == 0)
    loose = released == 1
    check(loose.sum() > 0, "headsq.vtu: no vertex marked released (the band is used here)")
    check(off[on].max() <= 1e-6, f"headsq.vtu: a vertex marked on the isosurface is {off[on].max():.2e} of the range off it")
    check(bool(np.all(surface[loose] != -1)), "headsq.vtu: a released vertex is not on a surface or the box")
    print(f"headsq.vtu: {on.sum()} vertices on the isosurface within {off[on].max():.1e} of the range, "
          f"{loose.sum()} released (up to {off[loose].max():.2e} off it)")


def main():
    a = oracle_args(__doc__)
    t = lambda name: os.path.join(a.tmp, name)
    for ext in ("vtu", "vtk"):
        run(a.cli, "mesh", "--shape", "sphere(0,0,0,1)", "--resolution", "14", "-o", t(f"ball.{ext}"))
        g = read(t(f"ball.{ext}"))
        check_quality(t(f"ball.{ext}"), g)
        check_places(t(f"ball.{ext}"), g)
    run(a.cli, "mesh", "--shape", "sphere(0,0,0,1)", "--resolution", "14", "--cut", "plane(0.1,0,0, 1,0.2,0)",
        "-o", t("ball.exo"))
    check_exodus(t("ball.exo"))
    run(a.cli, "cut", t("ball.vtu"), "-o", t("cut.vtu"), "--surface", "plane(0.1,0,0, 1,0.2,0)")
    check_quality(t("cut.vtu"), read(t("cut.vtu")))
    run(a.cli, "convert", t("cut.vtu"), t("cut_ascii.vtk"), "--ascii", "--quality-fields")
    run(a.cli, "convert", t("cut.vtu"), t("cut_ascii.vtu"), "--ascii", "--quality-fields")
    for name in ("cut_ascii.vtk", "cut_ascii.vtu"):
        g = read(t(name))
        check_quality(t(name), g)
        check(array(g.GetCellData(), "block") is not None, f"{name}: the block ids are gone")
    run(a.cli, "convert", t("cut.vtu"), t("plain.vtu"))
    check(read(t("plain.vtu")).GetCellData().GetArray("scaled_jacobian") is None,
          "convert without --quality-fields wrote quality arrays")
    if os.path.isdir(os.path.join(a.data, "volumes")):
        check_released(a.cli, a.data, t)
    else:
        print("no shared data: headsq's released vertices not checked")
    return finish()


if __name__ == "__main__":
    sys.exit(main())
