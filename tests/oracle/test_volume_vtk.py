#!/usr/bin/python3
"""Oracle test: isohex's volume readers and writers against Debian's VTK 9.1.

1. VTK writes a small image (odd sizes, awkward spacing and origin, an extent that does not
   start at 0) as .vti in every layout it offers (ascii, inline base64, appended raw or
   base64, zlib or none, UInt32 or UInt64 headers, both byte orders) and for several value
   types; `isohex volume convert` turns each into .vti and .nrrd; vtkXMLImageDataReader and
   vtkNrrdReader must read back the same values (bit for bit), dims, spacing and origin.
2. VTK writes MetaImage (.mhd/.mha, compressed or not), NIfTI (.nii, .nii.gz) and legacy
   .vtk (ASCII and binary) volumes: isohex must read the same values from each.
3. The shared volumes, read by VTK's own readers, equal isohex's conversions of them.
4. Truncated files make the CLI fail with a message naming the file, and no output.
Exits non-zero on any failure.
"""
import argparse
import itertools
import json
import os
import subprocess
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

FAILURES = []
# Debian's VTK overrides vtkNrrdReader with the MPI reader vtkPNrrdReader, which fails without MPI.
vtk.vtkObjectFactory.SetAllEnableFlags(False, "vtkNrrdReader")
# 11 x 5 x 4 points: vtkNrrdReader takes a first axis of 9 or fewer points for vector components.
EXTENT = (2, 12, 0, 4, 1, 4)
SPACING = (0.5, 1.25, 0.1)
ORIGIN = (-1.0, 2.0, 3.5)
TYPES = {"uint8": vtk.VTK_UNSIGNED_CHAR, "int16": vtk.VTK_SHORT, "uint16": vtk.VTK_UNSIGNED_SHORT,
         "int32": vtk.VTK_INT, "float32": vtk.VTK_FLOAT, "float64": vtk.VTK_DOUBLE}


def check(ok, what):
    if not ok:
        FAILURES.append(what)
        print("FAIL:", what)


class ErrorCatcher:
    """Records VTK error events, which VTK otherwise only prints."""

    def __init__(self, obj):
        self.errors = []
        obj.AddObserver("ErrorEvent", self)

    def __call__(self, obj, event):
        self.errors.append(event)


def run_cli(cli, *args):
    p = subprocess.run([cli, *args], capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout + p.stderr


def values_for(dtype, n):
    rng = np.random.default_rng(11)
    if dtype.startswith("float"):
        v = rng.normal(0, 1000, n) / 3.0  # thirds: not exact in binary
        return v.astype(dtype)
    info = np.iinfo(dtype)
    v = rng.integers(max(info.min, -30000), min(info.max, 60000), n, endpoint=True)
    v[0], v[-1] = max(info.min, -30000), min(info.max, 60000)
    return v.astype(dtype)


def make_image(dtype):
    img = vtk.vtkImageData()
    img.SetExtent(*EXTENT)
    img.SetSpacing(*SPACING)
    img.SetOrigin(*ORIGIN)
    arr = numpy_to_vtk(values_for(dtype, img.GetNumberOfPoints()), deep=True, array_type=TYPES[dtype])
    arr.SetName("density")
    img.GetPointData().SetScalars(arr)
    other = numpy_to_vtk(np.zeros(img.GetNumberOfPoints()), deep=True)  # must be ignored
    other.SetName("zeros")
    img.GetPointData().AddArray(other)
    return img


def first_point(img):
    """World position of the image's first grid point."""
    e, o, s = img.GetExtent(), img.GetOrigin(), img.GetSpacing()
    return tuple(o[a] + e[2 * a] * s[a] for a in range(3))


def dims_of(img):
    e = img.GetExtent()
    return tuple(e[2 * a + 1] - e[2 * a] + 1 for a in range(3))


def scalars(img):
    return vtk_to_numpy(img.GetPointData().GetScalars())


def read_with(reader_class, path):
    r = reader_class()
    catcher = ErrorCatcher(r)
    r.SetFileName(path)
    r.Update()
    if catcher.errors:
        raise RuntimeError(f"VTK failed to read {path}")
    return r.GetOutput()


def same(expected_img, got_img, what, exact_geometry=True):
    # isohex keeps values as float32: float64 inputs are compared after that rounding.
    e, g = scalars(expected_img).astype(np.float32), scalars(got_img)
    check(dims_of(expected_img) == dims_of(got_img), f"{what}: dims {dims_of(got_img)} != {dims_of(expected_img)}")
    check(e.shape == g.shape and np.array_equal(e.astype(np.float64), g.astype(np.float64)),
          f"{what}: values differ")
    if exact_geometry:
        check(tuple(got_img.GetSpacing()) == tuple(expected_img.GetSpacing()),
              f"{what}: spacing {got_img.GetSpacing()} != {expected_img.GetSpacing()}")
        fe, fg = first_point(expected_img), first_point(got_img)
        check(np.allclose(fe, fg, rtol=0, atol=1e-12), f"{what}: first point {fg} != {fe}")


def write_vti(img, path, mode, encode, compressor, header, big):
    w = vtk.vtkXMLImageDataWriter()
    catcher = ErrorCatcher(w)
    w.SetInputData(img)
    w.SetFileName(path)
    {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary, "appended": w.SetDataModeToAppended}[mode]()
    w.SetEncodeAppendedData(encode)
    {"none": w.SetCompressorTypeToNone, "zlib": w.SetCompressorTypeToZLib}[compressor]()
    {"UInt32": w.SetHeaderTypeToUInt32, "UInt64": w.SetHeaderTypeToUInt64}[header]()
    w.SetByteOrderToBigEndian() if big else w.SetByteOrderToLittleEndian()
    if not w.Write() or catcher.errors:
        raise RuntimeError("VTK failed to write " + path)


def convert_and_compare(cli, src, expected, label, tmp, exact_geometry=True):
    """isohex converts `src` to .vti and .nrrd; VTK must read back `expected`."""
    base = os.path.join(tmp, "out_" + os.path.basename(src).replace(".", "_"))
    for ext, reader in ((".vti", vtk.vtkXMLImageDataReader), (".nrrd", vtk.vtkNrrdReader)):
        rc, msg = run_cli(cli, "volume", "convert", src, base + ext)
        check(rc == 0, f"{label} -> {ext}: convert failed: {msg.strip()}")
        if rc != 0:
            continue
        try:
            same(expected, read_with(reader, base + ext), f"{label} -> isohex {ext} -> VTK", exact_geometry)
        except RuntimeError as e:
            check(False, f"{label} -> {ext}: {e}")


def test_vti_layouts(cli, tmp):
    n = 0
    for dtype, mode, encode, compressor, header, big in itertools.product(
            TYPES, ("ascii", "binary", "appended"), (False, True), ("none", "zlib"), ("UInt32", "UInt64"),
            (False, True)):
        if mode != "appended" and encode:
            continue  # EncodeAppendedData only affects appended data
        if mode == "ascii" and (compressor == "zlib" or header == "UInt64" or big):
            continue  # no binary data: these settings change nothing
        img = make_image(dtype)
        label = f"VTK {dtype} {mode}{' base64' if encode else ''} {compressor} {header} {'BE' if big else 'LE'}"
        src = os.path.join(tmp, label.replace(" ", "_") + ".vti")
        write_vti(img, src, mode, encode, compressor, header, big)
        # VTK's ascii writer rounds floats, so what VTK reads back is the reference.
        expected = read_with(vtk.vtkXMLImageDataReader, src) if mode == "ascii" else img
        convert_and_compare(cli, src, expected, label, tmp)
        n += 1
    # Several 32 KiB zlib blocks, and the JSON report of the same file.
    img = vtk.vtkImageData()
    img.SetDimensions(61, 47, 23)
    img.SetSpacing(0.3, 0.3, 0.7)
    img.GetPointData().SetScalars(numpy_to_vtk(values_for("float32", 61 * 47 * 23), deep=True))
    src = os.path.join(tmp, "large.vti")
    write_vti(img, src, "appended", False, "zlib", "UInt64", False)
    convert_and_compare(cli, src, img, "VTK large zlib", tmp)
    rc, msg = run_cli(cli, "volume", "info", src, "--json", os.path.join(tmp, "large.json"))
    check(rc == 0, f"info large.vti: {msg}")
    if rc == 0:
        j = json.load(open(os.path.join(tmp, "large.json")))
        v = scalars(img).astype(np.float64)
        check(j["dims"] == [61, 47, 23], f"info dims {j['dims']}")
        check(j["min"] == v.min() and j["max"] == v.max(), f"info range {j['min']} {j['max']}")
        check(abs(j["mean"] - v.mean()) < 1e-9 * max(1.0, abs(v.mean())), f"info mean {j['mean']} vs {v.mean()}")
        check(j["source_type"] == "f32", f"info type {j['source_type']}")
    print(f"{n + 1} VTK .vti layouts converted to .vti and .nrrd")


def test_other_vtk_writers(cli, tmp):
    for dtype in ("uint8", "int16", "float32"):
        img = vtk.vtkImageData()
        img.SetDimensions(11, 5, 4)
        img.SetSpacing(*SPACING)
        img.SetOrigin(*ORIGIN)
        img.GetPointData().SetScalars(numpy_to_vtk(values_for(dtype, 220), deep=True, array_type=TYPES[dtype]))
        cases = []  # (writer, path, VTK reader of that format)
        for name, compress in (("plain.mhd", False), ("packed.mha", True)):
            w = vtk.vtkMetaImageWriter()
            w.SetCompression(compress)
            cases.append((w, f"{dtype}_{name}", vtk.vtkMetaImageReader))
        for name in ("v.nii", "v.nii.gz"):
            cases.append((vtk.vtkNIFTIImageWriter(), f"{dtype}_{name}", vtk.vtkNIFTIImageReader))
        for name, binary in (("ascii.vtk", False), ("binary.vtk", True)):
            w = vtk.vtkStructuredPointsWriter()
            w.SetFileTypeToBinary() if binary else w.SetFileTypeToASCII()
            cases.append((w, f"{dtype}_{name}", vtk.vtkStructuredPointsReader))
        for w, name, reader in cases:
            path = os.path.join(tmp, name)
            w.SetFileName(path)
            w.SetInputData(img)
            w.Write()
            # The reference is what VTK reads back: MetaImage stores spacing as float32,
            # ASCII .vtk rounds floats, and VTK's NIfTI reader leaves the origin aside.
            expected = read_with(reader, path)
            check(np.array_equal(scalars(expected).astype(np.float64), scalars(img).astype(np.float64))
                  or name.endswith("ascii.vtk"), f"{name}: VTK does not read back what it wrote")
            convert_and_compare(cli, path, expected, f"VTK {name}", tmp, exact_geometry=".nii" not in name)
    print("MetaImage, NIfTI and legacy .vtk volumes written by VTK read back")


def test_shared_volumes(cli, data, tmp):
    vols = os.path.join(data, "volumes")
    if not os.path.isdir(vols):
        print("no shared data; skipped")
        return
    for name, reader in (("hydrogen.vti", vtk.vtkXMLImageDataReader), ("ironProt.vtk", vtk.vtkStructuredPointsReader),
                         ("HeadMRVolume.mhd", vtk.vtkMetaImageReader),
                         ("avg152T1_RL_nifti.nii.gz", vtk.vtkNIFTIImageReader)):
        src = os.path.join(vols, name)
        # VTK's NIfTI reader leaves the sform's offset aside: compare values and spacing only there.
        convert_and_compare(cli, src, read_with(reader, src), name, tmp, exact_geometry=not name.endswith(".nii.gz"))
    print("shared volumes agree with VTK's readers")


def test_bad_inputs(cli, tmp):
    img = make_image("float32")
    img.GetPointData().RemoveArray("zeros")  # so that every cut below falls in data isohex reads
    src = os.path.join(tmp, "good.vti")
    write_vti(img, src, "appended", False, "zlib", "UInt64", False)
    data = open(src, "rb").read()
    never = os.path.join(tmp, "never.nrrd")
    for cut in (0, 40, len(data) // 2, len(data) - 60):  # the last 30 bytes are closing tags
        bad = os.path.join(tmp, f"truncated_{cut}.vti")
        open(bad, "wb").write(data[:cut])
        rc, msg = run_cli(cli, "volume", "convert", bad, never)
        check(rc == 2 and bad in msg, f"truncated at {cut}: rc {rc}: {msg.strip()}")
    check(not os.path.exists(never), "a failed conversion left an output file")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--cli", required=True)
    ap.add_argument("--data", required=True)
    ap.add_argument("--tmp", required=True)
    args = ap.parse_args()
    os.makedirs(args.tmp, exist_ok=True)
    test_vti_layouts(args.cli, args.tmp)
    test_other_vtk_writers(args.cli, args.tmp)
    test_shared_volumes(args.cli, args.data, args.tmp)
    test_bad_inputs(args.cli, args.tmp)
    if FAILURES:
        print(f"{len(FAILURES)} failures")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
