"""Opens a recording's XDMF sidecar with ParaView's XDMF Reader (run with pvbatch) and checks it
against the HDF5 file read with h5py: one time step per frame, the points and velocities of
some frames bit for bit, one line cell per spring with its type. Exit status 0 when all hold.

    pvbatch --force-offscreen-rendering tests/io/paraview_check.py /abs/path/run.xdmf /abs/path/run.h5
"""
import sys

import h5py
import numpy as np
from paraview import servermanager
from paraview.simple import XDMFReader
from vtkmodules.util.numpy_support import vtk_to_numpy

xdmf, h5 = sys.argv[1], sys.argv[2]
with h5py.File(h5, "r") as f:
    x = f["particles/jelly/position/value"][:]
    v = f["particles/jelly/velocity/value"][:]
    t = f["particles/jelly/position/time"][:]
    spring_type = f["connectivity/type"][:]

reader = XDMFReader(FileNames=[xdmf])
times = list(reader.TimestepValues)
failures = []
if len(times) != len(t):
    failures.append(f"{len(times)} time steps, {len(t)} frames")
for k in sorted({0, 1, len(t) // 2, len(t) - 1}):
    reader.UpdatePipeline(t[k])
    data = servermanager.Fetch(reader)
    if data.IsA("vtkCompositeDataSet"):
        it = data.NewIterator()
        it.InitTraversal()
        data = it.GetCurrentDataObject()
    points = vtk_to_numpy(data.GetPoints().GetData())
    velocity = vtk_to_numpy(data.GetPointData().GetArray("velocity"))
    types = vtk_to_numpy(data.GetCellData().GetArray("spring_type"))
    if not np.array_equal(points, x[k]):
        failures.append(f"frame {k}: points differ")
    if not np.array_equal(velocity, v[k]):
        failures.append(f"frame {k}: velocities differ")
    if data.GetNumberOfCells() != len(spring_type) or not np.array_equal(types, spring_type):
        failures.append(f"frame {k}: {data.GetNumberOfCells()} cells, {len(spring_type)} springs")
print("paraview:", len(times), "time steps;", "; ".join(failures) if failures else "all frames match")
sys.exit(1 if failures else 0)
