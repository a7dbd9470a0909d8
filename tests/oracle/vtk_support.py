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
