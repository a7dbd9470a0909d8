#!/usr/bin/python3
"""Scaled-Jacobian throughput: isohex against VTK 9.1's vtkMeshQuality, on one mesh.

The mesh is `isohex generate box -n 100 --jitter 0.3` (1,000,000 perturbed hexes), written as
.vtu and read by VTK; build/bin/quality_bench builds the same mesh in memory (same generator
and seed) and reports its minimum scaled Jacobian, which must equal VTK's, so both measure the
same elements. VTK is timed on vtkMeshQuality::Update() (best of --repeats); isohex by the
benchmark's items/s with 1 and 2 threads. Use /usr/bin/python3 (Debian's python3-vtk9).

    /usr/bin/python3 bench/quality_vs_vtk.py --build build
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import vtk
from vtk.util.numpy_support import vtk_to_numpy


def cpu_model():
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        for line in out.splitlines():
            if line.startswith("Model name:"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


def vtk_throughput(path, repeats):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    quality = vtk.vtkMeshQuality()
    quality.SetInputData(grid)
    quality.SetHexQualityMeasureToScaledJacobian()
    best = float("inf")
    for _ in range(repeats):
        quality.Modified()
        start = time.perf_counter()
        quality.Update()
        best = min(best, time.perf_counter() - start)
    sj = vtk_to_numpy(quality.GetOutput().GetCellData().GetArray("Quality"))
    return grid.GetNumberOfCells() / best, float(sj.min())


def isohex_throughput(bench, repeats):
    r = subprocess.run([bench, "--benchmark_filter=BM_ScaledJacobians/", "--benchmark_format=json",
                        f"--benchmark_repetitions={repeats}", "--benchmark_report_aggregates_only=false"],
                       capture_output=True, text=True, check=True)
    best, min_sj = {}, None
    for b in json.loads(r.stdout)["benchmarks"]:
        if b.get("run_type") != "iteration":
            continue
        threads = int(b["name"].split("/")[1])  # BM_ScaledJacobians/<threads>/real_time
        best[threads] = max(best.get(threads, 0.0), b["items_per_second"])
        min_sj = b["min_sj"]
    return best, min_sj


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build", help="build folder holding bin/isohex and bin/quality_bench")
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    cli = os.path.join(a.build, "bin", "isohex")
    bench = os.path.join(a.build, "bin", "quality_bench")
    with tempfile.TemporaryDirectory() as tmp:
        mesh = os.path.join(tmp, "box100.vtu")
        subprocess.run([cli, "generate", "box", "-n", "100", "--jitter", "0.3", "-o", mesh],
                       check=True, capture_output=True)
        vtk_rate, vtk_min = vtk_throughput(mesh, a.repeats)
    rates, iso_min = isohex_throughput(bench, a.repeats)
    print(f"machine: {cpu_model()}, {os.cpu_count()} logical CPUs")
    print(f"mesh: isohex generate box -n 100 --jitter 0.3 (1,000,000 hexes)")
    print(f"VTK {vtk.vtkVersion.GetVTKVersion()} vtkMeshQuality (scaled Jacobian): {vtk_rate / 1e6:8.2f} M hexes/s")
    for t in sorted(rates):
        print(f"isohex scaled_jacobians, {t} thread(s):          {rates[t] / 1e6:8.2f} M hexes/s"
              f"  = {rates[t] / vtk_rate:5.1f} x VTK")
    same = abs(iso_min - vtk_min) <= 1e-12 * max(1.0, abs(vtk_min))
    print(f"min scaled Jacobian: isohex {iso_min:.15g}, VTK {vtk_min:.15g} ({'same mesh' if same else 'MISMATCH'})")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
