"""Loads an OBJ sequence written by `jelly export FILE.h5 --obj-sequence DIR` into ParaView as
one animated source (ParaView 5.11's OBJ reader opens one file at a time, not numbered series).

    pvpython scripts/paraview_obj_sequence.py DIR [--fps 60] [--check FRAME]

or, in the ParaView GUI (View > Python Shell):

    exec(open("scripts/paraview_obj_sequence.py").read()); Show(load_obj_sequence("out/objs"))

Frame k of the folder (frame_0000.obj, frame_0001.obj, ...) is the time step k / fps.
--check prints the time steps and the first point of FRAME, as the pipeline reads them (tests).
"""
import argparse
import glob
import os
import sys

from paraview.simple import ProgrammableSource, servermanager

# The programmable source's scripts run inside ParaView; there, min and max are numpy's.
_INFORMATION = """
import glob
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as sddp
n = len(glob.glob({folder!r} + "/frame_*.obj"))
times = [k / {fps} for k in range(n)]
info = self.GetOutputInformation(0)
info.Set(sddp.TIME_STEPS(), times, len(times))
info.Set(sddp.TIME_RANGE(), [times[0], times[-1]], 2)
"""

_DATA = """
import glob
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as sddp
from vtkmodules.vtkIOGeometry import vtkOBJReader
files = sorted(glob.glob({folder!r} + "/frame_*.obj"))
info = self.GetOutputInformation(0)
t = info.Get(sddp.UPDATE_TIME_STEP()) if info.Has(sddp.UPDATE_TIME_STEP()) else 0.0
k = int(round(t * {fps}))
k = 0 if k < 0 else (len(files) - 1 if k >= len(files) else k)
reader = vtkOBJReader()
reader.SetFileName(files[k])
reader.Update()
self.GetOutput().ShallowCopy(reader.GetOutput())
"""


def load_obj_sequence(folder, fps=60.0):
    """A ParaView source whose time steps are the OBJ files of `folder`."""
    folder = os.path.abspath(folder)
    if not glob.glob(folder + "/frame_*.obj"):
        raise SystemExit(f"error: no frame_*.obj in {folder}")
    source = ProgrammableSource(OutputDataSetType="vtkPolyData")
    source.ScriptRequestInformation = _INFORMATION.format(folder=folder, fps=float(fps))
    source.Script = _DATA.format(folder=folder, fps=float(fps))
    source.UpdatePipelineInformation()
    return source


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder")
    parser.add_argument("--fps", type=float, default=60.0)
    parser.add_argument("--check", type=int, default=None, metavar="FRAME")
    args = parser.parse_args()
    source = load_obj_sequence(args.folder, args.fps)
    times = source.TimestepValues
    print(f"time steps: {len(times)}")
    if args.check is not None:
        source.UpdatePipeline(time=times[args.check])
        data = servermanager.Fetch(source)
        x, y, z = data.GetPoint(0)
        print(f"frame {args.check}: {data.GetNumberOfPoints()} points, "
              f"{data.GetNumberOfCells()} cells, first point {x:.9g} {y:.9g} {z:.9g}")


if __name__ == "__main__" and len(sys.argv) > 1:  # not when exec()uted in the GUI
    main()
