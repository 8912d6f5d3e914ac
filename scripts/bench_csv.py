"""Writes a measured table as a CSV file with the metadata jelly-bench writes (`# key: value`
lines: the command, start and end dates, CPU, cores, load average at the start and at the end,
jelly's version), so that scripts/bench_page.py renders it into the documentation with the
machine and date taken from the file, never from prose.

    table = MeasuredTable("python_step", "what the rows are")
    ... measure ...
    table.write("docs/bench", ["case", "best", "median"], rows)  # docs/bench/python_step/table.csv

Every cell is written as text exactly as it should appear in the page (units included).
"""
import csv
import datetime
import os
import platform
import sys


def _now():
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def _load():
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def _cpu():
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.partition(":")[2].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def command_line():
    """The command as a reader runs it from the source tree: the module's PYTHONPATH, Debian's
    python3 and the script's path relative to the current folder."""
    script = os.path.relpath(os.path.abspath(sys.argv[0]))
    words = ["/usr/bin/python3", script] + sys.argv[1:]
    if os.environ.get("PYTHONPATH"):
        words.insert(0, "PYTHONPATH=" + os.environ["PYTHONPATH"])
    return " ".join(words)


class MeasuredTable:
    """One table: its start (date, load) is taken when it is made, its end when written."""

    def __init__(self, name, description, version=None):
        self.name, self.description, self.version = name, description, version
        self.start, self.load_start = _now(), _load()

    def write(self, folder, header, rows):
        """Writes FOLDER/NAME/table.csv; returns its path."""
        meta = {
            "command_line": command_line(),
            "cores": str(len(os.sched_getaffinity(0))),
            "cpu": _cpu(),
            "date_utc": self.start,
            "date_utc_end": _now(),
            "hardware_cores": str(os.cpu_count()),
            "load_average_end": _load(),
            "load_average_start": self.load_start,
            "python": platform.python_version(),
            "table": self.name,
        }
        if self.version:
            meta["jelly_version"] = self.version
        meta["description"] = self.description
        meta["types"] = ",".join("s" for _ in header)
        path = os.path.join(folder, self.name, "table.csv")
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w", newline="", encoding="utf-8") as f:
            for key, value in meta.items():
                f.write(f"# {key}: {value}\n")
            writer = csv.writer(f, lineterminator="\n")
            writer.writerow(header)
            writer.writerows(rows)
        return path
