#!/usr/bin/python3
"""What linking and including jelly costs (docs/CONTRIBUTING.md, "The public API"), as a
Markdown table: the installed headers, the umbrella header's preprocessed lines and compile CPU,
the shared libraries libjelly (the core) and a program of the core alone load, the start-up of
`jelly run` (one step of the seed scene) and of `import jelly`, each in wall time and in CPU
time (user + system: on a busy machine the wall time is mostly waiting for a core). The floors
come last: a file of `#include <Eigen/Core>` alone and `python3 -c pass`, measured the same way
(the same for both trees).

    library_figures.py [--build DIR] [--source DIR] [--before-build DIR --before-source DIR]
                       [--repeat 5]

With --before-*, each timing alternates between the two trees, run by run, so that a busy
machine slows both alike; the table gives the medians and their ratio. The load average while
measuring is printed with the table. Exit status 1 when a measurement could not be made.
"""
import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

UMBRELLA_SOURCE = "#include <jelly/jelly.hpp>\nint main() { return 0; }\n"
EIGEN_SOURCE = "#include <Eigen/Core>\nint main() { return 0; }\n"


class Tree:
    def __init__(self, build, source):
        self.build = os.path.abspath(build)
        self.source = os.path.abspath(source)

    def include_flags(self):
        return ["-I", os.path.join(self.build, "include"), "-I", "/usr/include/eigen3"]

    def public_headers(self):
        listed = os.path.join(self.source, "cmake", "public_headers.txt")
        if os.path.exists(listed):
            with open(listed, encoding="utf-8") as f:
                return sum(1 for line in f if re.match(r"[a-z]", line)) + 2  # + jelly, version
        # Before the list: every header outside detail/ folders of the library's modules.
        count = 2
        for module in ("core", "geometry", "terrain", "solvers", "io", "fit"):
            for folder, dirs, files in os.walk(os.path.join(self.source, module)):
                dirs[:] = [d for d in dirs if d != "detail"]
                count += sum(1 for name in files if name.endswith(".hpp"))
        return count

    def library(self):
        return os.path.join(self.build, "libjelly.so")

    def jelly(self):
        return os.path.join(self.build, "cli", "jelly")


def run(command, **kwargs):
    return subprocess.run(command, check=True, capture_output=True, text=True, **kwargs)


def umbrella_lines(tree, work):
    source = os.path.join(work, "umbrella.cpp")
    with open(source, "w", encoding="utf-8") as f:
        f.write(UMBRELLA_SOURCE)
    out = run(["g++", "-std=c++17", "-E", *tree.include_flags(), source]).stdout
    nlohmann = len(re.findall(r'^# 1 "/usr/include/nlohmann/', out, re.M))
    return out.count("\n"), nlohmann


def children_cpu():
    """CPU seconds (user + system) of the finished child processes, to the microsecond
    (os.times() counts clock ticks of 10 ms)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed(command, **kwargs):
    """Runs command; (wall seconds, CPU seconds: user + system of the child)."""
    before = children_cpu()
    start = time.perf_counter()
    run(command, **kwargs)
    wall = time.perf_counter() - start
    return wall, children_cpu() - before


def umbrella_cpu(tree, work):
    """CPU seconds (user + system) of `g++ -O2 -c` of a file that includes the umbrella."""
    source = os.path.join(work, "umbrella.cpp")
    return timed(["g++", "-std=c++17", "-O2", "-c", *tree.include_flags(), source, "-o",
                  os.path.join(work, "umbrella.o")])[1]


def eigen_core_cpu(tree, work):
    """The floor of umbrella_cpu: a file of `#include <Eigen/Core>` alone."""
    source = os.path.join(work, "eigen_core.cpp")
    with open(source, "w", encoding="utf-8") as f:
        f.write(EIGEN_SOURCE)
    return timed(["g++", "-std=c++17", "-O2", "-c", *tree.include_flags(), source, "-o",
                  os.path.join(work, "eigen_core.o")])[1]


def linked_libraries(path):
    out = run(["ldd", path]).stdout
    return sum(1 for line in out.splitlines() if line.strip())


CORE_PROGRAM = ("#include <jelly/solvers/integrators/registry.hpp>\n"
                "int main() { return jelly::integrator_names().empty(); }\n")


def core_program_libraries(tree, work):
    """Shared libraries (ldd lines) of a program that calls the core alone (an integrator name
    list), linked against the tree's libjelly: since the components, the core library."""
    source = os.path.join(work, "core_program.cpp")
    program = os.path.join(work, "core_program")
    with open(source, "w", encoding="utf-8") as f:
        f.write(CORE_PROGRAM)
    run(["g++", "-std=c++17", *tree.include_flags(), source, "-o", program, "-L", tree.build,
         "-ljelly", "-Wl,-rpath," + tree.build])
    return linked_libraries(program)


def run_one_step(tree, work):
    scene = os.path.join(tree.source, "scenes", "seed_slope.json")
    # The tree's own libjelly, also for a program copied from another build tree.
    env = dict(os.environ, LD_LIBRARY_PATH=tree.build)
    return timed([tree.jelly(), "run", scene, "--duration", "0.001", "-o",
                  os.path.join(work, "one.h5"), "--overwrite"], env=env)


def import_jelly(tree, work):
    env = dict(os.environ, PYTHONPATH=os.path.join(tree.build, "python"),
               LD_LIBRARY_PATH=tree.build)
    return timed([sys.executable, "-c", "import jelly"], env=env, cwd=work)


def python_alone(tree, work):
    """The floor of import_jelly: the interpreter's own start-up."""
    return timed([sys.executable, "-c", "pass"], cwd=work)


def alternate(measures, trees, work, repeat):
    """{name: [median per tree]} for each timing, the trees taking turns run by run. A measure
    with a tuple of names gives a tuple of values (wall and CPU of one run)."""
    results = {}
    for names, _ in measures:
        for name in names if isinstance(names, tuple) else (names,):
            results[name] = [[] for _ in trees]
    for _ in range(repeat):
        for names, measure in measures:
            for index, tree in enumerate(trees):
                values = measure(tree, work)
                if isinstance(names, tuple):
                    pairs = zip(names, values)
                else:
                    pairs = [(names, values)]
                for name, value in pairs:
                    results[name][index].append(value)
    return {name: [statistics.median(v) for v in values] for name, values in results.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    parser.add_argument("--build", default=os.path.join(here, "build"))
    parser.add_argument("--source", default=here)
    parser.add_argument("--before-build")
    parser.add_argument("--before-source")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    if bool(args.before_build) != bool(args.before_source):
        parser.error("--before-build and --before-source go together")
    if args.repeat < 1:
        parser.error(f"--repeat = {args.repeat} is invalid: at least 1")
    trees = [Tree(args.build, args.source)]
    names = ["this tree"]
    if args.before_build:
        trees.insert(0, Tree(args.before_build, args.before_source))
        names.insert(0, "before")

    with tempfile.TemporaryDirectory(prefix="jelly_figures_") as work:
        try:
            rows = [("installed headers", [str(t.public_headers()) for t in trees])]
            lines = [umbrella_lines(t, work) for t in trees]
            rows.append(("umbrella: preprocessed lines", [str(n) for n, _ in lines]))
            rows.append(("umbrella: nlohmann headers included", [str(k) for _, k in lines]))
            rows.append(("libjelly.so: shared libraries loaded (ldd)",
                         [str(linked_libraries(t.library())) for t in trees]))
            rows.append(("a program of the core alone: shared libraries loaded (ldd)",
                         [str(core_program_libraries(t, work)) for t in trees]))
            timings = [("umbrella: compile CPU (g++ -O2), s", umbrella_cpu),
                       (("jelly run, 1 step of the seed slope: wall, s",
                         "jelly run, 1 step of the seed slope: CPU, s"), run_one_step)]
            if all(os.path.isdir(os.path.join(t.build, "python", "jelly")) for t in trees):
                timings.append((("python3 -c 'import jelly': wall, s",
                                 "python3 -c 'import jelly': CPU, s"), import_jelly))
            timings.append(("floor: #include <Eigen/Core> alone: compile CPU (g++ -O2), s",
                            eigen_core_cpu))
            timings.append((("floor: python3 -c pass: wall, s", "floor: python3 -c pass: CPU, s"),
                            python_alone))
            medians = alternate(timings, trees, work, args.repeat)
        except (subprocess.CalledProcessError, OSError) as e:
            detail = getattr(e, "stderr", "") or ""
            print(f"library_figures: a measurement failed: {e}\n{detail}", file=sys.stderr)
            return 1
    for name, values in medians.items():
        digits = 4 if ": CPU, s" in name else 3
        rows.append((name + f" (median of {args.repeat})", [f"{v:.{digits}f}" for v in values]))

    header = ["", *names] + (["ratio"] if len(trees) == 2 else [])
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for name, values in rows:
        ratio = []
        if len(values) == 2:
            a, b = float(values[0]), float(values[1])
            ratio = [f"{b / a:.2f}" if a else "-"]
        print("| " + " | ".join([name, *values, *ratio]) + " |")
    print(f"\nLoad average while measuring: {os.getloadavg()[0]:.1f} ({os.cpu_count()} cores).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
