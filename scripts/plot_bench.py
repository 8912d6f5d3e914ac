#!/usr/bin/python3
"""Plots of jelly-bench results (the CSV files under out/bench) as PNG files.

    scripts/plot_bench.py [--in out/bench] [--out docs/img]

Writes bench_stability.png (largest stable dt against ks, measured and predicted, log-log),
bench_work_precision.png (error against wall time and against force evaluations) and
bench_speed.png (cost per step against the number of springs) and bench_budget.png (the cost
of a 1/60 s frame against its error, and the stiffest stable ks, per setup and size), for
whichever of the tables stability.csv, accuracy.csv, speed.csv and budget.csv exist.
"""
import argparse
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from bench_page import read_table  # noqa: E402  (the one reader of jelly-bench's CSV files)

# A run that completed, also when its solver missed its own tolerance on some steps.
COMPLETED = ("completed", "completed_with_warnings")


def finite(x):
    return isinstance(x, float) and math.isfinite(x)


def footer(fig, meta):
    text = "jelly %s, %s build, %s, %s cores; %s" % (
        meta.get("jelly_version", "?"), meta.get("build_type", "?"), meta.get("cpu", "?"),
        meta.get("cores", "?"), meta.get("date_utc", "?"))
    if "load_average_start" in meta:
        text += "; load average %s at the start, %s at the end" % (
            meta["load_average_start"], meta.get("load_average_end", "?"))
    fig.text(0.01, 0.005, text, fontsize=6, color="0.4")


def plot_stability(rows, meta, out):
    scenes = sorted({r["scene"] for r in rows})
    fig, axes = plt.subplots(1, len(scenes), figsize=(5 * len(scenes), 4), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        names = sorted({r["integrator"] for r in rows if r["scene"] == scene})
        for i, name in enumerate(names):
            sel = sorted((r for r in rows if r["scene"] == scene and r["integrator"] == name),
                         key=lambda r: r["ks"])
            color = "C%d" % i
            ks = [r["ks"] for r in sel if finite(r["dt_stable"])]
            dt = [r["dt_stable"] for r in sel if finite(r["dt_stable"])]
            if ks:
                ax.loglog(ks, dt, "o-", color=color, label=name + " measured (stable)")
                ku = [r["ks"] for r in sel if finite(r["dt_unstable"])]
                du = [r["dt_unstable"] for r in sel if finite(r["dt_unstable"])]
                ax.loglog(ku, du, "v", color=color, alpha=0.5, markersize=4)
            kp = [r["ks"] for r in sel if finite(r["dt_predicted"]) and r["dt_predicted"] > 0]
            dp = [r["dt_predicted"] for r in sel if finite(r["dt_predicted"]) and r["dt_predicted"] > 0]
            if kp:
                ax.loglog(kp, dp, "--", color=color, alpha=0.7, label=name + " predicted")
        contact = rows[0].get("contact", "")
        ax.set_title("%s (%s contact, n = %d, %g s); triangles: smallest unstable dt" %
                     (scene, contact, rows[0]["n"], rows[0]["horizon"]), fontsize=8)
        ax.set_xlabel("ks (N/m), kd = ratio x ks")
        ax.set_ylabel("largest stable dt (s)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6)
    footer(fig, meta)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(out, dpi=80)
    plt.close(fig)


def plot_work_precision(rows, meta, out):
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    names = sorted({r["integrator"] for r in rows})
    for i, name in enumerate(names):
        sel = [r for r in rows if r["integrator"] == name and r["status"] in COMPLETED
               and finite(r["error"]) and r["error"] > 0]
        sel.sort(key=lambda r: r["dt"])
        if not sel:
            continue
        err = [r["error"] for r in sel]
        axes[0].loglog([r["wall_seconds"] for r in sel], err, "o-", color="C%d" % i, label=name)
        axes[1].loglog([r["force_evaluations"] for r in sel], err, "o-", color="C%d" % i,
                       label=name)
    axes[0].set_xlabel("wall time (s, indicative: shared CPU)")
    axes[1].set_xlabel("force evaluations")
    for ax in axes:
        ax.set_ylabel("RMS position error at t_end (m)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    n = rows[0]["n"] if rows else 0
    fig.suptitle("work-precision: free spinning jelly, n = %d, t_end = %g s" %
                 (n, rows[0]["t_end"] if rows else 0), fontsize=9)
    footer(fig, meta)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(out, dpi=80)
    plt.close(fig)


def plot_speed(rows, meta, out):
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    # One line per integrator, and per thread count when the run has several (--threads 1,2).
    counts = sorted({r.get("threads", 1) for r in rows})
    keys = sorted({(r["integrator"], r.get("threads", 1)) for r in rows})
    names = sorted({k[0] for k in keys})
    for name, threads in keys:
        i = names.index(name)
        sel = sorted((r for r in rows if r["integrator"] == name and r.get("threads", 1) == threads
                      and r["status"] in COMPLETED), key=lambda r: r["springs"])
        if not sel:
            continue
        label = name if len(counts) == 1 else "%s, %d threads" % (name, threads)
        style = "o-" if threads == counts[0] else "s--"
        springs = [r["springs"] for r in sel]
        axes[0].loglog(springs, [r["step_seconds"] for r in sel], style, color="C%d" % i,
                       label=label)
        axes[1].semilogx(springs, [r["springs_per_second"] / 1e6 for r in sel], style,
                         color="C%d" % i, label=label)
    axes[0].set_ylabel("seconds per step (indicative: shared CPU)")
    axes[1].set_ylabel("force kernel: million springs per second")
    for ax in axes:
        ax.set_xlabel("springs")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("cost per step on the seed slope, dt = %g s" % (rows[0]["dt"] if rows else 0),
                 fontsize=9)
    footer(fig, meta)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(out, dpi=80)
    plt.close(fig)


def plot_budget(rows, meta, out):
    """Cost of a 1/60 s frame against the error to the RK4 reference, and the stiffest stable ks."""
    def what(r):  # ("cube", n) or ("cloth", n); tables before the cloth have cubes only
        return (r.get("scene", "cube"), int(r["n"]))

    def name(w):
        return "cube n = %d" % w[1] if w[0] == "cube" else "cloth %d x %d" % (w[1], w[1])
    sizes = sorted({what(r) for r in rows}, key=lambda w: (w[0] != "cube", w[1]))
    setups = []
    for r in rows:  # in the table's order
        if r["setup"] not in setups:
            setups.append(r["setup"])
    markers = "os^Dv<>p"
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    labelled = set()
    for i, setup in enumerate(setups):
        for j, n in enumerate(sizes):
            sel = [r for r in rows if r["setup"] == setup and what(r) == n
                   and r["status"] in COMPLETED and finite(r["frame_seconds_mean"])
                   and finite(r["error_max"]) and r["error_max"] > 0]  # 0: the reference
            for r in sel:
                axes[0].loglog(r["frame_seconds_mean"] * 1e3, max(r["error_max"], 1e-9),
                               markers[j % len(markers)], color="C%d" % (i % 10),
                               label=None if setup in labelled else setup)
                labelled.add(setup)
    budget_ms = 1e3 / 60
    axes[0].axvline(budget_ms, color="0.3", linestyle="--", linewidth=1)
    axes[0].text(budget_ms * 1.05, axes[0].get_ylim()[0] * 1.5, "1/60 s", fontsize=7, color="0.3")
    axes[0].set_xlabel("wall time of a 1/60 s frame (ms, mean over the run; indicative: shared CPU)")
    axes[0].set_ylabel("largest RMS particle distance to RK4 (m)")
    axes[0].set_title("cost and error; markers: " + ", ".join(
        "%s %s" % (markers[j % len(markers)], name(n)) for j, n in enumerate(sizes)), fontsize=8)
    # The stiffest ks of the ladder each setup keeps stable at its steps per frame.
    cubes = [w for w in sizes if w[0] == "cube"]  # the cloth searches no ks ladder
    width = 0.8 / max(len(cubes), 1)
    for j, n in enumerate(cubes):
        ks = []
        for setup in setups:
            sel = [r for r in rows if r["setup"] == setup and what(r) == n]
            value = sel[0]["stiffest_ks"] if sel else float("nan")
            ks.append(value if finite(value) and value > 0 else float("nan"))
        axes[1].bar([k + (j - (len(cubes) - 1) / 2) * width for k in range(len(setups))], ks,
                    width=width, label=name(n))
    axes[1].set_yscale("log")
    axes[1].set_xticks(range(len(setups)))
    axes[1].set_xticklabels(setups, rotation=45, ha="right", fontsize=7)
    axes[1].set_ylabel("stiffest stable ks of the ladder (N/m)")
    axes[1].set_title("stiffness kept stable at the setup's steps per frame (missing: not searched)",
                      fontsize=8)
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6)
    fig.suptitle("which integrator for a 1/60 s frame: the seed cube falling onto the seed slope "
                 "(coulomb contact)" + (", the cloth over its sphere" if len(cubes) < len(sizes)
                                        else ""), fontsize=9)
    footer(fig, meta)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(out, dpi=80)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--in", dest="input", default="out/bench", help="directory of the CSVs")
    parser.add_argument("--out", default="docs/img", help="directory for the PNG files")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    jobs = [("stability.csv", plot_stability, "bench_stability.png"),
            ("accuracy.csv", plot_work_precision, "bench_work_precision.png"),
            ("speed.csv", plot_speed, "bench_speed.png"),
            ("budget.csv", plot_budget, "bench_budget.png")]
    written = 0
    for table, plot, png in jobs:
        path = os.path.join(args.input, table)
        if not os.path.exists(path):
            print("skipped %s: no %s" % (png, path))
            continue
        rows, meta = read_table(path)
        plot(rows, meta, os.path.join(args.out, png))
        print("wrote " + os.path.join(args.out, png))
        written += 1
    if written == 0:
        sys.exit("no jelly-bench table found in " + args.input)


if __name__ == "__main__":
    main()
