"""Fitting from Python: fit_recording with jelly fit's options gives jelly fit's result."""

import re

import pytest

import jelly


def make_recording(scenes, path):
    scene = jelly.load_scene(scenes / "drop_coulomb.json", {
        "cube.n": 3, "cube.origin": [-1, 0.3, -1], "integrator.name": "rk4",
        "output_interval": 0.01, "duration": 0.5,
        "springs.structural": {"ks": 1000, "kd": 20}, "springs.shear": {"ks": 1000, "kd": 20},
        "springs.bending": {"ks": 1000, "kd": 20}})
    sim = jelly.Simulator(scene)
    with jelly.H5Recorder(str(path), sim, scene) as recorder:
        sim.add_observer(recorder)
        assert sim.run_until(scene.duration).ok
    return scene


def estimates(report):
    """The lines of a fit report that do not depend on wall time."""
    return [line for line in report.splitlines() if "wall" not in line and "time" not in line
            and not re.search(r"\d+\.\d+ s\b", line)]


def test_fit_recovers_the_coefficients_like_jelly_fit(scenes, tmp_path, run_cli):
    make_recording(scenes, tmp_path / "run.h5")
    result = jelly.fit_recording(tmp_path / "run.h5", initial={"ks": 1400, "kd": 30},
                                 write_scene=tmp_path / "fitted.json")
    assert result.converged
    assert result.at("ks").value == pytest.approx(1000, rel=1e-2)
    assert result.values()["kd"] == pytest.approx(20, rel=1e-2)
    assert [p.name for p in result.parameters] == ["ks", "kd"]
    fitted = jelly.load_scene(tmp_path / "fitted.json")
    assert fitted.bodies[0].springs.shear.ks == pytest.approx(1000, rel=1e-2)

    done = run_cli("fit", tmp_path / "run.h5", "--initial", "ks=1400", "--initial", "kd=30",
                   "--write-scene", tmp_path / "cli.json")
    assert done.returncode == 0, done.stderr
    assert estimates(done.stdout)[:3] == estimates(str(result))[:3]
    assert jelly.load_scene(tmp_path / "cli.json") == fitted


def test_fit_options_are_validated(scenes, tmp_path):
    make_recording(scenes, tmp_path / "run.h5")
    recording = jelly.read_recording(str(tmp_path / "run.h5"))
    with pytest.raises(jelly.InputError, match="free"):
        jelly.fit_recording(recording, free="ks,ks.shear")
    with pytest.raises(jelly.InputError, match=r"initial\.kd"):
        jelly.fit_recording(recording, free="ks", initial={"kd": 3})
    with pytest.raises(TypeError, match="unknown option 'windw'"):
        jelly.fit_recording(recording, windw=0.2)
    options = jelly.FitOptions()
    options.free = "ks.structural,kd"
    options.window = 0.25
    options.compute_covariance = False
    result = jelly.fit_recording(recording, options, max_iterations=3)
    assert [p.name for p in result.parameters] == ["ks.structural", "kd"]
    assert result.iterations <= 3 and result.windows == 2
    assert jelly.parse_free_parameters("ks.shear,kd") == ["ks.shear", "kd"]


def test_write_scene_is_never_the_recording(scenes, tmp_path):
    """Issue 44, item 9: as jelly fit --write-scene, write_scene naming the recording (also
    through a link) is refused before the fit and the recording is untouched (before: the fitted
    scene was written over it)."""
    make_recording(scenes, tmp_path / "run.h5")
    before = (tmp_path / "run.h5").read_bytes()
    (tmp_path / "link.json").symlink_to(tmp_path / "run.h5")
    for recording in (tmp_path / "run.h5", jelly.read_recording(str(tmp_path / "run.h5"))):
        for target in (tmp_path / "run.h5", tmp_path / "link.json"):
            with pytest.raises(jelly.InputError, match=r"is the recording .*run\.h5.*same file"):
                jelly.fit_recording(recording, write_scene=target, max_iterations=1)
    assert (tmp_path / "run.h5").read_bytes() == before


def test_fit_takes_the_adjoint_path_for_implicit_euler(scenes, tmp_path):
    """An implicit_euler recording: the exact gradients by default, the path named; numeric on
    request, with the reason; a bad name for gradients is an InputError."""
    scene = jelly.load_scene(scenes / "drop_coulomb.json", {
        "cube.n": 3, "cube.origin": [-1, 0.3, -1], "integrator.name": "implicit_euler",
        "integrator.dt": 0.005, "output_interval": 0.01, "duration": 0.5,
        "springs.structural": {"ks": 1000, "kd": 20}, "springs.shear": {"ks": 1000, "kd": 20},
        "springs.bending": {"ks": 1000, "kd": 20}})
    sim = jelly.Simulator(scene)
    with jelly.H5Recorder(str(tmp_path / "ie.h5"), sim, scene) as recorder:
        sim.add_observer(recorder)
        assert sim.run_until(scene.duration).ok
    result = jelly.fit_recording(tmp_path / "ie.h5", initial={"ks": 1400, "kd": 30},
                                 compute_covariance=False)
    assert result.gradient_path == "adjoint" and result.adjoint_passes > 0
    assert "derivatives: adjoint" in str(result)
    assert result.at("ks").value == pytest.approx(1000, rel=1e-2)
    numeric = jelly.fit_recording(tmp_path / "ie.h5", initial={"ks": 1400, "kd": 30},
                                  compute_covariance=False, gradients="numeric", max_iterations=1)
    assert numeric.gradient_path == "numeric"
    assert numeric.gradient_reason == "asked for (gradients = numeric)"
    with pytest.raises(jelly.InputError, match="gradients = exact is invalid"):
        jelly.fit_recording(tmp_path / "ie.h5", gradients="exact")
