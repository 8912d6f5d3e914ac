#!/usr/bin/env python3
"""Peak resident memory of `jelly run` against the run-limit estimate, per integrator and body.

Runs each integrator on cubes (n = 20, 40), a cloth and a tetrahedral body (a TetGen grid written
to a temporary folder) for three steps without a recording, reads the peak resident size from
`/usr/bin/time -f %M`, and the estimate from the message `jelly run` gives with max_particles = 1.
Prints a Markdown table; with --out DIR it also writes DIR/memory_estimate/table.csv (one row
per integrator, a column "peak / estimate (MB)" per case, with the date, machine and load:
scripts/bench_csv.py), which scripts/bench_page.py renders into docs/scenes.md ("How close the
memory estimate is").

  scripts/memory_figures.py --jelly build/cli/jelly [--integrators rk4,xpbd] [--cases cube20]
                            [--out docs/bench]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_csv import MeasuredTable  # noqa: E402
INTEGRATORS = ["explicit_euler", "symplectic_euler", "midpoint", "rk4", "xpbd", "arkode_erk",
               "implicit_euler", "projective_dynamics", "arkode_dirk"]


def write_tet_grid(k, stem):
    """A TetGen .node/.ele of a k^3 grid of cubes of 5 cm, each split into 6 tetrahedra."""
    h = 0.05

    def index(i, j, l):
        return (i * (k + 1) + j) * (k + 1) + l

    with open(stem + ".node", "w") as f:
        f.write(f"{(k + 1) ** 3} 3 0 0\n")
        for i in range(k + 1):
            for j in range(k + 1):
                for l in range(k + 1):
                    f.write(f"{index(i, j, l)} {i * h} {j * h} {l * h}\n")
    tets = []
    for i in range(k):
        for j in range(k):
            for l in range(k):
                v = [index(i + a, j + b, l + c) for a in (0, 1) for b in (0, 1) for c in (0, 1)]
                for p, q in ((1, 3), (1, 5), (2, 3), (2, 6), (4, 5), (4, 6)):
                    tets.append((v[0], v[p], v[q], v[7]))
    with open(stem + ".ele", "w") as f:
        f.write(f"{len(tets)} 4 0\n")
        for t, tet in enumerate(tets):
            f.write(f"{t} {tet[0]} {tet[1]} {tet[2]} {tet[3]}\n")


def cases(folder):
    slope = os.path.join(ROOT, "scenes", "seed_slope.json")
    cloth = os.path.join(ROOT, "scenes", "hanging_cloth.json")
    out = {
        "cube20": (slope, ["--set", "cube.n=20"]),
        "cube40": (slope, ["--set", "cube.n=40"]),
        "cloth200": (cloth, ["--set", "bodies[0].nu=200", "--set", "bodies[0].nv=200"]),
    }
    for k in (20, 40):
        stem = os.path.join(folder, f"tet{k}")
        write_tet_grid(k, stem)
        scene = os.path.join(folder, f"tet{k}.json")
        with open(scene, "w") as f:
            f.write('{"bodies": [{"kind": "tetmesh", "name": "tet", "file": "tet%d.node",'
                    ' "position": [0, 2, 0], "density": 1000,'
                    ' "springs": {"structural": {"ks": 2000, "kd": 5}}}],'
                    ' "gravity": [0, -9.8, 0], "terrains": [],'
                    ' "integrator": {"name": "rk4", "dt": 0.001}, "duration": 1}' % k)
        out[f"tet{k}"] = (scene, [])
    return out


# The column headings of the table --out writes.
CASE_NAMES = {"cube20": "cube n = 20", "cube40": "cube n = 40", "cloth200": "cloth 200 x 200",
              "tet20": "tet mesh 20^3", "tet40": "tet mesh 40^3"}


def estimate(jelly, scene, extra, integrator):
    r = subprocess.run([jelly, "run", scene, "-q", "--integrator", integrator,
                        "--set", "max_particles=1"] + extra, capture_output=True, text=True)
    m = re.search(r"bodies = (\d+) particles .* about ([\d.]+) (bytes|kB|MB|GB)", r.stderr)
    if not m:
        raise SystemExit(f"no estimate in: {r.stderr}")
    scale = {"bytes": 1, "kB": 1e3, "MB": 1e6, "GB": 1e9}[m.group(3)]
    return int(m.group(1)), float(m.group(2)) * scale


def peak(jelly, scene, extra, integrator):
    r = subprocess.run(["/usr/bin/time", "-f", "%M", jelly, "run", scene, "-q", "--integrator",
                        integrator, "--dt", "0.001", "--duration", "0.003"] + extra,
                       capture_output=True, text=True)
    kib = int(r.stderr.strip().splitlines()[-1])
    return kib * 1024.0, r.returncode


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--jelly", default=os.path.join(ROOT, "build", "cli", "jelly"))
    ap.add_argument("--integrators", default=",".join(INTEGRATORS))
    ap.add_argument("--cases", default="cube20,cube40,cloth200,tet20,tet40")
    ap.add_argument("--out", help="also write OUT/memory_estimate/table.csv")
    args = ap.parse_args()
    print(f"load average: {os.getloadavg()[0]:.1f}", file=sys.stderr)
    version = subprocess.run([args.jelly, "--version"], capture_output=True, text=True)
    table = MeasuredTable(
        "memory_estimate",
        "peak resident size of `jelly run` (3 steps at dt = 1 ms, no recording, /usr/bin/time "
        "-f %M) against the run-limit estimate, MB, each integrator's default options",
        version.stdout.split()[-1] if version.returncode == 0 and version.stdout else None)
    cells = {}
    with tempfile.TemporaryDirectory() as folder:
        all_cases = cases(folder)
        print("| integrator | body | particles | measured peak, MB | estimate, MB | estimate / peak |")
        print("|---|---|---|---|---|---|")
        for name in args.cases.split(","):
            scene, extra = all_cases[name]
            for integrator in args.integrators.split(","):
                n, est = estimate(args.jelly, scene, extra, integrator)
                measured, rc = peak(args.jelly, scene, extra, integrator)
                note = "" if rc == 0 else f" (exit {rc})"
                cells[(integrator, name)] = f"{measured / 1e6:.0f}{note} / {est / 1e6:.0f}"
                print(f"| {integrator} | {name} | {n} | {measured / 1e6:.0f}{note} | "
                      f"{est / 1e6:.0f} | {est / measured:.2f} |", flush=True)
    print(f"load average: {os.getloadavg()[0]:.1f}", file=sys.stderr)
    if args.out:
        names = args.cases.split(",")
        header = ["integrator"] + [f"{CASE_NAMES.get(n, n)}: peak / estimate (MB)"
                                   for n in names]
        rows = [[f"`{i}`"] + [cells[(i, n)] for n in names]
                for i in args.integrators.split(",")]
        print(table.write(args.out, header, rows), file=sys.stderr)


if __name__ == "__main__":
    main()
