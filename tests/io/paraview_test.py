"""The ParaView test (ctest jelly_paraview): records each seed scene and two scenes of several
bodies (two cubes; a cloth, whose surface is its own) with the jelly program and
checks the recordings in Debian's ParaView (tests/io/paraview_check.py under pvpython, in a
virtual X server for the screenshot). Exit status 77 (ctest: skipped) when pvpython is absent.

    /usr/bin/python3 tests/io/paraview_test.py --jelly build/cli/jelly [--screenshot out.png]
"""
import argparse
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, "..", "..", "scenes")
# Each seed scene, long enough to see its impact, and scenes of several bodies and surfaces (kept
# short: every frame is compared).
RUNS = [("two_jellies", 1.0), ("seed_slope", 1.5), ("seed_elevator", 1.5), ("drop_coulomb", 1.2),
        ("hanging_cloth", 0.5), ("obstacles", 0.5)]
# Written by the test (no scene of scenes/ has obstacles): a cube dropped onto a turned box that
# spins and oscillates, and a sphere.
OBSTACLES = """{
  "bodies": [{"kind": "cube", "name": "jelly", "n": 4, "edge_length": 0.6,
              "origin": [-0.3, 1.4, -0.3]}],
  "terrains": [
    {"kind": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
    {"kind": "box", "center": [0, 0.6, 0], "size": [2, 0.2, 1], "rotation_degrees": [0, 30, 10],
     "angular_velocity_degrees": [0, 90, 0],
     "motion": {"kind": "oscillation", "amplitude": [0.3, 0, 0], "frequency": 1}},
    {"kind": "sphere", "center": [1.5, 0.5, 0], "radius": 0.5}],
  "integrator": {"name": "rk4", "dt": 0.001}, "duration": 1, "output_interval": 0.02
}"""
# What a reader says when it cannot read something: the sidecar must not cause any of these.
COMPLAINT = re.compile(r"ERR\||WARN\||error|warning|skipping|HDF5-DIAG|cannot|failed", re.I)
# What says that the X server, not ParaView, failed (then the check runs again on another display).
X_FAILED = re.compile(r"bad X server connection|Xvfb failed to start|cannot open display")
SKIP = 77


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--jelly", required=True, help="the jelly program")
    parser.add_argument("--screenshot", help="where to save the screenshot (PNG)")
    args = parser.parse_args()
    pvpython = shutil.which("pvpython")
    if pvpython is None:
        print("SKIPPED: ParaView's pvpython is not installed (Debian: apt-get install paraview; "
              "scripts/install-deps.sh installs it)")
        return SKIP
    with tempfile.TemporaryDirectory(prefix="jelly-paraview-") as tmp:
        xdmfs = []
        for scene, seconds in RUNS:
            h5 = os.path.join(tmp, scene + ".h5")
            path = os.path.join(SCENES, scene + ".json")
            if scene == "obstacles":
                path = os.path.join(tmp, scene + ".json")
                with open(path, "w") as out:
                    out.write(OBSTACLES)
            subprocess.run([args.jelly, "run", path, "--duration",
                            str(seconds), "-o", h5, "--quiet"], check=True,
                           stdout=subprocess.DEVNULL)
            # Relative to the working directory below: the sidecar must find its .h5 by itself.
            xdmfs.append(os.path.join("..", scene + ".xdmf"))
        # The first recording's ParaView state (the sidecar is rewritten with it).
        first = os.path.join(tmp, RUNS[0][0] + ".h5")
        subprocess.run([args.jelly, "xdmf", first, "--state", "--overwrite"], check=True,
                       stdout=subprocess.DEVNULL)
        elsewhere = os.path.join(tmp, "elsewhere")
        os.mkdir(elsewhere)
        command = [pvpython, "--force-offscreen-rendering", os.path.join(HERE, "paraview_check.py")]
        command += xdmfs + ["--state", os.path.join("..", RUNS[0][0] + ".paraview.py")]
        xvfb_run = shutil.which("xvfb-run") if args.screenshot else None
        if args.screenshot:
            if xvfb_run is None and not os.environ.get("DISPLAY"):
                print("no screenshot: neither xvfb-run (Debian: xvfb) nor a DISPLAY")
            else:
                command += ["--screenshot", os.path.abspath(args.screenshot)]
        for attempt in range(3):
            run = command
            if xvfb_run and "--screenshot" in command:
                # From a random display number: `xvfb-run -a` alone starts at :99 and races with
                # other users of the machine. -noreset: without it Xvfb resets when ParaView closes
                # its first connection, and ParaView's next one can fail.
                run = [xvfb_run, "-a", "-n", str(random.randint(100, 899)), "-s",
                       "-screen 0 1280x1024x24 -noreset"] + command
            result = subprocess.run(run, cwd=elsewhere, stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT, text=True, timeout=300)
            if result.returncode == 0 or not X_FAILED.search(result.stdout) or attempt == 2:
                break
            print(f"the X server failed (attempt {attempt + 1}), trying another display")
    complaints = [line for line in result.stdout.splitlines()
                  if line.strip() and not line.startswith("paraview_check:") and
                  COMPLAINT.search(line)]
    print(result.stdout, end="")
    for line in complaints:
        print("FAIL: ParaView complained:", line)
    return 1 if result.returncode or complaints else 0


if __name__ == "__main__":
    sys.exit(main())
