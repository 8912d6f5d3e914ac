#!/usr/bin/env python3
"""The largest stable time step of each explicit integrator against the spring stiffness ks,
measured by a parameter sweep on Dask (jelly.sweep), plotted like jelly-bench stability.

A jelly (5 x 5 x 5 particles) is dropped onto a floor with Coulomb contact and simulated for
1 s with every combination of integrator, ks (all spring types, kd = 0.02 ks) and dt. A
(integrator, ks) pair is stable at dt when the run completes; the largest stable dt is the
largest dt below which every run completed.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/stable_dt_sweep.py [--quick]
        [--out out/stable_dt] [--workers 2] [--scheduler tcp://host:8786]
"""

import argparse
import math
import os
import pathlib

import jelly

HERE = pathlib.Path(__file__).resolve().parent
SCENE = HERE.parents[1] / "scenes" / "drop_coulomb.json"


def springs(ks):
    """One value of the scene key "springs": every type with stiffness ks, kd = 0.02 ks."""
    one = {"ks": ks, "kd": 0.02 * ks}
    return {"structural": one, "shear": one, "bending": one}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a small grid (a test)")
    parser.add_argument("--out", default="out/stable_dt", help="output folder")
    parser.add_argument("--workers", type=int, default=None, help="LocalCluster workers")
    parser.add_argument("--scheduler", default=None,
                        help="address of a running Dask scheduler (default: a LocalCluster)")
    args = parser.parse_args()

    integrators = ["symplectic_euler", "midpoint", "rk4"]
    ks_values = [250, 1000, 4000, 16000]
    dts = [2.5e-4 * 2 ** (k / 2) for k in range(13)]  # 0.25 ms .. 16 ms
    duration = 1.0
    if args.quick:
        integrators, ks_values, dts, duration = ["symplectic_euler", "rk4"], [500, 8000], \
            [1e-3, 4e-3, 1.6e-2], 0.3

    scene = jelly.load_scene(SCENE, {"cube.n": 5, "duration": duration})
    client = None
    if args.scheduler:
        from distributed import Client
        client = Client(args.scheduler)
    table = jelly.sweep(scene, {"integrator.name": integrators,
                                "springs": [springs(ks) for ks in ks_values],
                                "integrator.dt": dts},
                        client=client, out_dir=None, n_workers=args.workers)
    table["ks"] = [ks for _ in integrators for ks in ks_values for _ in dts]

    os.makedirs(args.out, exist_ok=True)
    rows = []
    for (name, ks), group in table.groupby(["integrator.name", "ks"], sort=False):
        stable = math.nan
        for dt, status in sorted(zip(group["integrator.dt"], group["status"])):
            if status not in ("completed", "completed_with_warnings"):
                break
            stable = dt
        rows.append({"integrator": name, "ks": ks, "dt_stable": stable})
        print(f"{name:18s} ks {ks:8.0f}: largest stable dt {stable:.3g} s")
    import pandas
    summary = pandas.DataFrame(rows)
    summary.to_csv(os.path.join(args.out, "stable_dt.csv"), index=False)
    table.drop(columns=["springs"]).to_csv(os.path.join(args.out, "runs.csv"), index=False)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5, 4))
    for i, name in enumerate(integrators):
        sel = summary[summary["integrator"] == name].dropna()
        ax.loglog(sel["ks"], sel["dt_stable"], "o-", color=f"C{i}", label=name)
    ax.set_xlabel("ks (N/m), kd = 0.02 ks")
    ax.set_ylabel("largest stable dt (s)")
    ax.set_title(f"jelly {jelly.__version__}: n = 5 jelly dropped on a floor, {duration:g} s",
                 fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "stable_dt.png"), dpi=80)
    print(f"written: {args.out}/stable_dt.png, stable_dt.csv, runs.csv")


if __name__ == "__main__":  # required: Dask's worker processes import this file
    main()
