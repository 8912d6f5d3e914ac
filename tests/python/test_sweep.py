"""Sweeps on Dask distributed: a LocalCluster of 2 workers gives what a serial loop gives."""

import math
import subprocess
import sys

import numpy as np
import pandas
import pytest
from distributed import Client, LocalCluster

import jelly

PARAMETERS = {"springs.structural.ks": [800, 4000], "integrator.dt": [0.002, 0.008]}


@pytest.fixture(scope="module")
def client():
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as c:
        yield c


def small_scene(scenes):
    return jelly.load_scene(scenes / "drop_coulomb.json", {
        "cube.n": 5, "integrator.name": "explicit_euler", "duration": 0.6})


def test_sweep_equals_a_serial_loop(scenes, tmp_path, client):
    scene = small_scene(scenes)
    table = jelly.sweep(scene, PARAMETERS, client=client, out_dir=tmp_path / "sweep")
    assert list(table.columns) == ["run", *PARAMETERS, *jelly._sweep.SUMMARY_COLUMNS]
    assert len(table) == 4
    assert pandas.read_csv(tmp_path / "sweep" / "summary.csv").shape == table.shape

    for i, point in enumerate(jelly.sweep_points(PARAMETERS)):
        row = table.iloc[i]
        assert [row[p] for p in PARAMETERS] == list(point.values())
        one = scene.with_overrides(point)
        sim = jelly.Simulator(one)
        serial_file = str(tmp_path / f"serial_{i}.h5")
        with jelly.H5Recorder(serial_file, sim, one) as recorder:
            sim.add_observer(recorder)
            report = sim.run_until(0.6)
        assert row["status"] == report.status
        assert row["t_end"] == report.t and row["steps"] == report.steps
        energy = sim.total_energy()
        if math.isfinite(energy):
            assert row["final_energy"] == energy
        if report.status == "diverged":
            assert row["t_diverged"] == report.t
        else:
            assert math.isnan(row["t_diverged"])
        swept, serial = jelly.read_recording(row["file"]), jelly.read_recording(serial_file)
        assert np.array_equal(swept.time, serial.time)
        assert np.array_equal(swept.position, serial.position)
        assert np.array_equal(swept.velocity, serial.velocity)
    # explicit Euler at dt = 0.008 with the stiff springs does not survive
    assert set(table["status"]) == {"completed", "diverged"}


def test_sweep_rejects_a_bad_point_before_running(scenes, tmp_path):
    with pytest.raises(jelly.InputError, match=r"integrator\.dt = -1 is invalid"):
        jelly.sweep(small_scene(scenes), {"integrator.dt": [0.001, -1]}, out_dir=tmp_path)
    with pytest.raises(TypeError, match="must be a list"):
        jelly.sweep(small_scene(scenes), {"integrator.dt": 0.001}, out_dir=tmp_path)


def test_sweep_on_its_own_local_cluster_without_files(scenes):
    table = jelly.sweep(small_scene(scenes), {"springs.shear.kd": [5, 40]}, out_dir=None,
                        n_workers=2)
    assert list(table["status"]) == ["completed", "completed"]
    assert list(table["file"]) == ["", ""]


def test_sweep_over_a_body_s_path(scenes, client):
    # A path into one body of a scene of two: each point changes that body only, and the
    # cluster's runs end where the serial ones do.
    scene = jelly.load_scene(scenes / "two_jellies.json", {"duration": 0.8})  # lands at ~0.65 s
    parameters = {"bodies[0].springs.structural.ks": [300, 900]}
    table = jelly.sweep(scene, parameters, client=client, out_dir=None)
    for i, point in enumerate(jelly.sweep_points(parameters)):
        one = scene.with_overrides(point)
        soft, stiff = one.bodies
        assert soft.springs.structural.ks == point["bodies[0].springs.structural.ks"]
        assert stiff.springs.structural.ks == 5000
        sim = jelly.Simulator(one)
        report = sim.run_until(0.8)
        assert table.iloc[i]["status"] == report.status == "completed"
        assert table.iloc[i]["final_energy"] == sim.total_energy()
    assert table.iloc[0]["final_energy"] != table.iloc[1]["final_energy"]


def test_a_failing_run_keeps_the_other_rows(scenes, tmp_path, client):
    # Run 1 cannot write its file (a directory is in the way): its row says so, naming its
    # parameters; the other runs and summary.csv are kept (issue 38).
    out = tmp_path / "sweep"
    (out / "run_0001.h5").mkdir(parents=True)
    parameters = {"springs.structural.ks": [800, 4000]}
    with pytest.warns(RuntimeWarning, match=r"1 of 2 runs failed"):
        table = jelly.sweep(small_scene(scenes), parameters, client=client, out_dir=out,
                            duration=0.05, overwrite=True)
    assert list(table["status"]) == ["completed", "failed"]
    assert table.iloc[1]["reason"].startswith("run 1 (springs.structural.ks=4000): InputError")
    assert (out / "run_0000.h5").is_file()
    assert pandas.read_csv(out / "summary.csv")["status"].tolist() == ["completed", "failed"]


def test_an_earlier_sweep_s_files_are_kept_unless_overwrite(scenes, tmp_path, client):
    out = tmp_path / "sweep"
    parameters = {"springs.shear.kd": [5, 40]}
    jelly.sweep(small_scene(scenes), parameters, client=client, out_dir=out, duration=0.02)
    summary = (out / "summary.csv").read_bytes()
    with pytest.raises(jelly.InputError, match=r"out_dir = .* holds the files of an earlier "
                                               r"sweep \(summary.csv, run_0000.h5.*overwrite=True"):
        jelly.sweep(small_scene(scenes), parameters, client=client, out_dir=out, duration=0.03)
    assert (out / "summary.csv").read_bytes() == summary
    table = jelly.sweep(small_scene(scenes), parameters, client=client, out_dir=out,
                        duration=0.03, overwrite=True)
    assert list(table["status"]) == ["completed", "completed"]
    assert list(table["t_end"]) == pytest.approx([0.03, 0.03])


def test_sweep_applies_the_run_limits_of_jelly_run(scenes, tmp_path):
    with pytest.raises(jelly.InputError, match=r"integrator\.dt = 1e-06 is invalid: a step "
                                               r"giving at most 1000000000 steps"):
        jelly.sweep(small_scene(scenes), {"integrator.dt": [1e-6]}, out_dir=None,
                    duration=1e4)


UNGUARDED_SCRIPT = """
import jelly
scene = jelly.load_scene({scene!r}, {{"cube.n": 3, "duration": 0.01}})
table = jelly.sweep(scene, {{"springs.structural.ks": [700, 1400]}}, out_dir=None)
print(table)
"""


def test_an_unguarded_script_is_refused_before_any_process_starts(scenes, tmp_path):
    # The README's snippet pasted into a script without `if __name__ == "__main__":` spun for
    # ever, every worker importing the script and sweeping again.
    script = tmp_path / "unguarded.py"
    script.write_text(UNGUARDED_SCRIPT.format(scene=str(scenes / "seed_slope.json")))
    result = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                            timeout=120, cwd=tmp_path)
    assert result.returncode != 0
    assert "if __name__ == \"__main__\":" in result.stderr
    assert f"{script}, line 4" in result.stderr
