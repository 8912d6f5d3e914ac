"""Opens jelly recordings in ParaView and checks them against their HDF5 files (run by pvpython,
from tests/io/paraview_test.py).

For each RECORDING.xdmf (its .h5 beside it):
  * the default reader (what the GUI preselects and OpenDataFile picks; Xdmf3ReaderS in ParaView
    5.11): one time step per frame at the recorded times; in every frame one block per body
    (points = the recorded positions bit for bit, one cell per spring, velocity bit for bit),
    one per body's render surface (points = the recorded surface vertices bit for bit, one
    triangle per recorded triangle) and one per terrain (the plane's quad in its plane, the
    elevator's box at its recorded height, an obstacle's mesh at its recorded rotation and
    position); in three frames every array (speed, strain, mass,
    rest_length, ks, kd, spring type, the observables as field data; the surface's vertices as
    the weighted sums of the particles, its triangles and speed) against values computed from
    the HDF5 file;
  * Xdmf3ReaderT and the XDMF Reader: time steps, blocks, points and cells of three frames.
With --state FILE: runs the first recording's ParaView state (`jelly xdmf --state`) and checks
its colour range (all frames) and camera (on the bodies). With --screenshot PNG: shows the first
recording as ParaView shows it by default (colour by speed
is checked) at its frame of largest elastic energy and saves a screenshot (needs a display:
xvfb-run). For the last recording, Plot Global Variables Over Time gives the observables.

Prints "paraview_check: ..." lines; exit status 1 if a check failed.
"""
import argparse
import os
import sys
import time

import h5py
import numpy as np
from paraview import simple
from vtkmodules.util.numpy_support import vtk_to_numpy

failures = []


def say(*words):
    print("paraview_check:", *words, flush=True)


def check(ok, message):
    if not ok:
        failures.append(message)
        say("FAIL", message)
    return ok


def exact_times(recorded, dt, interval):
    """The frames' exact times as the sidecar must give them (exact_frame_times, io/recording.hpp):
    a recorded time (a sum of steps) within dt / 1000 of k x interval is that product, else within
    dt / 1000 of n x dt that product, else as recorded."""
    out = []
    for t in recorded:
        t = float(t)
        for every in (interval, dt):
            if every > 0 and dt > 0:
                k = round(t / every)
                if abs(t - k * every) <= 1e-3 * dt:
                    t = k * every
                    break
        out.append(t)
    return np.asarray(out)


class Recording:
    """What the HDF5 file holds, read with h5py."""

    def __init__(self, h5_path):
        with h5py.File(h5_path, "r") as f:
            bodies = []
            for name, group in f["particles"].items():
                bodies.append({
                    "name": name,
                    "first": int(group.attrs.get("first_particle", -1)),
                    "x": group["position/value"][:],
                    "v": group["velocity/value"][:],
                    "mass": group["mass"][:],
                    "surface": self.read_surface(group),
                })
            next_first = 0
            for body in bodies:  # without first_particle the bodies follow one another by name
                if body["first"] < 0:
                    body["first"] = next_first
                next_first = body["first"] + len(body["mass"])
            self.bodies = sorted(bodies, key=lambda b: b["first"])
            self.recorded_time = f[f"particles/{self.bodies[0]['name']}/position/time"][:]
            par = f["parameters"].attrs
            self.time = exact_times(self.recorded_time, float(par.get("dt", 0)),
                                    float(par.get("output_interval", 0)))
            xdmf = f.get("xdmf")
            self.speed_range = xdmf.attrs.get("speed_range") if xdmf is not None else None
            self.bounds = xdmf.attrs.get("bounds") if xdmf is not None else None
            c = f["connectivity"]
            springs, rest, ks, kd, kind = (c["springs"][:], c["rest_length"][:], c["ks"][:],
                                           c["kd"][:], c["type"][:])
            self.observables = {name: g["value"][:] for name, g in f["observables"].items()}
            self.terrains = []
            for name, g in f.get("terrain", {}).items():
                self.terrains.append({"name": name, "kind": g.attrs["kind"],
                                      "normal": np.asarray(g.attrs["normal"], float),
                                      "position": g["position/value"][:],
                                      "rotation": g["rotation/value"][:] if "rotation" in g
                                      else None,
                                      "mesh": g["mesh/vertices"][:] if "mesh" in g else None})
        self.terrains.sort(key=lambda t: int(t["name"].split("_")[0]))
        frames = [len(self.time)] + [len(b["x"]) for b in self.bodies] + [
            len(b["v"]) for b in self.bodies] + [
            len(b["surface"]["x"]) for b in self.bodies if b["surface"] is not None]
        self.frames = min(frames)
        for body in self.bodies:
            n = len(body["mass"])
            mine = (springs[:, 0] >= body["first"]) & (springs[:, 0] < body["first"] + n)
            body["springs"] = springs[mine] - body["first"]
            body["rest_length"], body["ks"], body["kd"], body["type"] = (
                rest[mine], ks[mine], kd[mine], kind[mine])

    @staticmethod
    def read_surface(group):
        """The body's render surface (None when the recording holds none)."""
        if "surface" not in group:
            return None
        s = group["surface"]
        return {"triangles": s["triangles"][:], "x": s["position/value"][:],
                "offsets": s["vertex_offsets"][:], "particles": s["vertex_particles"][:],
                "weights": s["vertex_weights"][:]}

    @staticmethod
    def blend(surface, values):
        """Per vertex: sum of weights times `values` of its particles ([N][3] -> [V][3])."""
        o = surface["offsets"]
        terms = surface["weights"][:, None] * values[surface["particles"]]
        return np.add.reduceat(terms, o[:-1], axis=0) if len(terms) else terms

    def strain(self, body, k):
        x = body["x"][k]
        a, b = body["springs"][:, 0], body["springs"][:, 1]
        return np.linalg.norm(x[a] - x[b], axis=1) / body["rest_length"] - 1


def leaves(data):
    """The datasets of a reader's output, in block order, with their names (None when unnamed)."""
    if not data.IsA("vtkCompositeDataSet"):
        return [(None, data)]
    out = []
    it = data.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        meta = it.GetCurrentMetaData()
        out.append((meta.Get(data.NAME()) if meta.Has(data.NAME()) else None,
                    it.GetCurrentDataObject()))
        it.GoToNextItem()
    return out


def array(attributes, name):
    a = attributes.GetArray(name)
    return None if a is None else vtk_to_numpy(a)


SPRING_TYPE = "spring_type (0 structural, 1 shear, 2 bending)"


def check_body(tag, rec, body, data, k, every_array):
    n, m = len(body["mass"]), len(body["springs"])
    check(data.GetNumberOfPoints() == n and data.GetNumberOfCells() == m,
          f"{tag}: {data.GetNumberOfPoints()} points, {data.GetNumberOfCells()} cells; "
          f"expected {n} particles, {m} springs")
    if data.GetNumberOfPoints() != n:
        return
    pd, cd = data.GetPointData(), data.GetCellData()
    check(np.array_equal(vtk_to_numpy(data.GetPoints().GetData()), body["x"][k]),
          f"{tag}: points differ from the recorded positions")
    velocity = array(pd, "velocity")
    check(velocity is not None and np.array_equal(velocity, body["v"][k]),
          f"{tag}: velocity differs from the recorded one")
    if not every_array:
        return
    speed = array(pd, "speed")
    check(speed is not None and np.allclose(speed, np.linalg.norm(body["v"][k], axis=1),
                                            rtol=1e-6, atol=1e-6), f"{tag}: speed is not |velocity|")
    check(pd.GetScalars() is not None and pd.GetScalars().GetName() == "speed",
          f"{tag}: the active point scalars are not speed")
    check(np.array_equal(array(pd, "mass"), body["mass"]), f"{tag}: mass differs")
    strain = array(cd, "strain")
    check(strain is not None and np.allclose(strain, rec.strain(body, k), rtol=0, atol=2e-5),
          f"{tag}: strain is not |xa - xb| / rest_length - 1")
    for name in ("rest_length", "ks", "kd", SPRING_TYPE):
        key = "type" if name == SPRING_TYPE else name
        values = array(cd, name)
        check(values is not None and np.array_equal(values, body[key]), f"{tag}: {name} differs")
    ids = vtk_to_numpy(data.GetCells().GetConnectivityArray()).reshape(-1, 2)
    check(np.array_equal(ids, body["springs"]), f"{tag}: cells are not the springs")
    if body is not rec.bodies[0]:  # the observables (of the whole model) are the first body's
        return
    fd = data.GetFieldData()
    for name, values in rec.observables.items():
        a = array(fd, name)
        check(a is not None and np.array_equal(a.reshape(-1), np.atleast_1d(values[k])),
              f"{tag}: field data {name} differs from /observables/{name}")


def check_surface(tag, rec, body, data, k, every_array):
    """A body's render surface: the recorded vertex positions as points, its triangles."""
    s = body["surface"]
    v, f = len(s["offsets"]) - 1, len(s["triangles"])
    check(data.GetNumberOfPoints() == v and data.GetNumberOfCells() == f,
          f"{tag}: {data.GetNumberOfPoints()} points, {data.GetNumberOfCells()} cells; "
          f"expected {v} vertices, {f} triangles")
    if data.GetNumberOfPoints() != v:
        return
    points = vtk_to_numpy(data.GetPoints().GetData())
    check(np.array_equal(points, s["x"][k]),
          f"{tag}: points differ from the recorded surface/position/value")
    if not every_array:
        return
    # The recorded vertices are what the surface's weights make of the recorded particles.
    check(np.allclose(points, rec.blend(s, body["x"][k]), rtol=0, atol=1e-12),
          f"{tag}: points are not the weighted sums of the particle positions")
    check(all(data.GetCellType(c) == 5 for c in range(data.GetNumberOfCells())),
          f"{tag}: cells are not all triangles")
    ids = vtk_to_numpy(data.GetCells().GetConnectivityArray()).reshape(-1, 3)
    check(np.array_equal(ids, s["triangles"]), f"{tag}: cells are not the surface's triangles")
    speed = array(data.GetPointData(), "speed")
    expected = np.linalg.norm(rec.blend(s, body["v"][k]), axis=1)
    check(speed is not None and np.allclose(speed, expected, rtol=1e-6, atol=1e-6),
          f"{tag}: speed is not |the weighted sum of the particle velocities|")
    check(data.GetPointData().GetScalars() is not None and
          data.GetPointData().GetScalars().GetName() == "speed",
          f"{tag}: the active point scalars are not speed")


def check_terrain(tag, terrain, data, k):
    points = vtk_to_numpy(data.GetPoints().GetData()) if data.GetPoints() else np.zeros((0, 3))
    p = terrain["position"][k]
    if terrain["kind"] == "plane":
        check(len(points) == 4 and data.GetNumberOfCells() == 2,
              f"{tag}: {len(points)} points, {data.GetNumberOfCells()} cells; expected a quad")
        check(np.allclose((points - p) @ terrain["normal"], 0, atol=1e-9),
              f"{tag}: the quad is not in the plane")
    elif terrain["mesh"] is not None:  # its recorded render mesh, turned and placed
        r = terrain["rotation"][k] if terrain["rotation"] is not None else np.eye(3)
        check(len(points) == len(terrain["mesh"]) and
              np.allclose(points, terrain["mesh"] @ r.T + p, rtol=0, atol=1e-9),
              f"{tag}: the points are not the recorded mesh at the recorded rotation and position")
    if terrain["kind"] == "elevator":
        check(len(points) == 8 and data.GetNumberOfCells() == 12,
              f"{tag}: {len(points)} points, {data.GetNumberOfCells()} cells; expected a box")
        if len(points):
            check(abs(points[:, 1].max() - p[1]) < 1e-9,
                  f"{tag}: box top at y = {points[:, 1].max()}, platform at {p[1]}")
    speed = array(data.GetPointData(), "speed")
    check(speed is not None and len(speed) == len(points), f"{tag}: no speed array")


def check_blocks(tag, rec, blocks, k, every_array=False, names=False):
    # Each body (particles and springs), then its surface when it has one; then the terrains.
    expected = []
    for body in rec.bodies:
        expected.append((body["name"], body, False))
        if body["surface"] is not None:
            expected.append((body["name"] + " surface", body, True))
    if not check(len(blocks) == len(expected) + len(rec.terrains),
                 f"{tag} frame {k}: {len(blocks)} blocks, expected {len(expected)} for the "
                 f"bodies and their surfaces, then {len(rec.terrains)} terrains"):
        return
    for (block, body, surface), (name, data) in zip(expected, blocks):
        if names:
            check(name == block, f"{tag}: block named {name}, expected {block}")
        if surface:
            check_surface(f"{tag} frame {k} {block}", rec, body, data, k, every_array)
        else:
            check_body(f"{tag} frame {k} {block}", rec, body, data, k, every_array)
    for terrain, (name, data) in zip(rec.terrains, blocks[len(expected):]):
        if names:
            check(name == terrain["name"], f"{tag}: block named {name}, expected {terrain['name']}")
        check_terrain(f"{tag} frame {k} {terrain['name']}", terrain, data, k)


def check_recording(xdmf):
    h5 = os.path.splitext(xdmf)[0] + ".h5"
    rec = Recording(h5)
    label = os.path.basename(xdmf)
    some = sorted({0, rec.frames // 2, rec.frames - 1})
    start = time.monotonic()

    reader = simple.OpenDataFile(xdmf)
    check(reader is not None and reader.GetXMLName() == "Xdmf3ReaderS",
          f"{label}: the default reader is {reader.GetXMLName() if reader else None}")
    times = np.asarray(reader.TimestepValues)
    check(np.array_equal(times, rec.time[:rec.frames]),
          f"{label}: {len(times)} time steps, {rec.frames} recorded frames (or other times)")
    # Exact (rec.time: products, not the sums of steps the run recorded).
    summed = int(np.count_nonzero(rec.recorded_time[:rec.frames] != rec.time[:rec.frames]))
    say(f"{label}: {summed} of {rec.frames} recorded times were sums of steps off their exact time")
    algorithm = reader.GetClientSideObject()
    for k in range(min(len(times), rec.frames)):
        algorithm.UpdateTimeStep(times[k])
        check_blocks(f"{label} default reader", rec, leaves(algorithm.GetOutputDataObject(0)), k,
                     every_array=k in some)
    say(f"{label}: default reader ({reader.GetXMLName()}): {len(times)} time steps, every frame "
        "checked")
    simple.Delete(reader)

    for name, make in (("Xdmf3ReaderT", lambda: simple.Xdmf3ReaderT(FileName=[xdmf])),
                       ("XDMF Reader", lambda: simple.XDMFReader(FileNames=[xdmf]))):
        reader = make()
        check(len(reader.TimestepValues) == rec.frames,
              f"{label} {name}: {len(reader.TimestepValues)} time steps, {rec.frames} frames")
        algorithm = reader.GetClientSideObject()
        for k in some:
            algorithm.UpdateTimeStep(rec.time[k])
            check_blocks(f"{label} {name}", rec, leaves(algorithm.GetOutputDataObject(0)), k,
                         names=name == "XDMF Reader")
        say(f"{label}: {name}: {len(reader.TimestepValues)} time steps, frames {some} checked")
        simple.Delete(reader)
    say(f"{label}: {len(rec.bodies)} bodies, "
        f"{sum(b['surface'] is not None for b in rec.bodies)} surfaces, {len(rec.terrains)} "
        f"terrains, {rec.frames} frames checked in {time.monotonic() - start:.1f} s")
    return rec


def check_global_variables(xdmf, rec):
    """Filters > Plot Global Variables Over Time: the observables (field data) against time."""
    reader = simple.OpenDataFile(xdmf)
    plot = simple.PlotGlobalVariablesOverTime(Input=reader)
    plot.UpdatePipeline()
    table = plot.GetClientSideObject().GetOutputDataObject(0)
    label = os.path.basename(xdmf)
    check(table.GetNumberOfRows() == rec.frames,
          f"{label}: Plot Global Variables Over Time has {table.GetNumberOfRows()} rows")
    for name, values in rec.observables.items():
        column = array(table.GetRowData(), name)
        check(column is not None and np.array_equal(column.reshape(len(column), -1),
                                                    values[:rec.frames].reshape(rec.frames, -1)),
              f"{label}: Plot Global Variables Over Time: {name} differs from /observables")
    say(f"{label}: Plot Global Variables Over Time: {table.GetNumberOfRows()} rows, "
        f"{len(rec.observables)} observables")
    simple.Delete(plot)
    simple.Delete(reader)


def screenshot(xdmf, rec, png):
    reader = simple.OpenDataFile(xdmf)
    view = simple.CreateView("RenderView")
    view.ViewSize = [1200, 800]
    view.OrientationAxesVisibility = 1
    display = simple.Show(reader, view)
    check(list(display.ColorArrayName) == ["POINTS", "speed"],
          f"ParaView colours by {list(display.ColorArrayName)} by default, not by speed")
    energy = rec.observables.get("elastic_energy")
    k = int(np.argmax(energy[:rec.frames])) if energy is not None else rec.frames // 2
    view.ViewTime = rec.time[k]
    top = max(np.linalg.norm(b["v"][:rec.frames], axis=2).max() for b in rec.bodies)
    lut = simple.GetColorTransferFunction("speed")
    lut.RescaleTransferFunction(0.0, float(top))
    display.SetScalarBarVisibility(view, True)
    bar = simple.GetScalarBar(lut, view)
    bar.Title = "speed (m/s)"
    bar.ComponentTitle = ""
    simple.Render(view)  # the first render resets the camera: place it after
    com = rec.observables["center_of_mass"][k] if "center_of_mass" in rec.observables else \
        rec.bodies[0]["x"][k].mean(axis=0)
    # From the front right, above, at three times the diagonal of the bodies' box.
    x = np.concatenate([b["x"][k] for b in rec.bodies])
    away = np.array([8.0, 6.0, 18.0])
    away *= 3 * np.linalg.norm(np.ptp(x, axis=0)) / np.linalg.norm(away)
    view.CameraFocalPoint = list(com)
    view.CameraPosition = list(com + away)
    view.CameraViewUp = [0, 1, 0]
    text = simple.Text(Text=f"{os.path.basename(xdmf)}   t = {rec.time[k]:.2f} s   "
                            "(default reader, colour by speed)")
    simple.Show(text, view).FontSize = 14
    simple.Render(view)
    simple.SaveScreenshot(png, view, ImageResolution=[1200, 800])
    from vtkmodules.vtkIOImage import vtkPNGReader
    image = vtkPNGReader()
    image.SetFileName(png)
    image.Update()
    pixels = vtk_to_numpy(image.GetOutput().GetPointData().GetScalars())
    colours = len(np.unique(pixels.reshape(len(pixels), -1), axis=0))
    check(colours > 50, f"{png}: only {colours} colours")
    say(f"screenshot {png}: {colours} colours, frame {k} (t = {rec.time[k]:.3f} s)")
    # Closed here: a render view still open when sys.exit() runs makes the X server report
    # "GLXBadContext" while Python shuts down.
    for proxy in (text, reader, view):
        simple.Delete(proxy)


def check_state(state, xdmf, rec):
    """Loads the state written by `jelly xdmf --state` as ParaView's Load State runs a Python
    state: the colour range must be the speed range over every frame (not frame 0's) and the
    camera must look at the bodies' box over the run from a distance that shows all of it."""
    import runpy
    label = os.path.basename(state)
    for proxy in list(simple.GetSources().values()):
        simple.Delete(proxy)
    runpy.run_path(state, run_name="__main__")
    sources = list(simple.GetSources().values())
    check(len(sources) == 1 and os.path.samefile(sources[0].FileName[0], xdmf),
          f"{label}: opened {[s.FileName for s in sources]}, not {xdmf}")
    top = max(max(np.linalg.norm(b["v"][:rec.frames], axis=2).max() for b in rec.bodies),
              0.0)
    lut = simple.GetColorTransferFunction("speed")
    points = lut.RGBPoints
    lo, hi = points[0], points[-4]
    check(rec.speed_range is not None and abs(hi - top) <= 1e-6 * max(1.0, top) and
          lo == rec.speed_range[0] and hi == rec.speed_range[1],
          f"{label}: colour range [{lo}, {hi}], the largest speed over all frames is {top}")
    check(lut.AutomaticRescaleRangeMode == "Never", f"{label}: the range is rescaled while playing")
    x = np.concatenate([b["x"][:rec.frames].reshape(-1, 3) for b in rec.bodies])
    lo3, hi3 = x.min(axis=0), x.max(axis=0)
    view = simple.GetActiveView()
    focal = np.asarray(view.CameraFocalPoint)
    check(np.allclose(focal, 0.5 * (lo3 + hi3), atol=1e-9 * (1 + np.abs(focal).max())),
          f"{label}: the camera looks at {focal}, not the bodies' box centre {0.5 * (lo3 + hi3)}")
    distance = np.linalg.norm(np.asarray(view.CameraPosition) - focal)
    radius = 0.5 * np.linalg.norm(hi3 - lo3)
    fits = radius / np.sin(np.radians(view.CameraViewAngle / 2))
    check(fits <= distance <= 1.5 * fits,
          f"{label}: camera distance {distance:.3g} m for a box of radius {radius:.3g} m")
    say(f"{label}: colour range [{lo:.3g}, {hi:.3g}] m/s (largest speed {top:.3g}), camera on "
        f"the box centre at {distance:.3g} m (radius {radius:.3g} m)")
    for proxy in list(simple.GetSources().values()):
        simple.Delete(proxy)
    # A render view still open when sys.exit() runs makes the X server report GLXBadContext.
    simple.Delete(view)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("xdmf", nargs="+")
    parser.add_argument("--screenshot", help="PNG of the first recording")
    parser.add_argument("--state", help="the first recording's state (jelly xdmf --state)")
    args = parser.parse_args()
    recordings = [check_recording(x) for x in args.xdmf]
    check_global_variables(args.xdmf[-1], recordings[-1])  # every frame again: the last one only
    if args.state:
        check_state(args.state, args.xdmf[0], recordings[0])
    if args.screenshot:
        screenshot(args.xdmf[0], recordings[0], args.screenshot)
    say("all checks passed" if not failures else f"{len(failures)} checks failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
