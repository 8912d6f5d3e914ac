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
    assert (tmp_path / "p.png").exists()
    # Still in free flight at 0.5 s: dv_z/dt = c (w - v_z) / m gives the drift
    # w (t - (1 - exp(-c t / m)) m / c) (c = 0.5 N s/m, w = 3 m/s, m = 1 kg): 0.172805 m.
    c, w, m, t = 0.5, 3.0, 1.0, 0.5
    exact = w * (t - (1 - math.exp(-c * t / m)) * m / c)
    # Backward Euler at dt = 0.01 on the same equation: v <- (v + h c w / m) / (1 + h c / m).
    backward, v, h = 0.0, 0.0, 0.01
    for _ in range(50):
        v = (v + h * c * w / m) / (1 + h * c / m)
        backward += h * v
    for integrator, expected, tolerance in (("rk4", exact, 1e-5),
                                             ("implicit_euler", backward, 1e-8)):
        line = next(l for l in out.splitlines() if l.startswith(f"{integrator}: drift"))
        python = float(line.split("Python force ")[1].split()[0])
        scene = float(line.split("scene force ")[1].split()[0])
        # The force written in Python acts inside the solver like the scene's own wind.
        assert abs(python - scene) < 1e-9, line
        assert abs(scene - expected) < tolerance, line
    assert "note:" not in out  # the Jacobian was given: nothing treated explicitly


def test_fit_recording(tmp_path):
    out = run("fit_recording.py", "--out", str(tmp_path), cwd=tmp_path)
    assert "ks: 1000.0" in out and (tmp_path / "fitted.json").exists()


def test_stable_dt_sweep(tmp_path):
    out = run("stable_dt_sweep.py", "--quick", "--workers", "2", "--out", str(tmp_path),
              cwd=tmp_path)
    assert "largest stable dt" in out
    assert (tmp_path / "stable_dt.png").exists() and (tmp_path / "stable_dt.csv").exists()


def test_throw_with_pin(tmp_path):
    out = run("throw_with_pin.py", "--iterations", "40", cwd=tmp_path)
    line = next(l for l in out.splitlines() if l.startswith("miss distance"))
    held = float(line.split("held still ")[1].split()[0])
    optimised = float(line.split("optimised ")[1].split()[0])
    # The exact gradients take L-BFGS-B to a swing that lands the jelly three times closer.
    assert optimised < held / 2.5, line
    assert "allowed 0.15 m" in out
