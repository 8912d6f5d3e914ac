"""Parameter sweeps on Dask distributed: one simulation per combination of values, one HDF5 file
per run, and a summary table (pandas DataFrame and CSV).

The runs are independent processes' work: each task rebuilds the scene from its JSON text and the
run's overrides, simulates it with the C++ solver and records it. ``client=None`` starts a
``distributed.LocalCluster`` on this machine (one single-threaded worker process per core) and
closes it at the end; any other ``distributed.Client`` (a Slurm or Kubernetes cluster through
dask-jobqueue or dask-kubernetes, or ``Client("tcp://scheduler:8786")``) runs the same tasks
there, with ``out_dir`` on a file system the workers share.
"""

from __future__ import annotations

import itertools
import math
import os
import time
from typing import Any, Mapping, Optional, Sequence

from . import _jelly
from ._scene import Scene, _json_value

__all__ = ["sweep", "sweep_points"]

# Columns of the summary, after 'run' and one column per swept path.
SUMMARY_COLUMNS = ["status", "reason", "t_end", "t_diverged", "steps", "final_energy",
                   "wall_seconds", "file"]


def sweep_points(parameters: Mapping[str, Sequence[Any]]) -> list[dict[str, Any]]:
    """The product of the values, in order (the last path varies fastest): a list of
    {path: value} dicts, one per run."""
    paths = list(parameters)
    for path in paths:
        if isinstance(parameters[path], (str, bytes)) or not hasattr(parameters[path], "__iter__"):
            raise TypeError(f"sweep: the values of '{path}' must be a list")
    return [dict(zip(paths, values))
            for values in itertools.product(*(list(parameters[p]) for p in paths))]


def run_point(scene_json: str, source: str, point: Mapping[str, Any], path: Optional[str],
              duration: Optional[float], recorder_options: Optional[dict]) -> dict[str, Any]:
    """One run of a sweep (executed on a worker): the scene with the point's overrides,
    simulated until its duration and recorded to `path` (None: not recorded)."""
    start = time.perf_counter()
    overrides = dict(point)
    if duration is not None:
        overrides["duration"] = duration
    scene = Scene(scene_json, overrides, source)
    sim = _jelly.Simulator(scene)
    recorder = None
    if path is not None:
        options = _jelly.RecorderOptions()
        for key, value in (recorder_options or {}).items():
            setattr(options, key, value)
        recorder = _jelly.H5Recorder(path, sim, scene, options)
        sim.add_observer(recorder)
    try:
        report = sim.run_until(scene.get("duration"))
    finally:
        if recorder is not None:
            recorder.close()
    energy = sim.total_energy()
    return {
        "status": report.status,
        "reason": report.reason,
        "t_end": report.t,
        "t_diverged": report.t if report.status == "diverged" else math.nan,
        "steps": report.steps,
        "final_energy": energy if math.isfinite(energy) else math.nan,
        "wall_seconds": time.perf_counter() - start,
        "file": path or "",
    }


def sweep(scene: Scene, parameters: Mapping[str, Sequence[Any]], client: Any = None, *,
          out_dir: Optional[str | os.PathLike] = "sweep", duration: Optional[float] = None,
          recorder_options: Optional[dict] = None, n_workers: Optional[int] = None):
    """Runs the scene once per combination of the parameter values ({json_path: [values]}, the
    product of all lists) in parallel on Dask distributed, and returns the summary as a pandas
    DataFrame (also written to out_dir/summary.csv).

    Each run is recorded to out_dir/run_NNNN.h5 (out_dir=None: no files, no CSV). Columns: run,
    one per path, status ("completed", "completed_with_warnings", "diverged", "solver_failed"),
    reason, t_end (time reached), t_diverged (NaN unless diverged), steps, final_energy (total
    energy at the end, J; NaN if not finite), wall_seconds (of the whole task on its worker), file.

    client: None starts a LocalCluster of n_workers (default: the number of cores, at most the
    number of runs) single-threaded worker processes and closes it afterwards; pass a
    distributed.Client to run anywhere else. duration overrides the scene's. Every point is
    validated before anything runs: a bad value raises InputError naming its JSON path.
    """
    import pandas

    points = sweep_points(parameters)
    source_json = scene.source_json
    source = scene._name
    for point in points:  # fail early, here, with the C++ message
        Scene(source_json, point if duration is None else {**point, "duration": duration}, source)
    paths: list[Optional[str]] = [None] * len(points)
    if out_dir is not None:
        out_dir = os.path.abspath(os.fspath(out_dir))
        os.makedirs(out_dir, exist_ok=True)
        paths = [os.path.join(out_dir, f"run_{i:04d}.h5") for i in range(len(points))]

    own_cluster = None
    if client is None:
        from distributed import Client, LocalCluster
        workers = n_workers or max(1, min(len(points), os.cpu_count() or 1))
        own_cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=":0")
        client = Client(own_cluster)
    try:
        futures = client.map(run_point, [source_json] * len(points), [source] * len(points),
                             points, paths, [duration] * len(points),
                             [recorder_options] * len(points), pure=False)
        rows = client.gather(futures)
    finally:
        if own_cluster is not None:
            client.close()
            own_cluster.close()

    records = []
    for i, (point, row) in enumerate(zip(points, rows)):
        record: dict[str, Any] = {"run": i}
        record.update({path: _plain(value) for path, value in point.items()})
        record.update(row)
        records.append(record)
    frame = pandas.DataFrame.from_records(
        records, columns=["run", *parameters, *SUMMARY_COLUMNS])
    if out_dir is not None:
        frame.to_csv(os.path.join(out_dir, "summary.csv"), index=False)
    return frame


def _plain(value: Any) -> Any:
    """A swept value as a table cell: numbers and strings as they are, others as JSON."""
    if isinstance(value, (int, float, str, bool)):
        return value
    return _json_value(value)
