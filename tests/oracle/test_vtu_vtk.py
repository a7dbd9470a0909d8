#!/usr/bin/python3
"""Oracle test: isohex's .vtu reader and writer against VTK's own XML writer and reader.

VTK writes a small hex grid (with a `fixed` point array and a `block` cell array) in every
layout it offers; `isohex convert` translates each file in each of its output modes; VTK
reads the results back, and points (bit for bit), connectivity, cell types, `fixed` and
`block` must match the grid VTK started from. Malformed and non-hex inputs must make the
CLI fail with a message naming the file. Exits non-zero on any failure.
"""
import argparse
import itertools
import os
import subprocess
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

FAILURES = []


def check(ok, what):
    if not ok:
        FAILURES.append(what)
        print("FAIL:", what)


def hex_grid(nx, ny, nz, float32):
    """A jittered hex grid with awkward coordinates, a fixed flag per boundary vertex and a block per hex."""
    rng = np.random.default_rng(7)
    ids = lambda i, j, k: i + (nx + 1) * (j + (ny + 1) * k)
    pts = np.array([[i, j, k] for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)], dtype=np.float64)
    pts = pts / 3.0 + rng.uniform(-0.05, 0.05, pts.shape)  # thirds: not representable exactly
    # (VTK cannot read back its own L2-norm range key when the norm overflows: no 1e300.)
    pts[0] = [-0.0, 1e-300 if not float32 else 1e-30, 1e150 if not float32 else 1e30]
    if float32:
        pts = pts.astype(np.float32)
    grid = vtk.vtkUnstructuredGrid()
    points = vtk.vtkPoints()
    points.SetData(numpy_to_vtk(pts, deep=True))
    grid.SetPoints(points)
    cells = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                cells.append([ids(i, j, k), ids(i + 1, j, k), ids(i + 1, j + 1, k), ids(i, j + 1, k),
                              ids(i, j, k + 1), ids(i + 1, j, k + 1), ids(i + 1, j + 1, k + 1), ids(i, j + 1, k + 1)])
    grid.Allocate(len(cells))
    for c in cells:
        grid.InsertNextCell(vtk.VTK_HEXAHEDRON, 8, c)
    fixed = np.array([1 if (p_i in (0, nx) or p_j in (0, ny) or p_k in (0, nz)) else 0
                      for p_k in range(nz + 1) for p_j in range(ny + 1) for p_i in range(nx + 1)], dtype=np.uint8)
    fixed_arr = numpy_to_vtk(fixed, deep=True, array_type=vtk.VTK_UNSIGNED_CHAR)
    fixed_arr.SetName("fixed")
    grid.GetPointData().AddArray(fixed_arr)
    extra = numpy_to_vtk(np.linspace(0, 1, len(pts)), deep=True)  # must be ignored
    extra.SetName("temperature")
    grid.GetPointData().AddArray(extra)
    block = np.array([(c % 3) * 1000 - 7 for c in range(len(cells))], dtype=np.int32)
    block_arr = numpy_to_vtk(block, deep=True, array_type=vtk.VTK_INT)
    block_arr.SetName("block")
    grid.GetCellData().AddArray(block_arr)
    return grid


class ErrorCatcher:
    """Records VTK error events, which VTK otherwise only prints."""

    def __init__(self, obj):
        self.errors = []
        obj.AddObserver("ErrorEvent", self)

    def __call__(self, obj, event):
        self.errors.append(event)


def with_32bit_cells(grid):
    """A shallow copy of `grid` whose cells are stored in 32 bits, so that VTK writes Int32
    connectivity and offsets (SetIdTypeToInt32 only affects vtkIdType arrays)."""
    cells = vtk.vtkCellArray()
    cells.DeepCopy(grid.GetCells())
    cells.ConvertTo32BitStorage()
    types = vtk.vtkUnsignedCharArray()
    types.DeepCopy(grid.GetCellTypesArray())
    out = vtk.vtkUnstructuredGrid()
    out.ShallowCopy(grid)
    out.SetCells(types, cells)
    return out


def write_vtk(grid, path, mode, encode, compressor, header, idtype):
    w = vtk.vtkXMLUnstructuredGridWriter()
    catcher = ErrorCatcher(w)
    w.SetInputData(with_32bit_cells(grid) if idtype == "Int32" else grid)
    w.SetFileName(path)
    {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary, "appended": w.SetDataModeToAppended}[mode]()
    w.SetEncodeAppendedData(encode)
    {"none": w.SetCompressorTypeToNone, "zlib": w.SetCompressorTypeToZLib}[compressor]()
    {"UInt32": w.SetHeaderTypeToUInt32, "UInt64": w.SetHeaderTypeToUInt64}[header]()
    {"Int32": w.SetIdTypeToInt32, "Int64": w.SetIdTypeToInt64}[idtype]()
    if not w.Write() or catcher.errors:
        raise RuntimeError("VTK failed to write " + path)


def read_vtk(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    catcher = ErrorCatcher(r)
    r.SetFileName(path)
    r.Update()
    if catcher.errors:
        raise RuntimeError("VTK failed to read " + path)
    return r.GetOutput()


def cells_of(grid):
    ca = grid.GetCells()
    return (vtk_to_numpy(ca.GetConnectivityArray()).astype(np.int64),
            vtk_to_numpy(ca.GetOffsetsArray()).astype(np.int64),
            vtk_to_numpy(grid.GetCellTypesArray()).astype(np.int64))


def same_bits(a, b):
    a = np.ascontiguousarray(a, dtype=np.float64)
    b = np.ascontiguousarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def compare(expected, got, what, with_arrays=True):
    pe = vtk_to_numpy(expected.GetPoints().GetData())
    pg = vtk_to_numpy(got.GetPoints().GetData())
    check(pg.dtype == np.float64, f"{what}: points written as {pg.dtype}, expected Float64")
    check(same_bits(pe, pg), f"{what}: points differ")
    ce, cg = cells_of(expected), cells_of(got)
    for name, e, g in zip(("connectivity", "offsets", "types"), ce, cg):
        check(np.array_equal(e, g), f"{what}: {name} differ")
    if not with_arrays:
        return
    for data, name in ((lambda g: g.GetPointData(), "fixed"), (lambda g: g.GetCellData(), "block")):
        arr = data(got).GetArray(name)
        check(arr is not None, f"{what}: array '{name}' missing")
        if arr is not None:
            check(np.array_equal(vtk_to_numpy(data(expected).GetArray(name)).astype(np.int64),
                                 vtk_to_numpy(arr).astype(np.int64)), f"{what}: array '{name}' differs")


def run_cli(cli, *args):
    p = subprocess.run([cli, *args], capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout + p.stderr


def convert_all(cli, src, expected, label, tmp, with_arrays=True):
    """Converts `src` in each isohex output mode; VTK must read back what it expects."""
    for opts in ([], ["--no-compress"], ["--ascii"]):
        out = os.path.join(tmp, "out_" + "_".join(o.strip("-") for o in opts) + os.path.basename(src))
        rc, msg = run_cli(cli, "convert", src, out, *opts)
        what = f"{label} -> isohex {' '.join(opts) or 'default'}"
        check(rc == 0, f"{what}: convert failed: {msg.strip()}")
        if rc == 0:
            try:
                compare(expected, read_vtk(out), what, with_arrays)
            except RuntimeError as e:
                check(False, f"{what}: {e}")


def test_vtk_layouts(cli, tmp):
    n = 0
    for float32, mode, encode, compressor, header, idtype in itertools.product(
            (False, True), ("ascii", "binary", "appended"), (False, True), ("none", "zlib"),
            ("UInt32", "UInt64"), ("Int32", "Int64")):
        if mode != "appended" and encode:
            continue  # EncodeAppendedData only affects appended data
        grid = hex_grid(4, 3, 2, float32)
        label = (f"VTK {mode}{' base64' if encode else ''} {compressor} {header} {idtype} "
                 f"{'Float32' if float32 else 'Float64'}")
        src = os.path.join(tmp, label.replace(" ", "_") + ".vtu")
        write_vtk(grid, src, mode, encode, compressor, header, idtype)
        # VTK's ascii writer rounds coordinates, so what VTK reads back is the reference.
        convert_all(cli, src, read_vtk(src) if mode == "ascii" else grid, label, tmp)
        n += 1
    # Large enough for several 32 KiB zlib blocks per array.
    grid = hex_grid(30, 20, 12, False)
    src = os.path.join(tmp, "large.vtu")
    write_vtk(grid, src, "appended", False, "zlib", "UInt64", "Int64")
    convert_all(cli, src, grid, "VTK large appended zlib", tmp)
    print(f"{n + 1} VTK layouts converted in 3 modes each")


def test_can(cli, data, tmp):
    src = os.path.join(data, "hexmeshes", "can.vtu")
    if not os.path.exists(src):
        print("no can.vtu; skipped")
        return
    convert_all(cli, src, read_vtk(src), "can.vtu", tmp, with_arrays=False)


def test_voxel_and_mixed(cli, tmp):
    # A voxel becomes a hex: corners 2,3 and 6,7 swap.
    grid = hex_grid(1, 1, 1, False)
    vox = vtk.vtkUnstructuredGrid()
    vox.SetPoints(grid.GetPoints())
    vox.InsertNextCell(vtk.VTK_VOXEL, 8, [0, 1, 2, 3, 4, 5, 6, 7])
    src = os.path.join(tmp, "voxel.vtu")
    write_vtk(vox, src, "appended", False, "zlib", "UInt64", "Int64")
    out = os.path.join(tmp, "voxel_out.vtu")
    rc, msg = run_cli(cli, "convert", src, out)
    check(rc == 0, f"voxel: convert failed: {msg.strip()}")
    if rc == 0:
        conn, _, types = cells_of(read_vtk(out))
        check(list(conn) == [0, 1, 3, 2, 4, 5, 7, 6] and list(types) == [12], f"voxel: got {list(conn)} {list(types)}")

    # A tetrahedron among hexes: refused by default, dropped (with its block id) on request.
    mixed = hex_grid(2, 1, 1, False)
    mixed.InsertNextCell(vtk.VTK_TETRA, 4, [0, 1, 3, 6])
    mixed.GetCellData().GetArray("block").InsertNextValue(99)
    src = os.path.join(tmp, "mixed.vtu")
    write_vtk(mixed, src, "binary", False, "zlib", "UInt32", "Int64")
    rc, msg = run_cli(cli, "convert", src, os.path.join(tmp, "mixed_out.vtu"))
    check(rc != 0 and "tetrahedron" in msg and "mixed.vtu" in msg, f"mixed: expected a tetrahedron error, got {rc}: {msg}")
    out = os.path.join(tmp, "mixed_skip.vtu")
    rc, msg = run_cli(cli, "convert", "--skip-non-hex", src, out)
    check(rc == 0 and "skipped 1 " in msg, f"mixed --skip-non-hex: {rc}: {msg}")
    if rc == 0:
        compare(hex_grid(2, 1, 1, False), read_vtk(out), "mixed --skip-non-hex")


def test_bad_inputs(cli, tmp):
    grid = hex_grid(3, 3, 3, False)
    src = os.path.join(tmp, "good.vtu")
    write_vtk(grid, src, "appended", False, "zlib", "UInt64", "Int64")
    data = open(src, "rb").read()
    for cut in (0, 40, len(data) // 3, len(data) // 2, len(data) - 40):
        bad = os.path.join(tmp, f"truncated_{cut}.vtu")
        open(bad, "wb").write(data[:cut])
        rc, msg = run_cli(cli, "convert", bad, os.path.join(tmp, "never.vtu"))
        check(rc != 0 and 0 < rc < 128 and bad in msg, f"truncated at {cut}: rc {rc}: {msg.strip()}")
    check(not os.path.exists(os.path.join(tmp, "never.vtu")), "a failed conversion left an output file")
    for comp, setter in (("vtkLZ4DataCompressor", "SetCompressorTypeToLZ4"),
                         ("vtkLZMADataCompressor", "SetCompressorTypeToLZMA")):
        w = vtk.vtkXMLUnstructuredGridWriter()
        w.SetInputData(grid)
        getattr(w, setter)()
        bad = os.path.join(tmp, comp + ".vtu")
        w.SetFileName(bad)
        w.Write()
        rc, msg = run_cli(cli, "convert", bad, os.path.join(tmp, "never.vtu"))
        check(rc != 0 and comp in msg and "vtkZLibDataCompressor" in msg and bad in msg,
              f"{comp}: expected a clear error, got {rc}: {msg.strip()}")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--cli", required=True)
    ap.add_argument("--data", required=True)
    ap.add_argument("--tmp", required=True)
    args = ap.parse_args()
    os.makedirs(args.tmp, exist_ok=True)
    test_vtk_layouts(args.cli, args.tmp)
    test_can(args.cli, args.data, args.tmp)
    test_voxel_and_mixed(args.cli, args.tmp)
    test_bad_inputs(args.cli, args.tmp)
    if FAILURES:
        print(f"{len(FAILURES)} failures")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
