"""VTK pieces the oracle tests share (not a test itself: ctest runs only test_*.py)."""
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy


def read_vtu(path):
    """The unstructured grid in a .vtu file, as VTK's own XML reader reads it."""
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def hex_quality(grid, measure="ScaledJacobian"):
    """vtkMeshQuality's per-cell hex metric (Verdict as VTK 9.1 carries it), e.g. ScaledJacobian."""
    q = vtk.vtkMeshQuality()
    q.SetInputData(grid)
    getattr(q, "SetHexQualityMeasureTo" + measure)()
    q.Update()
    return vtk_to_numpy(q.GetOutput().GetCellData().GetArray("Quality")).astype(np.float64)


def trilinear(vol, spacing, p):
    """The trilinear interpolant of vol[z, y, x] at world points p (N x 3), origin 0."""
    g = p / spacing
    i = np.clip(np.floor(g).astype(int), 0, np.array(vol.shape[::-1]) - 2)
    f = g - i
    out = np.zeros(len(p))
    for dz in (0, 1):
        for dy in (0, 1):
            for dx in (0, 1):
                w = (f[:, 0] if dx else 1 - f[:, 0]) * (f[:, 1] if dy else 1 - f[:, 1]) * (f[:, 2] if dz else 1 - f[:, 2])
                out += w * vol[i[:, 2] + dz, i[:, 1] + dy, i[:, 0] + dx]
    return out
