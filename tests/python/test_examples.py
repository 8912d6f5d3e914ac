"""The Python examples run (small settings) and write what they say."""

import math
import os
import subprocess
import sys


from conftest import SOURCE_DIR

EXAMPLES = SOURCE_DIR / "examples" / "python"


def run(script, *args, cwd):
    done = subprocess.run([sys.executable, str(EXAMPLES / script), *args], cwd=cwd,
                          capture_output=True, text=True, env=dict(os.environ), timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def test_custom_force(tmp_path):
    out = run("custom_force.py", "--seconds", "0.5", "--plot", str(tmp_path / "p.png"),
              cwd=tmp_path)
    assert "drift along z" in out and (tmp_path / "p.png").exists()
    drift = float(out.split("drift along z after 0.5 s: ")[1].split()[0])
    scene_force = float(out.split("drift along z with the scene's wind force: ")[1].split()[0])
    # Still in free flight at 0.5 s: dv_z/dt = c (w - v_z) / m gives the drift
    # w (t - (1 - exp(-c t / m)) m / c) (c = 0.5 N s/m, w = 3 m/s, m = 1 kg): 0.172805 m.
    # The scene's wind force inside RK4 steps meets it closely; the Python impulses before each
    # step (operator splitting) to O(dt).
    c, w, m, t = 0.5, 3.0, 1.0, 0.5
    exact = w * (t - (1 - math.exp(-c * t / m)) * m / c)
    assert abs(scene_force - exact) < 1e-5
    assert abs(drift - exact) < 1e-3


def test_fit_recording(tmp_path):
    out = run("fit_recording.py", "--out", str(tmp_path), cwd=tmp_path)
    assert "ks: 1000.0" in out and (tmp_path / "fitted.json").exists()


def test_stable_dt_sweep(tmp_path):
    out = run("stable_dt_sweep.py", "--quick", "--workers", "2", "--out", str(tmp_path),
              cwd=tmp_path)
    assert "largest stable dt" in out
    assert (tmp_path / "stable_dt.png").exists() and (tmp_path / "stable_dt.csv").exists()
