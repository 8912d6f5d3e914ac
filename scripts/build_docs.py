#!/usr/bin/python3
"""Builds the documentation site (`make docs`): stages docs/ and the generated reference pages
into BUILD/docs-src, then runs `mkdocs build --strict` (mkdocs.yml at the repository root) into
BUILD/site. Needs no network.

Generated, never committed (all under BUILD/docs-src):
  index.md                 README.md, its links rewritten for the site
  reference/cli.md         `jelly --help` and every subcommand's --help, `jelly list`,
                           `jelly-bench --help` and its subcommands'
  reference/scene-keys.md  the field tables as `jelly fields` prints them (generated from the
                           C++ declarations), then the rows of docs/scenes.md's key tables
                           whose keys no field table declares
  reference/cpp.md, cpp-api/  Doxygen HTML of the headers listed in cmake/public_headers.txt,
                           a table of them with each header's first sentence
  reference/python.md      pydoc of every name in jelly.__all__ (the module's docstrings)

A built page that loads a script, style sheet, icon or image from another site fails the
build (the site must need no network to be read). A link from a page to a file of the
repository outside docs/ (e.g. ../assets/README.md) is served from a copy under repo/, so that
every link of the site resolves offline. A generator
whose program is missing (doxygen; the built jelly, jelly-bench or Python module) leaves a page
that says so and what to build, and a warning on stderr; --require-all makes that an error.

The C++ reference documents exactly the public headers, from their own comments
(scripts/doxygen_filter.py): any Doxygen warning (an undocumented public class, function,
member, enum or typedef) and any public header without its page is a problem; --cpp-only runs
that part alone (the test jelly_docs_cpp_reference).

Usage: build_docs.py [--source DIR] [--build DIR] [--require-all] [--stage-only] [--cpp-only]
Exit codes: 0 built; 1 mkdocs failed (a warning under --strict) or a generator failed; 2 bad
arguments; 77 mkdocs (or its material theme) is not installed.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys

LINK = re.compile(r"(!?\[[^\]]*\]\()([^)\s]+)(\))")


def warn(message):
    print(f"build_docs: warning: {message}", file=sys.stderr)


class Stager:
    """Copies markdown into the staging tree, rewriting relative links that leave docs/."""

    def __init__(self, source, stage):
        self.source, self.stage = source, stage

    def rewrite(self, text, repo_path, staged_path):
        """`text` of the repository file `repo_path`, written at `staged_path` (both relative)."""
        page_dir = os.path.dirname(staged_path)

        def fix(match):
            target = match.group(2)
            if re.match(r"^[a-z]+:", target) or target.startswith("#"):
                return match.group(0)
            path, _, anchor = target.partition("#")
            resolved = os.path.normpath(os.path.join(os.path.dirname(repo_path), path))
            if resolved.startswith(".."):
                return match.group(0)
            if resolved.startswith("docs" + os.sep) or resolved == "docs":
                staged = resolved[len("docs") + 1:]
            elif os.path.isfile(os.path.join(self.source, resolved)):
                staged = os.path.join("repo", resolved)
                destination = os.path.join(self.stage, staged)
                if not os.path.exists(destination):
                    os.makedirs(os.path.dirname(destination), exist_ok=True)
                    if resolved.endswith(".md"):
                        self.copy_markdown(resolved, staged)
                    else:
                        shutil.copyfile(os.path.join(self.source, resolved), destination)
            else:
                # a folder of the repository: not a page of the site; name it instead
                return f"`{resolved}`" if not match.group(1).startswith("!") else match.group(0)
            link = os.path.relpath(staged, page_dir or ".")
            return match.group(1) + link + ("#" + anchor if anchor else "") + match.group(3)

        out = []
        fence = False
        for line in text.split("\n"):
            if line.lstrip().startswith("```"):
                fence = not fence
            out.append(line if fence or line.startswith("    ") else LINK.sub(fix, line))
        return "\n".join(out)

    def copy_markdown(self, repo_path, staged_path):
        with open(os.path.join(self.source, repo_path), encoding="utf-8") as f:
            text = f.read()
        destination = os.path.join(self.stage, staged_path)
        os.makedirs(os.path.dirname(destination), exist_ok=True)
        with open(destination, "w", encoding="utf-8") as f:
            f.write(self.rewrite(text, repo_path, staged_path))


def write(stage, path, text):
    destination = os.path.join(stage, path)
    os.makedirs(os.path.dirname(destination), exist_ok=True)
    with open(destination, "w", encoding="utf-8") as f:
        f.write(text)


def run(command, **kwargs):
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            **kwargs)
    return result.returncode, result.stdout


def subcommands(help_text):
    """Subcommand names of a CLI11 help text (the lines under 'SUBCOMMANDS:')."""
    names, inside = [], False
    for line in help_text.split("\n"):
        if line.strip().upper().startswith("SUBCOMMANDS"):
            inside = True
            continue
        if inside:
            m = re.match(r"^\s+([a-z][a-z0-9_-]*)\s", line + " ")
            if m:
                names.append(m.group(1))
            elif line.strip() and not line.startswith(" "):
                inside = False
    return names


def cli_page(build, problems):
    programs = [("jelly", os.path.join(build, "cli", "jelly")),
                ("jelly-bench", os.path.join(build, "bench", "jelly-bench"))]
    parts = ["# Command line\n",
             "Generated by `make docs` (scripts/build_docs.py) from the programs' own `--help`:"
             " what you read here is what the built programs print.\n"]
    for name, program in programs:
        parts.append(f"## {name}\n")
        if not os.access(program, os.X_OK):
            problems.append(f"{program} is not built (make build): its reference is missing")
            parts.append(f"Not generated: `{program}` was not built when the site was.\n")
            continue
        status, text = run([program, "--help"])
        if status != 0:
            problems.append(f"{program} --help exited {status}")
        parts.append("```text\n" + text.rstrip() + "\n```\n")
        for sub in subcommands(text):
            status, sub_text = run([program, sub, "--help"])
            if status != 0:
                problems.append(f"{program} {sub} --help exited {status}")
            parts.append(f"### {name} {sub}\n\n```text\n{sub_text.rstrip()}\n```\n")
        if name == "jelly":
            status, listing = run([program, "list"])
            if status == 0:
                parts.append("### What `jelly list` prints\n\nThe registered integrators, body"
                             " and terrain kinds and contact models of this build:\n\n```text\n"
                             + listing.rstrip() + "\n```\n")
            else:
                problems.append(f"{program} list exited {status}")
    return "\n".join(parts)


def table_keys(fields_json):
    """Every key the field tables declare (their fields' names, the kinds they belong to, and
    the leaves of their paths: "springs", "divergence", ...)."""
    keys = set()
    for table in fields_json:
        keys.update(f["name"] for f in table["fields"])
        keys.update(table.get("used_by", []))
        leaf = re.sub(r"\[i\]", "", table["path"]).split(".")[-1]
        if leaf:
            keys.add(leaf)
    return keys


def row_declared(row, declared):
    """Whether every key a row of a hand-written key table names in its first cell is declared:
    `a`, `b.c` -> a, b, c; in `springs.{structural,shear,bending}.{ks,kd}` one declared key of
    each set of alternatives (instances of one table) is enough."""
    cell = row.split("|")[1]
    for code in re.findall(r"`([^`]+)`", cell):
        for part in re.split(r"\.(?![^{]*\})", code):
            names = {k.strip() for k in part.strip("{}").split(",") if k.strip()}
            if names and not names & declared:
                return False
    return True


def scene_keys_page(source, build, problems):
    """The field tables of the built `jelly fields` (every key declared once in C++: type,
    default, unit, what is allowed), then the rows of docs/scenes.md's key tables whose keys no
    field table declares (none today; the prose stays on that page)."""
    parts = ["# Scene keys\n",
             "Every key of a scene file with its type, default and what is allowed, generated by"
             " `make docs` from `jelly fields`: the same declarations read, write and validate"
             " the keys and give the Python properties. Rows of type object or list are read by"
             " their own code (a list of bodies, a path); their own keys are in the tables named"
             " there and in [Scenes and bodies](../scenes.md), with the prose, the `--set`"
             " syntax and examples.\n"]
    program = os.path.join(build, "cli", "jelly")
    declared = set()
    if os.access(program, os.X_OK):
        status, text = run([program, "fields", "--format", "markdown"])
        if status != 0:
            problems.append(f"{program} fields exited {status}")
        parts.append(text.rstrip() + "\n")
        status, text = run([program, "fields", "--format", "json"])
        if status == 0:
            declared = table_keys(json.loads(text))
        else:
            problems.append(f"{program} fields --format json exited {status}")
    else:
        problems.append(f"{program} is not built (make build): the field tables are"
                        " missing from the scene-key reference")
        parts.append(f"Not generated: `{program}` was not built when the site was, so the"
                     " field tables are missing.\n")
    with open(os.path.join(source, "docs", "scenes.md"), encoding="utf-8") as f:
        lines = f.read().split("\n")
    pending, i = None, 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("#"):
            pending = line.rstrip() if line.startswith("##") else None
            i += 1
            continue
        if line.startswith("|") and i + 1 < len(lines) and re.match(r"^\|[-:| ]+\|$",
                                                                     lines[i + 1].strip()):
            header, rule = lines[i], lines[i + 1]
            i += 2
            rows = []
            while i < len(lines) and lines[i].startswith("|"):
                rows.append(lines[i])
                i += 1
            # Only key tables (first column "key" or "kind"), and of them the rows that name a
            # key no field table declares.
            if header.split("|")[1].strip() not in ("key", "kind"):
                continue
            rows = [r for r in rows if not row_declared(r, declared)]
            if rows:
                if pending:
                    parts.append(pending + "\n")
                    pending = None
                parts.append("\n".join([header, rule] + rows) + "\n")
            continue
        i += 1
    text = "\n".join(parts)
    # links of the tables are relative to docs/; this page is one folder down
    return LINK.sub(lambda m: m.group(0) if re.match(r"^([a-z]+:|#|\.\./)", m.group(2))
                    else m.group(1) + "../" + m.group(2) + m.group(3), text)


NAMESPACE_DOC = """/// \\namespace jelly
/// The public API of jelly: the headers of cmake/public_headers.txt. Names in a `detail`
/// namespace or under a detail/ folder are internal and may change in any release.
"""


def doxygen_reference(source, output, work, headers):
    """Runs Doxygen on exactly `headers` (paths in the repository) into the HTML folder
    `output`, reading their plain `//` comments through scripts/doxygen_filter.py. Returns
    (problems, pages): every Doxygen warning (an undocumented public class, function, member,
    enum or typedef; a malformed comment) is a problem, and so is a header without its page in
    the reference; `pages` maps each header to its page, relative to `output`'s parent."""
    doxygen = shutil.which("doxygen")
    if not doxygen:
        return ["doxygen is not installed (scripts/install-deps.sh --docs): no C++ API"], {}
    os.makedirs(work, exist_ok=True)
    shutil.rmtree(output, ignore_errors=True)
    namespace_doc = os.path.join(work, "namespace.dox")
    with open(namespace_doc, "w", encoding="utf-8") as f:
        f.write(NAMESPACE_DOC)
    log = os.path.join(work, "warnings.log")
    inputs = " ".join([os.path.join(source, h) for h in headers] + [namespace_doc])
    doc_filter = os.path.join(source, "scripts", "doxygen_filter.py")
    doxyfile = "\n".join([
        "PROJECT_NAME = jelly", "PROJECT_BRIEF = \"public C++ API\"",
        f"OUTPUT_DIRECTORY = {work}", "CREATE_SUBDIRS = NO",
        f"INPUT = {inputs}", f"STRIP_FROM_PATH = {source}",
        f"STRIP_FROM_INC_PATH = {source}", "FULL_PATH_NAMES = YES",
        f"INPUT_FILTER = \"/usr/bin/python3 {doc_filter}\"", "FILTER_SOURCE_FILES = NO",
        "EXTRACT_ALL = NO", "EXTRACT_PRIVATE = NO", "EXTRACT_STATIC = YES",
        "EXCLUDE_SYMBOLS = detail detail::* *::detail *::detail::* nlohmann nlohmann::*",
        "JAVADOC_AUTOBRIEF = YES", "QUIET = YES", "WARNINGS = YES",
        "WARN_IF_UNDOCUMENTED = YES", "WARN_IF_DOC_ERROR = YES", "WARN_NO_PARAMDOC = NO",
        f"WARN_LOGFILE = {log}",
        "GENERATE_HTML = YES", f"HTML_OUTPUT = {output}", "SEARCHENGINE = YES",
        "SERVER_BASED_SEARCH = NO", "USE_MATHJAX = NO", "GENERATE_LATEX = NO",
        "GENERATE_XML = NO", "HAVE_DOT = NO", "SOURCE_BROWSER = NO", "HTML_TIMESTAMP = NO",
        "ENABLE_PREPROCESSING = YES", "MACRO_EXPANSION = NO", ""])
    with open(os.path.join(work, "Doxyfile"), "w", encoding="utf-8") as f:
        f.write(doxyfile)
    if os.path.exists(log):
        os.remove(log)
    status, text = run([doxygen, os.path.join(work, "Doxyfile")])
    problems = []
    if status != 0:
        problems.append(f"doxygen exited {status}:\n{text[-2000:]}")
    if os.path.exists(log):
        with open(log, encoding="utf-8") as f:
            warnings = [line.replace(source + os.sep, "") for line in f.read().split("\n")
                        if line.strip()]
        if warnings:
            problems.append(f"{len(warnings)} Doxygen warnings on the public headers (each"
                            " public class, function, member, enum and typedef needs its"
                            " comment):\n  " + "\n  ".join(warnings))
    # Doxygen writes `#include <solvers/simulator.hpp>`; users write <jelly/solvers/...>.
    for name in os.listdir(output) if os.path.isdir(output) else []:
        if name.endswith(".html"):
            path = os.path.join(output, name)
            with open(path, encoding="utf-8") as f:
                text = f.read()
            fixed = re.sub(r'(#include &lt;(?:<a class="el" href="[^"]*">)?)(?=(?:core|geometry|terrain|solvers|io|fit)/)',
                           r"\1jelly/",
                           text)
            if fixed != text:
                with open(path, "w", encoding="utf-8") as f:
                    f.write(fixed)
    pages = {}
    # Doxygen names a file's page by its base name, or by its path where two share one
    mangle = lambda name: name.replace("_", "__").replace("/", "_2").replace(".", "_8")
    base = os.path.basename(output)
    for h in headers:
        candidates = [f"{base}/{mangle(name)}.html" for name in (os.path.basename(h), h)]
        page = next((p for p in candidates
                     if os.path.exists(os.path.join(os.path.dirname(output), p))), None)
        if page:
            pages[h] = page
        else:
            problems.append(f"{h} is in cmake/public_headers.txt but has no page in the C++"
                            " reference (its first comment, after #pragma once, documents it)")
    return problems, pages


def public_headers(source):
    with open(os.path.join(source, "cmake", "public_headers.txt"), encoding="utf-8") as f:
        return [line.split()[0] for line in f if re.match(r"^[a-z]", line)]


def cpp_page(source, stage, build, problems):
    parts = ["# C++ API\n"]
    headers = public_headers(source)
    found, pages = doxygen_reference(source, os.path.join(stage, "reference", "cpp-api"),
                                     os.path.join(build, "docs-doxygen"), headers)
    problems.extend(found)
    if not pages:
        parts.append("Not generated: Doxygen was not installed, or failed, when the site was"
                     " built.\n")
        return "\n".join(parts)
    parts.append(f"The {len(headers)} headers of `cmake/public_headers.txt` (what `cmake --install`"
                 " installs; `<jelly/jelly.hpp>` includes them), documented by Doxygen from their"
                 " comments. Everything else is internal and may change.\n")
    parts.append("**[Open the C++ API reference](cpp-api/index.html)** ("
                 "[classes](cpp-api/annotated.html), [files](cpp-api/files.html)).\n")
    parts.append("| header | what it holds |\n|---|---|")
    for h in headers:
        summary = header_summary(os.path.join(source, h))
        link = f"[`<jelly/{h}>`]({pages[h]})" if h in pages else f"`<jelly/{h}>`"
        parts.append(f"| {link} | {summary} |")
    return "\n".join(parts) + "\n"


def header_summary(path):
    """The first sentence of a header's own comment (the one after #pragma once)."""
    text = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("#pragma") or (not text and not line.strip()):
                continue
            if not line.startswith("//"):
                break
            text.append(line[2:].strip())
    sentence = re.split(r"(?<=\.)\s", " ".join(text) + " ", maxsplit=1)[0].strip()
    if len(sentence) > 160:  # a long sentence: up to its first colon or semicolon
        short = re.split(r"(?<=[:;])\s", sentence, maxsplit=1)[0]
        if short.count("(") == short.count(")"):
            sentence = short
    return sentence.rstrip(".:;").replace("|", "\\|")


PYTHON_SNIPPET = r"""
import inspect, pydoc, re, sys, jelly
names = sorted(getattr(jelly, "__all__", [n for n in dir(jelly) if not n.startswith("_")]))
print("MODULE\t" + jelly.__file__)
for name in names:
    obj = getattr(jelly, name)
    if not (callable(obj) or isinstance(obj, type)):
        continue
    text = pydoc.render_doc(obj, title="%s", renderer=pydoc.plaintext)
    # pybind11 starts a function's docstring with its signature: what follows is the doc
    doc = [line for line in (inspect.getdoc(obj) or "").split("\n")
           if line.strip() and not re.match(r"^(\d+\. )?" + re.escape(name) + r"\(", line)
           and line.strip() != "Overloaded function."]
    if not doc:
        print("UNDOCUMENTED\t" + name)
    print("NAME\t" + name)
    print(text.replace("\x00", ""))
"""


def python_page(source, build, problems):
    parts = ["# Python module\n"]
    module_dir = os.path.join(build, "python")
    env = dict(os.environ, PYTHONPATH=module_dir)
    status, text = run(["/usr/bin/python3", "-c", PYTHON_SNIPPET], env=env, cwd=build)
    if status != 0 or not text.startswith("MODULE\t" + module_dir):
        problems.append("the Python module jelly is not built in "
                        f"{module_dir} (make build): no Python reference\n{text[-1000:]}")
        parts.append("Not generated: the Python module was not built when the site was.\n")
        return "\n".join(parts)
    parts.append("Every public name of `import jelly` with its signature and docstring, as"
                 " `pydoc` renders them (generated by `make docs` from the built module). The"
                 " guide is [Python](../python.md); the type stub `python/jelly/__init__.pyi`"
                 " has the signatures too.\n")
    undocumented = re.findall(r"^UNDOCUMENTED\t(\S+)$", text, re.M)
    if undocumented:
        problems.append("names of jelly.__all__ without a docstring (python/src/*.cpp): "
                        + ", ".join(undocumented))
    text = re.sub(r"^UNDOCUMENTED\t\S+\n", "", text, flags=re.M)
    sections = text.split("\nNAME\t")[1:]
    index = []
    body = []
    for section in sections:
        name, _, doc = section.partition("\n")
        index.append(f"[`{name}`](#{name.lower()})")
        doc = re.sub(r".\x08", "", doc).rstrip()
        body.append(f"## {name}\n\n```text\n{doc}\n```\n")
    parts.append(", ".join(index) + "\n")
    return "\n".join(parts + body)


EXTERNAL = re.compile(r"<(?:script|img|iframe|source|link(?=[^>]*rel=\"?(?:stylesheet|preload|"
                      r"icon|modulepreload)))[^>]*\s(?:src|href)=\"?((?:https?:)?//[^\"\s>]+)")


def external_resources(site):
    """(page, url) of every script, style sheet, icon or image a built page loads from
    elsewhere (a plain link to another site is not loaded, and allowed)."""
    found = []
    for root, _, files in os.walk(site):
        for name in files:
            if name.endswith(".html"):
                path = os.path.join(root, name)
                with open(path, encoding="utf-8", errors="replace") as f:
                    for url in EXTERNAL.findall(f.read()):
                        found.append((os.path.relpath(path, site), url))
    return found


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--source", default=os.path.dirname(here))
    parser.add_argument("--build", default=None, help="the CMake build folder (SOURCE/build)")
    parser.add_argument("--require-all", action="store_true",
                        help="a reference page that cannot be generated is an error")
    parser.add_argument("--stage-only", action="store_true", help="do not run mkdocs")
    parser.add_argument("--cpp-only", action="store_true",
                        help="only the C++ reference (Doxygen) and its checks, into"
                        " BUILD/docs-doxygen/cpp-api; exit 77 without doxygen")
    args = parser.parse_args()
    source = os.path.abspath(args.source)
    build = os.path.abspath(args.build or os.path.join(source, "build"))
    stage = os.path.join(build, "docs-src")
    site = os.path.join(build, "site")

    if args.cpp_only:
        if not shutil.which("doxygen"):
            print("build_docs: doxygen is not installed (Debian package doxygen:"
                  " scripts/install-deps.sh --docs): skipped", file=sys.stderr)
            return 77
        work = os.path.join(build, "docs-doxygen")
        headers = public_headers(source)
        problems, pages = doxygen_reference(source, os.path.join(work, "cpp-api"), work, headers)
        for problem in problems:
            print(f"build_docs: {problem}", file=sys.stderr)
        print(f"build_docs: C++ reference of {len(pages)} of {len(headers)} public headers in"
              f" {os.path.join(work, 'cpp-api')}")
        return 1 if problems else 0

    if not args.stage_only:
        status, text = run(["/usr/bin/python3", "-c", "import mkdocs, material"])
        if status != 0 or not shutil.which("mkdocs"):
            print("build_docs: mkdocs and its material theme are not installed (Debian packages"
                  " mkdocs, mkdocs-material: scripts/install-deps.sh --docs)", file=sys.stderr)
            return 77

    shutil.rmtree(stage, ignore_errors=True)
    os.makedirs(stage)
    stager = Stager(source, stage)
    docs = os.path.join(source, "docs")
    for root, _, files in os.walk(docs):
        for name in files:
            repo_path = os.path.relpath(os.path.join(root, name), source)
            staged = os.path.relpath(os.path.join(root, name), docs)
            if name.endswith(".md"):
                stager.copy_markdown(repo_path, staged)
            elif name.endswith(".h5"):
                continue  # jelly-bench's HDF5 beside the CSV files of docs/bench/: not committed
            else:
                os.makedirs(os.path.join(stage, os.path.dirname(staged)), exist_ok=True)
                shutil.copyfile(os.path.join(root, name), os.path.join(stage, staged))
    stager.copy_markdown("README.md", "index.md")

    problems = []
    write(stage, "reference/cli.md", cli_page(build, problems))
    write(stage, "reference/scene-keys.md", scene_keys_page(source, build, problems))
    write(stage, "reference/cpp.md", cpp_page(source, stage, build, problems))
    write(stage, "reference/python.md", python_page(source, build, problems))
    for problem in problems:
        warn(problem)
    if problems and args.require_all:
        return 1
    if args.stage_only:
        print(f"build_docs: staged {stage}")
        return 0

    # mkdocs.yml names build/docs-src and build/site; another build folder gets a copy of it
    # that names its own.
    import yaml  # python3-yaml, a dependency of mkdocs
    with open(os.path.join(source, "mkdocs.yml"), encoding="utf-8") as f:
        settings = yaml.safe_load(f)
    settings["docs_dir"], settings["site_dir"] = stage, site
    config = os.path.join(build, "mkdocs.yml")
    with open(config, "w", encoding="utf-8") as f:
        yaml.safe_dump(settings, f, sort_keys=False)
    status = subprocess.run(["mkdocs", "build", "--strict", "--clean", "--config-file", config],
                            cwd=source).returncode
    if status != 0:
        print("build_docs: mkdocs build --strict failed (a warning above is an error)",
              file=sys.stderr)
        return 1
    external = external_resources(site)
    if external:
        for page, url in external[:20]:
            print(f"build_docs: {page} loads {url}: the site must need no network",
                  file=sys.stderr)
        return 1
    print(f"build_docs: site in {site} (open {os.path.join(site, 'index.html')})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
