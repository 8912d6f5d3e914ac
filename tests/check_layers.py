#!/usr/bin/python3
"""The layering of jelly's folders (docs/CONTRIBUTING.md), checked on the sources.

Layers, left to right; a file of one layer includes only headers of its own layer and of the
layers to its left (a detail/ header counts as its module's):

    core -> geometry -> terrain -> solvers -> io -> fit -> cli, bench, viewer, python

    check_layers.py [--root DIR]             every #include of the layer folders under DIR
    check_layers.py [--root DIR] --umbrella  cmake/jelly.hpp.in includes every public header
                                             (cmake/public_headers.txt) and no other, a
                                             public header includes only public ones, and
                                             every other header is under a detail/ folder
    check_layers.py --self-test              both checks catch violations in a temporary tree

Exit status 0 when clean, 1 with one line per violation on stderr.

The build enforces the layers on what it compiles (cmake/JellyLayers.cmake: each layer's
sources and public headers see only their layer and those to its left; the ctest
jelly_layers_compile proves it). This scan still covers what the compiler cannot see: an
internal header that reaches up but is included only by higher layers, the programs' folders,
jelly/ paths naming no module and quoted includes relative to the including file.
"""
import argparse
import os
import re
import shutil
import sys
import tempfile

LAYERS = [["core"], ["geometry"], ["terrain"], ["solvers"], ["io"], ["fit"],
          ["cli", "bench", "viewer", "python"]]
RANK = {module: rank for rank, modules in enumerate(LAYERS) for module in modules}
LIBRARY = ["core", "geometry", "terrain", "solvers", "io", "fit"]  # libjelly, installed
# Headers generated into include/jelly/ by the build: the umbrella sits on top of the library.
GENERATED = {"jelly.hpp": "fit", "version.hpp": "core"}
SOURCE_EXTENSIONS = (".hpp", ".cpp", ".h", ".cc", ".inl")
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')
# What a public header may include besides public headers and the light standard headers: the
# umbrella's compile time (docs/CONTRIBUTING.md, "The public API") is <Eigen/Core> and little
# else. Eigen's geometry types are named through the forward declarations <Eigen/Core> holds.
PUBLIC_THIRD_PARTY = {"Eigen/Core", "nlohmann/json_fwd.hpp"}
HEAVY_STANDARD = {"regex", "iostream", "fstream", "filesystem", "thread", "mutex", "future",
                  "chrono", "random", "variant", "unordered_map", "unordered_set", "set", "deque",
                  "list", "omp.h"}


def sources(root, module):
    top = os.path.join(root, module)
    for folder, dirs, files in os.walk(top):
        dirs.sort()
        for name in sorted(files):
            if name.endswith(SOURCE_EXTENSIONS):
                yield os.path.join(folder, name)


def module_of_include(root, including_file, kind, target):
    """The module a header belongs to, None for a header outside jelly (std, Eigen, ...),
    or '?name' for a jelly/ path naming no known module."""
    parts = target.split("/")
    if parts[0] == "jelly" and len(parts) >= 2:
        if len(parts) == 2:
            return GENERATED.get(parts[1], "?" + parts[1])
        return parts[1] if parts[1] in RANK else "?" + parts[1]
    if kind == '"':
        # A quoted include is first looked up beside the including file.
        resolved = os.path.normpath(os.path.join(os.path.dirname(including_file), target))
        relative = os.path.relpath(resolved, root)
        first = relative.split(os.sep)[0]
        if os.path.exists(resolved) and first in RANK:
            return first
    return None


def check_layers(root):
    violations = []
    for module in RANK:
        for path in sources(root, module):
            with open(path, encoding="utf-8", errors="replace") as f:
                for number, line in enumerate(f, 1):
                    m = INCLUDE.match(line)
                    if not m:
                        continue
                    kind, target = m.group(1), m.group(2)
                    included = module_of_include(root, path, kind, target)
                    if included is None:
                        continue
                    where = f"{os.path.relpath(path, root)}:{number}"
                    if included.startswith("?"):
                        violations.append(f"{where}: includes {target}, whose module "
                                          f"'{included[1:]}' is not a layer of jelly")
                    elif RANK[included] > RANK[module]:
                        violations.append(f"{where}: {module} includes {target} of {included}, "
                                          f"a layer above it")
    return violations


def public_list(root):
    """cmake/public_headers.txt: (header, in the umbrella) pairs, header as jelly/...."""
    out = []
    with open(os.path.join(root, "cmake", "public_headers.txt"), encoding="utf-8") as f:
        for line in f:
            words = line.split("#")[0].split()
            if words:
                out.append(("jelly/" + words[0], words[1:] != ["extension"]))
    return out


def is_heavy(include):
    """A header that a header of the umbrella may not include (<...> form, not jelly's own)."""
    if include.startswith("jelly/"):
        return False
    third_party = "/" in include or include[0].isupper() or include.endswith(".h")
    return include in HEAVY_STANDARD or (third_party and include not in PUBLIC_THIRD_PARTY)


def check_umbrella(root):
    """The umbrella includes exactly the public headers (less the extension ones); a public
    header exists, is not from a detail/ folder and includes only public headers (an installed
    header that includes another one would not compile in a consumer); a header of the umbrella
    includes no heavy third-party or standard header (PUBLIC_THIRD_PARTY, HEAVY_STANDARD)."""
    path = os.path.join(root, "cmake", "jelly.hpp.in")
    with open(path, encoding="utf-8") as f:
        included = [m.group(2) for m in map(INCLUDE.match, f) if m]
    listed = public_list(root)
    public = {header for header, _ in listed} | {"jelly/" + g for g in GENERATED}
    violations = []
    for header, umbrella in listed:
        if umbrella and header not in included:
            violations.append(f"cmake/jelly.hpp.in: does not include <{header}>, a public header")
        if "detail" in header.split("/"):
            violations.append(f"cmake/public_headers.txt: {header} is from a detail/ folder")
    for header in included:
        if header not in public or dict(listed).get(header) is False:
            violations.append(f"cmake/jelly.hpp.in: includes <{header}>, which is not a public "
                              f"header of the umbrella (cmake/public_headers.txt)")
    for header, umbrella in listed:
        file = os.path.join(root, header[len("jelly/"):])
        if not os.path.exists(file):
            violations.append(f"cmake/public_headers.txt: {header} does not exist")
            continue
        with open(file, encoding="utf-8") as f:
            for number, line in enumerate(f, 1):
                m = INCLUDE.match(line)
                if m and m.group(2).startswith("jelly/") and m.group(2) not in public:
                    violations.append(f"{header[len('jelly/'):]}:{number}: a public header "
                                      f"includes <{m.group(2)}>, which is not public "
                                      f"(cmake/public_headers.txt)")
                elif m and umbrella and m.group(1) == "<" and is_heavy(m.group(2)):
                    violations.append(f"{header[len('jelly/'):]}:{number}: a public header "
                                      f"includes <{m.group(2)}>, which every includer would "
                                      f"compile: include it in a .cpp (or a detail/ header); "
                                      f"allowed: {', '.join(sorted(PUBLIC_THIRD_PARTY))} and the "
                                      f"light standard headers")
    # Every header of the library is either public (listed, installed) or internal under a
    # detail/ folder: a new header outside detail/ that is not listed is a mistake either way.
    for module in LIBRARY:
        for path in sources(root, module):
            relative = os.path.relpath(path, root).replace(os.sep, "/")
            if (relative.endswith(".hpp") and "detail" not in relative.split("/")
                    and "jelly/" + relative not in public):
                violations.append(f"{relative}: neither a public header (cmake/public_headers.txt) "
                                  f"nor under a detail/ folder")
    return violations


def self_test():
    """Both checks on temporary trees: clean ones pass, each planted violation is found."""
    failures = []
    made = []

    def tree(files):
        root = tempfile.mkdtemp(prefix="jelly_layers_")
        made.append(root)
        for name, text in files.items():
            path = os.path.join(root, name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
        return root

    clean = {
        "core/model.hpp": "#include <vector>\n#include <Eigen/Core>\n",
        "core/detail/jacobian.hpp": "#include <jelly/core/model.hpp>\n",
        "solvers/simulator.hpp": '#include "../terrain/plane.hpp"\n',
        "solvers/simulator.cpp": "#include <jelly/core/detail/jacobian.hpp>\n",
        "terrain/plane.hpp": "#include <jelly/core/model.hpp>\n",
        "cli/main.cpp": '#include <jelly/jelly.hpp>\n#include "output.hpp"\n'
                        "#include <jelly/viewer/window.hpp>\n",
        "cli/output.hpp": "#include <jelly/io/scene.hpp>\n",
        "cmake/jelly.hpp.in": "#include <jelly/core/model.hpp>\n#include <jelly/terrain/plane.hpp>\n"
                              "#include <jelly/solvers/simulator.hpp>\n",
        "cmake/public_headers.txt": "# comment\ncore/model.hpp\nterrain/plane.hpp\n"
                                    "solvers/simulator.hpp\ncore/json.hpp extension\n",
        "core/json.hpp": "#include <nlohmann/json.hpp>\n",
    }
    root = tree(clean)
    for name, found in (("layers", check_layers(root)), ("umbrella", check_umbrella(root))):
        if found:
            failures.append(f"a clean tree fails the {name} check: {found}")

    planted = [
        ("core/forces.cpp", "#include <jelly/solvers/simulator.hpp>\n", "core includes"),
        ("core/detail/bands.hpp", "#include <jelly/io/detail/h5.hpp>\n", "core includes"),
        ("terrain/plane.cpp", '#include "../solvers/simulator.hpp"\n', "terrain includes"),
        ("io/scene.cpp", "  #  include <jelly/cli/output.hpp>\n", "io includes"),
        ("fit/fit.cpp", "#include <jelly/jelly.hpp>\n", None),  # the umbrella is fit's level
        ("solvers/x.cpp", "#include <jelly/jelly.hpp>\n", "solvers includes"),
        ("solvers/y.cpp", "#include <jelly/solver/x.hpp>\n", "not a layer"),
    ]
    for name, text, expected in planted:
        files = dict(clean)
        files[name] = text
        found = check_layers(tree(files))
        if expected is None and found:
            failures.append(f"{name} ({text.strip()}) is allowed but reported: {found}")
        if expected is not None and not any(expected in v and name in v for v in found):
            failures.append(f"{name} ({text.strip()}) is not reported: {found}")

    files = dict(clean)
    files["cmake/public_headers.txt"] += "terrain/detail/elevator.hpp\n"
    files["terrain/detail/elevator.hpp"] = "#include <jelly/core/model.hpp>\n"
    if not any("terrain/detail/elevator.hpp" in v for v in check_umbrella(tree(files))):
        failures.append("a public header missing from the umbrella is not reported")
    files = dict(clean)
    files["cmake/jelly.hpp.in"] += "#include <jelly/core/detail/jacobian.hpp>\n"
    if not any("not a public header" in v for v in check_umbrella(tree(files))):
        failures.append("a detail/ header in the umbrella is not reported")
    files = dict(clean)
    files["cmake/jelly.hpp.in"] += "#include <jelly/core/json.hpp>\n"
    if not any("core/json.hpp" in v for v in check_umbrella(tree(files))):
        failures.append("an extension header in the umbrella is not reported")
    files = dict(clean)
    files["terrain/plane.hpp"] += "#include <jelly/core/detail/jacobian.hpp>\n"
    if not any("terrain/plane.hpp:2" in v for v in check_umbrella(tree(files))):
        failures.append("a public header including a detail/ one is not reported")
    files = dict(clean)
    files["solvers/simulator.hpp"] += "#include <jelly/solvers/dynamics.hpp>\n"
    files["solvers/dynamics.hpp"] = ""
    if not any("solvers/simulator.hpp:2" in v for v in check_umbrella(tree(files))):
        failures.append("a public header including an internal one is not reported")
    for heavy in ("Eigen/Geometry", "regex", "omp.h", "nlohmann/json.hpp"):
        files = dict(clean)
        files["terrain/plane.hpp"] = "#include <Eigen/Core>\n#include <" + heavy + ">\n"
        if not any("terrain/plane.hpp:2" in v and heavy in v for v in check_umbrella(tree(files))):
            failures.append(f"a public header including <{heavy}> is not reported")
    files = dict(clean)
    files["geometry/box.hpp"] = "#include <jelly/core/model.hpp>\n"
    if not any("geometry/box.hpp: neither" in v for v in check_umbrella(tree(files))):
        failures.append("a header outside detail/ left off the public list is not reported")
    for root in made:
        shutil.rmtree(root, ignore_errors=True)
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", default=os.path.join(os.path.dirname(__file__), ".."))
    parser.add_argument("--umbrella", action="store_true")
    parser.add_argument("--self-test", action="store_true")
    args = parser.parse_args()
    if args.self_test:
        problems = self_test()
    elif args.umbrella:
        problems = check_umbrella(os.path.abspath(args.root))
    else:
        problems = check_layers(os.path.abspath(args.root))
    for p in problems:
        print(p, file=sys.stderr)
    if not problems:
        print("self-test passed" if args.self_test else "clean")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
