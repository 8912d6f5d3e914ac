#!/usr/bin/env python3
"""Runs the commands that README.md and docs/*.md show, as a reader would (issue 16: docs that
fail).

A command is a line of an indented or fenced shell block, or an inline `code` span, that starts
with a program of the project or one the docs tell readers to run (jelly, jelly-bench, build/...,
scripts/..., /usr/bin/python3, make, cmake, ctest, ...), joined with its continuation lines.
Output and formulas in the same blocks do not start with one and are left alone.

* A synopsis (optional parts in [brackets], placeholders such as SCENE.json or NAME) cannot run
  as written: its program and subcommand are run with --help instead, which must exit 0.
* Every other command runs in a fresh sandbox (a temporary directory with scenes/, scripts/,
  assets/ and examples/ linked from the source tree, build/ linked to the build directory,
  empty out/ and docs/img/, and `jelly` and `jelly-bench` on the PATH) and must exit 0. The
  commands of one file run in order in one sandbox, so that `jelly run ... -o run.h5` followed by
  `jelly fit run.h5` works as it does for a reader; assignments (B=...) carry over.
* tests/docs/doc_commands.txt lists the exceptions, each with its reason: `skip` (a command
  that installs or rebuilds the tree), `timeout N` (a benchmark that runs for minutes: it must
  not fail in its first N seconds), `display N` (a window: run under xvfb-run, the same way),
  `if-installed PROGRAM` (a program jelly does not depend on, such as ParaView's pvpython), and
  `setup FILE.md` (commands run first in that file's sandbox, e.g. to make the recording its
  examples read). An exception that matches no command in the docs is an error too.

Usage: doc_commands.py --source DIR --build DIR [--list | --check-exceptions] [FILE.md ...]
(ctest runs each markdown file as its own test, and --check-exceptions once.)
"""
import argparse
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time

# First words of a command. Environment assignments (OPENBLAS_NUM_THREADS=1 ...) and wrappers
# (taskset -c 1, /usr/bin/time, xvfb-run ...) are looked through.
PROGRAMS = {"jelly", "jelly-bench", "make", "cmake", "ctest", "bash", "/usr/bin/python3",
            "python3", "pvpython", "pvbatch", "for", "$B"}
PROGRAM_PREFIXES = ("build/", "build-", "scripts/", "./build/")
WRAPPERS = {"taskset", "/usr/bin/time", "xvfb-run", "nice", "timeout"}

DEFAULT_TIMEOUT = 300  # s: a documented command that runs longer needs a `timeout N` entry


def first_program(words):
    """The program word of a command line split into words, or None."""
    i = 0
    while i < len(words):
        w = words[i]
        if re.match(r"^[A-Z_][A-Z0-9_]*=", w):  # VAR=value prefix
            i += 1
            continue
        if w in WRAPPERS:
            i += 1
            # the wrapper's own options and their values: taskset -c 1, xvfb-run -a -s "..."
            while i < len(words) and words[i].startswith("-"):
                i += 2 if words[i] in ("-c", "-s", "-f", "-n") else 1
            continue
        return w
    return None


def is_command(text):
    words = split_words(text)
    if not words:
        return False
    if re.match(r"^[A-Z_][A-Z0-9_]*=\S*$", words[0]) and len(words) == 1:
        return True  # B=build/bench/jelly-bench: an assignment for the commands after it
    program = first_program(words)
    if program is None:
        return False
    return program in PROGRAMS or program.startswith(PROGRAM_PREFIXES)


def strip_comment(line):
    """The line without a trailing shell comment (a # after whitespace, outside quotes)."""
    quote = None
    for i, c in enumerate(line):
        if quote:
            if c == quote:
                quote = None
        elif c in "'\"":
            quote = c
        elif c == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].rstrip()
    return line.rstrip()


def normalize(text):
    return " ".join(text.split())


def extract(path):
    """The commands of a markdown file, in order: (line number, text, kind)."""
    lines = open(path, encoding="utf-8").read().split("\n")
    commands = []
    fence = None  # language of the open fenced block
    i = 0
    while i < len(lines):
        line = lines[i]
        stripped = line.strip()
        if stripped.startswith("```"):
            fence = None if fence is not None else (stripped[3:].strip() or "text")
            i += 1
            continue
        in_block = (fence in ("sh", "bash", "shell", "console", "text")) or (
            fence is None and line.startswith("    ") and (i == 0 or lines[i - 1].strip() == ""
                                                        or lines[i - 1].startswith("    ")))
        if fence is not None and not in_block:
            i += 1
            continue
        if in_block:
            text = strip_comment(stripped)
            start = i + 1
            while text.endswith("\\") and i + 1 < len(lines):
                i += 1
                text = text[:-1].rstrip() + " " + strip_comment(lines[i].strip())
            if is_command(text):
                commands.append((start, normalize(text), "block"))
            i += 1
            continue
        # inline `code` spans of prose (not inside a block)
        for span in re.findall(r"`([^`]+)`", line):
            if " " in span.strip() and is_command(span):
                kind = "inline"
                words = span.split()
                # `jelly run`, `jelly run --restart f.h5`, `scripts/animate.py --fps 60`: a
                # subcommand or an option named in prose, not a command to run
                first_argument = 2 if re.match(r"^[a-z][a-z-]*$", words[1]) else 1
                if len(words) <= 2 or (len(words) > first_argument and
                                       words[first_argument].startswith("-")):
                    kind = "mention"
                commands.append((i + 1, normalize(span), kind))
        i += 1
    return commands


PLACEHOLDER = re.compile(r"^[A-Z][A-Z_]*(\.\w+|=[A-Z_]+|\.\.\.)?$")
PIPE_PROGRAMS = {"grep", "head", "tail", "sort", "tee", "wc", "less"}


def is_synopsis(text):
    """Optional parts in [brackets], placeholders (SCENE.json, NAME, PATH=VALUE, out/<scene>.h5)
    or alternatives written a | b: a usage line, not a command."""
    if re.search(r"(^|\s)[\[<]", text) or re.search(r"<[A-Za-z_][\w-]*>", text):
        return True
    words = text.split()
    if any(PLACEHOLDER.match(w) for w in words[1:]):
        return True
    for i, w in enumerate(words[:-1]):
        if w == "|" and words[i + 1] not in PIPE_PROGRAMS:
            return True
    return False


def split_words(text):
    try:
        return shlex.split(text)
    except ValueError:
        return text.split()


def help_command(text):
    """`program [subcommand] --help` for a synopsis."""
    words = split_words(text)
    program_index = 0
    while program_index < len(words) and words[program_index] != first_program(words):
        program_index += 1
    out = words[program_index:program_index + 1]
    if len(words) > program_index + 1 and re.match(r"^[a-z][a-z-]*$", words[program_index + 1]):
        out.append(words[program_index + 1])
    return " ".join(out + ["--help"])


def load_exceptions(path):
    """({normalized command: (action, seconds, reason)}, {file: [setup commands]}) from
    doc_commands.txt."""
    exceptions, setups = {}, {}
    action = None
    for raw in open(path, encoding="utf-8"):
        line = raw.rstrip("\n")
        if not line.strip() or line.lstrip().startswith("#") and not line.startswith("    "):
            continue
        if line.startswith("    "):
            if action is None:
                sys.exit(f"{path}: a command before any 'skip:', 'timeout N:' or 'setup' line")
            if action[0] == "setup":
                setups.setdefault(action[2], []).append(normalize(line))
            else:
                exceptions[normalize(line)] = action
            continue
        m = re.match(r"^(skip|timeout (\d+)|display (\d+)|if-installed (\S+)|setup (\S+)):"
                     r"\s*(.+)$", line)
        if not m:
            sys.exit(f"{path}: cannot read '{line}' (expected 'skip: reason', 'timeout N: "
                     f"reason', 'display N: reason', 'if-installed PROGRAM: reason' or "
                     f"'setup FILE.md: reason', then commands indented by 4 spaces)")
        reason = m.group(6)
        if m.group(5):
            action = ("setup", 0, m.group(5))
        elif m.group(4):
            action = ("if-installed", DEFAULT_TIMEOUT, reason, m.group(4))
        elif m.group(3):
            action = ("display", int(m.group(3)), reason)
        elif m.group(2):
            action = ("timeout", int(m.group(2)), reason)
        else:
            action = ("skip", 0, reason)
    return exceptions, setups


def make_sandbox(source, build):
    root = tempfile.mkdtemp(prefix="jelly-docs-")
    for name in ("scenes", "scripts", "assets", "examples"):
        if os.path.exists(os.path.join(source, name)):
            os.symlink(os.path.join(source, name), os.path.join(root, name))
    os.symlink(build, os.path.join(root, "build"))
    os.makedirs(os.path.join(root, "out"))
    os.makedirs(os.path.join(root, "docs", "img"))
    # The folders benchmarks write their CSV/JSON into (the sandbox's, not the committed ones).
    bench = os.path.join(source, "docs", "bench")
    if os.path.isdir(bench):
        for name in os.listdir(bench):
            if os.path.isdir(os.path.join(bench, name)):
                os.makedirs(os.path.join(root, "docs", "bench", name))
    bin_dir = os.path.join(root, ".bin")
    os.makedirs(bin_dir)
    for name, rel in (("jelly", "cli/jelly"), ("jelly-bench", "bench/jelly-bench")):
        if os.path.exists(os.path.join(build, rel)):
            os.symlink(os.path.join(build, rel), os.path.join(bin_dir, name))
    return root, bin_dir


def run(command, cwd, env, seconds):
    """(ok, still_running, output) of `bash -c command` within `seconds`."""
    process = subprocess.Popen(["bash", "-c", "set -eo pipefail\n" + command], cwd=cwd, env=env,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               start_new_session=True)
    try:
        output, _ = process.communicate(timeout=seconds)
        return process.returncode == 0, False, output.decode(errors="replace")
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        output, _ = process.communicate()
        return True, True, output.decode(errors="replace")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--source", required=True)
    parser.add_argument("--build", required=True)
    parser.add_argument("--list", action="store_true", help="only list the commands found")
    parser.add_argument("--check-exceptions", action="store_true",
                        help="only check that every exception matches a documented command")
    parser.add_argument("files", nargs="*", help="markdown files relative to the source")
    args = parser.parse_args()
    source, build = os.path.abspath(args.source), os.path.abspath(args.build)
    files = args.files or (["README.md"] + sorted(
        os.path.join("docs", f) for f in os.listdir(os.path.join(source, "docs"))
        if f.endswith(".md")))
    exceptions, setups = load_exceptions(
        os.path.join(source, "tests", "docs", "doc_commands.txt"))
    seen = set()
    failures = []
    if args.check_exceptions:
        for name in files:
            seen.update(text for _, text, _ in extract(os.path.join(source, name)))
        stale = [text for text in exceptions if text not in seen]
        for text in stale:
            print(f"tests/docs/doc_commands.txt: '{text}' matches no command in the docs any "
                  "more: remove it", file=sys.stderr)
        return 1 if stale else 0
    for name in files:
        commands = extract(os.path.join(source, name))
        if args.list:
            for line, text, kind in commands:
                action = exceptions.get(text)
                tag = action[0] + (f" {action[1]}" if action and action[0] == "timeout" else "") \
                    if action else ("synopsis" if kind == "mention" or is_synopsis(text) else "run")
                print(f"{name}:{line}: [{tag}] {text}")
            continue
        sandbox, bin_dir = make_sandbox(source, build)
        env = dict(os.environ)
        env["PATH"] = bin_dir + os.pathsep + env.get("PATH", "")
        assignments = []
        try:
            for text in setups.get(name, []):
                ok, _, output = run(text, sandbox, env, DEFAULT_TIMEOUT)
                print(f"{name}: setup {'ok' if ok else 'FAILED'}: {text}")
                if not ok:
                    failures.append((f"{name} (setup in doc_commands.txt)", text, output))
            for line, text, kind in commands:
                seen.add(text)
                where = f"{name}:{line}"
                action = exceptions.get(text)
                if action and action[0] == "skip":
                    print(f"{where}: skipped ({action[2]}): {text}")
                    continue
                if re.match(r"^[A-Z_][A-Z0-9_]*=\S*$", text):
                    assignments.append(text)
                    continue
                command = text.rstrip("&").rstrip()
                if (kind == "mention" or is_synopsis(text)) and not action:
                    command = help_command(text)
                if action and action[0] == "if-installed" and not shutil.which(action[3]):
                    print(f"{where}: skipped ({action[3]} is not installed: {action[2]}): {text}")
                    continue
                if action and action[0] == "display":
                    if not shutil.which("xvfb-run"):
                        print(f"{where}: skipped (needs a display; xvfb-run is not installed): "
                              f"{text}")
                        continue
                    command = "xvfb-run -a " + command
                seconds = action[1] if action else DEFAULT_TIMEOUT
                start = time.monotonic()
                ok, running, output = run("\n".join(assignments + [command]), sandbox, env,
                                          seconds)
                if running and not (action and action[0] in ("timeout", "display")):
                    ok = False
                    output += f"\n(still running after {seconds} s)"
                took = time.monotonic() - start
                state = "started, stopped after" if running else ("ok in" if ok else "FAILED in")
                print(f"{where}: {state} {took:.1f} s: {command}")
                if not ok:
                    failures.append((where, command, output))
        finally:
            shutil.rmtree(sandbox, ignore_errors=True)
    for where, command, output in failures:
        print(f"\n{where}: FAILED: {command}\n{output[-3000:]}", file=sys.stderr)
    if failures:
        print(f"\n{len(failures)} documented command(s) failed. Fix the command in the docs, or "
              "add it to tests/docs/doc_commands.txt with the reason it cannot run here.",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
