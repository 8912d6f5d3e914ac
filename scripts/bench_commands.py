#!/usr/bin/python3
"""Times documented commands (a `jelly run` per setup and case) in alternation and writes the
table the documentation shows, with the date, machine and load (scripts/bench_csv.py), for
scripts/bench_page.py to render.

    scripts/bench_commands.py docs/bench/NAME/spec.json [--rounds N] [--build DIR]

spec.json says what to run (commands run from the source tree, `jelly` is BUILD/cli/jelly):

    {"description": "what a cell is (e.g. mean wall time per 1/60 s frame)",
     "divide": 60, "unit": "ms", "rounds": 3,
     "columns": ["n = 20 cube", "64 x 64 cloth"],
     "rows": [{"label": "`jacobi`, 3 substeps x 2 sweeps", "commands": ["jelly run ...", "..."]}]}

Each round runs every row's command of every column once, in order, so that a change of load
hits every setup alike; a cell is each round's wall time divided by `divide`, in `unit`, then
the median. A command that fails stops the script (exit 1). Writes
docs/bench/NAME/table.csv beside the spec.
"""
import argparse
import json
import os
import shlex
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_csv import MeasuredTable  # noqa: E402

SCALE = {"s": 1.0, "ms": 1e3, "us": 1e6}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("spec")
    parser.add_argument("--rounds", type=int, default=None)
    parser.add_argument("--build", default="build")
    args = parser.parse_args()
    with open(args.spec, encoding="utf-8") as f:
        spec = json.load(f)
    source = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    jelly = os.path.join(os.path.abspath(args.build), "cli", "jelly")
    if not os.access(jelly, os.X_OK):
        print(f"bench_commands: {jelly} is not built", file=sys.stderr)
        return 2
    rounds = args.rounds or spec.get("rounds", 3)
    scale, divide = SCALE[spec.get("unit", "s")], spec.get("divide", 1)
    folder = os.path.dirname(os.path.abspath(args.spec))
    result = subprocess.run([jelly, "--version"], stdout=subprocess.PIPE, text=True)
    version = result.stdout.split()[-1] if result.returncode == 0 and result.stdout else None
    table = MeasuredTable(os.path.basename(folder), spec["description"], version)
    times = {(r, c): [] for r in range(len(spec["rows"])) for c in range(len(spec["columns"]))}
    for _ in range(rounds):
        for r, row in enumerate(spec["rows"]):
            for c, command in enumerate(row["commands"]):
                words = shlex.split(command)
                if words[0] == "jelly":
                    words[0] = jelly
                start = time.perf_counter()
                result = subprocess.run(words, cwd=source, stdout=subprocess.DEVNULL,
                                        stderr=subprocess.PIPE, text=True)
                elapsed = time.perf_counter() - start
                if result.returncode != 0:
                    print(f"bench_commands: `{command}` exited {result.returncode}:\n"
                          f"{result.stderr[-2000:]}", file=sys.stderr)
                    return 1
                times[(r, c)].append(elapsed / divide * scale)
                print(f"{row['label']} | {spec['columns'][c]}: {times[(r, c)][-1]:.3g} "
                      f"{spec.get('unit', 's')}", flush=True)
    unit = spec.get("unit", "s")
    rows = []
    for r, row in enumerate(spec["rows"]):
        cells = [row["label"]]
        for c in range(len(spec["columns"])):
            values = times[(r, c)]
            cells.append(" / ".join(f"{v:.3g}" for v in values)
                         + f" (median {statistics.median(values):.3g} {unit})")
        rows.append(cells)
    header = ["setup"] + [f"{name}, {unit} (each round)" for name in spec["columns"]]
    path = table.write(os.path.dirname(folder), header, rows)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
