"""Parameter sweeps on Dask distributed: one simulation per combination of values, one HDF5 file
per run, and a summary table (pandas DataFrame and CSV).

The runs are independent processes' work: each task rebuilds the scene from its JSON text and the
run's overrides, simulates it with the C++ solver and records it. ``client=None`` starts a
``distributed.LocalCluster`` on this machine (one single-threaded worker process per core) and
closes it at the end; any other ``distributed.Client`` (a Slurm or Kubernetes cluster through
dask-jobqueue or dask-kubernetes, or ``Client("tcp://scheduler:8786")``) runs the same tasks
there, with ``out_dir`` on a file system the workers share.

A run that raises (a file that cannot be written, a worker lost) is a row with status "failed"
and the error, naming the run's parameters, in its reason; the other runs are kept.
"""

from __future__ import annotations

import ast
import itertools
import math
import multiprocessing
import os
import sys
import time
import warnings
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


def _describe(run: int, point: Mapping[str, Any]) -> str:
    """'run 3 (springs.structural.ks=700, integrator.dt=0.004)'."""
    values = ", ".join(f"{path}={_plain(value)}" for path, value in point.items())
    return f"run {run} ({values})" if values else f"run {run}"


def _failed_row(run: int, point: Mapping[str, Any], error: BaseException, path: Optional[str],
                wall_seconds: float = math.nan) -> dict[str, Any]:
    """The summary row of a run that raised: status 'failed', the error in its reason."""
    return {
        "status": "failed",
        "reason": f"{_describe(run, point)}: {type(error).__name__}: {error}",
        "t_end": math.nan, "t_diverged": math.nan, "steps": 0, "final_energy": math.nan,
        "wall_seconds": wall_seconds, "file": path or "",
    }


def run_point(scene_json: str, source: str, point: Mapping[str, Any], path: Optional[str],
              duration: Optional[float], recorder_options: Optional[dict],
              base_directory: str = "", run: int = 0) -> dict[str, Any]:
    """One run of a sweep (executed on a worker): the scene with the point's overrides,
    simulated until its duration and recorded to `path` (None: not recorded). An exception is
    returned as a row with status 'failed' naming the run's parameters (not raised: the other
    runs' rows are kept, and Dask logs no task with its arguments)."""
    start = time.perf_counter()
    try:
        return _run_point(scene_json, source, point, path, duration, recorder_options,
                          base_directory, start)
    except Exception as error:  # noqa: BLE001  (reported in the row)
        return _failed_row(run, point, error, path, time.perf_counter() - start)


def _run_point(scene_json: str, source: str, point: Mapping[str, Any], path: Optional[str],
               duration: Optional[float], recorder_options: Optional[dict],
               base_directory: str, start: float) -> dict[str, Any]:
    overrides = dict(point)
    if duration is not None:
        overrides["duration"] = duration
    scene = Scene(scene_json, overrides, source, base_directory)
    _jelly._check_run_limits(scene, path or "")
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


def _unguarded_main_call() -> Optional[str]:
    """'script.py, line 12' when sweep is called from a script's top-level code outside
    ``if __name__ == "__main__":`` (whose worker processes, started by spawning, would import the
    script and sweep again, for ever); None otherwise (a guarded call, a module, a notebook)."""
    main = sys.modules.get("__main__")
    main_file = getattr(main, "__file__", None)
    if main is None or not main_file or not os.path.isfile(main_file):
        return None
    frame = sys._getframe(1)
    while frame is not None and not (frame.f_globals is vars(main)
                                     and frame.f_code.co_name == "<module>"):
        frame = frame.f_back
    if frame is None:
        return None
    line = frame.f_lineno
    try:
        with open(main_file, encoding="utf-8") as f:
            tree = ast.parse(f.read())
    except (OSError, SyntaxError, ValueError):
        return None
    for node in tree.body:
        if isinstance(node, ast.If) and _is_main_guard(node.test):
            last = max(getattr(n, "end_lineno", n.lineno) for n in node.body)
            if node.body[0].lineno <= line <= last:
                return None
    return f"{main_file}, line {line}"


def _is_main_guard(test: ast.expr) -> bool:
    """``__name__ == "__main__"`` (either way round)."""
    if not (isinstance(test, ast.Compare) and len(test.ops) == 1
            and isinstance(test.ops[0], ast.Eq)):
        return False
    sides = [test.left, test.comparators[0]]
    names = [s.id for s in sides if isinstance(s, ast.Name)]
    texts = [s.value for s in sides if isinstance(s, ast.Constant)]
    return names == ["__name__"] and texts == ["__main__"]


def _check_out_dir(out_dir: str, count: int, overwrite: bool) -> None:
    """Refuses an out_dir that holds an earlier sweep's files (unless overwrite)."""
    if overwrite or not os.path.isdir(out_dir):
        return
    names = ["summary.csv"] + [f"run_{i:04d}.h5" for i in range(count)]
    earlier = [n for n in names
               if os.path.lexists(os.path.join(out_dir, n))
               or n.endswith(".h5") and os.path.lexists(os.path.join(out_dir, n[:-3] + ".xdmf"))]
    if earlier:
        shown = ", ".join(earlier[:3]) + (", ..." if len(earlier) > 3 else "")
        raise _jelly.InputError(
            f"sweep: out_dir = '{out_dir}' is invalid: it holds the files of an earlier sweep "
            f"({shown}); choose another out_dir, or pass overwrite=True to replace them")


def _write_summary(frame: Any, path: str) -> None:
    """summary.csv, written beside and renamed (an existing one is replaced only whole)."""
    partial = path + ".partial"
    frame.to_csv(partial, index=False)
    os.replace(partial, path)


def sweep(scene: Scene, parameters: Mapping[str, Sequence[Any]], client: Any = None, *,
          out_dir: Optional[str | os.PathLike] = "sweep", duration: Optional[float] = None,
          recorder_options: Optional[dict] = None, n_workers: Optional[int] = None,
          overwrite: bool = False):
    """Runs the scene once per combination of the parameter values ({json_path: [values]}, the
    product of all lists) in parallel on Dask distributed, and returns the summary as a pandas
    DataFrame (also written to out_dir/summary.csv).

    Each run is recorded to out_dir/run_NNNN.h5 (out_dir=None: no files, no CSV). Columns: run,
    one per path, status ("completed", "completed_with_warnings", "diverged", "solver_failed"),
    reason, t_end (time reached), t_diverged (NaN unless diverged), steps, final_energy (total
    energy at the end, J; NaN if not finite), wall_seconds (of the whole task on its worker), file.
    A run that raised is a row with status "failed" and "run N (path=value, ...): the error" as
    its reason; the other rows are kept (a warning names the failed runs).

    client: None starts a LocalCluster of n_workers (default: the number of cores, at most the
    number of runs) single-threaded worker processes and closes it afterwards; pass a
    distributed.Client to run anywhere else. duration overrides the scene's. Every point is
    validated before anything runs, with the limits jelly run applies: a bad value raises
    InputError naming its JSON path. An out_dir holding an earlier sweep's files (summary.csv,
    run_NNNN.h5) raises InputError unless overwrite=True. With client=None, a script must call
    sweep under ``if __name__ == "__main__":`` (the workers import the script): a call outside
    it raises RuntimeError before any process starts.
    """
    import pandas

    points = sweep_points(parameters)
    source_json = scene.source_json
    source = scene._name
    base = scene.base_directory
    paths: list[Optional[str]] = [None] * len(points)
    if out_dir is not None:
        out_dir = os.path.abspath(os.fspath(out_dir))
        paths = [os.path.join(out_dir, f"run_{i:04d}.h5") for i in range(len(points))]
    for point, path in zip(points, paths):  # fail early, here, with the C++ message
        _jelly._check_run_limits(
            Scene(source_json, point if duration is None else {**point, "duration": duration},
                  source, base), path or "")
    if client is None:
        if getattr(multiprocessing.current_process(), "_inheriting", False):
            raise RuntimeError(_GUARD_MESSAGE.format(where="a worker process importing the "
                                                     "script"))
        where = _unguarded_main_call()
        if where is not None:
            raise RuntimeError(_GUARD_MESSAGE.format(where=where))
    if out_dir is not None:
        _check_out_dir(out_dir, len(points), overwrite)
        os.makedirs(out_dir, exist_ok=True)
    if overwrite:
        recorder_options = {**(recorder_options or {}), "overwrite": True}

    own_cluster = None
    if client is None:
        from distributed import Client, LocalCluster
        workers = n_workers or max(1, min(len(points), os.cpu_count() or 1))
        own_cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=":0")
        client = Client(own_cluster)
    try:
        count = len(points)
        futures = client.map(run_point, [source_json] * count, [source] * count, points, paths,
                             [duration] * count, [recorder_options] * count, [base] * count,
                             list(range(count)), pure=False)
        rows = []
        for run, (point, path, future) in enumerate(zip(points, paths, futures)):
            try:
                rows.append(future.result())
            except Exception as error:  # noqa: BLE001  (a lost worker: the row says so)
                rows.append(_failed_row(run, point, error, path))
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
        _write_summary(frame, os.path.join(out_dir, "summary.csv"))
    failed = [row["reason"] for row in rows if row["status"] == "failed"]
    if failed:
        warnings.warn(f"sweep: {len(failed)} of {len(rows)} runs failed (status 'failed' in the "
                      "table): " + "; ".join(failed[:3]) + ("; ..." if len(failed) > 3 else ""),
                      RuntimeWarning, stacklevel=2)
    return frame


_GUARD_MESSAGE = (
    "jelly.sweep with client=None is called from {where}, outside 'if __name__ == "
    "\"__main__\":'. Its LocalCluster starts worker processes that import the script, which "
    "would start a sweep again in each of them: put the script's work under 'if __name__ == "
    "\"__main__\":' (docs/python.md), or pass a distributed.Client.")


def _plain(value: Any) -> Any:
    """A swept value as a table cell: numbers and strings as they are, others as JSON."""
    if isinstance(value, (int, float, str, bool)):
        return value
    return _json_value(value)
