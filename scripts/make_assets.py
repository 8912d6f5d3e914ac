#!/usr/bin/python3
"""Makes the project's own triangle meshes under assets/ (no copied models).

  scripts/make_assets.py [--out DIR] [--check]

Each shape is a solid built with Gmsh's OpenCASCADE kernel (Debian: python3-gmsh) from spheres,
cylinders and boxes by booleans, and its boundary meshed with triangles:

  gummy_bear.obj  a gummy bear from spheres and capsules (a capsule: a cylinder with a sphere
                  at each end), 0.32 m tall, standing on y = 0 and facing +z; each part is an
                  OBJ group (`g`): belly, head, snout, ear_left, ear_right, arm_left,
                  arm_right, leg_left, leg_right (pins by vertex group; a vertex where two parts
                  meet is in both).
  torus.obj       a torus lying on y = 0 (axis y), major radius 0.3 m, minor radius 0.1 m.
  bowl.obj        a bowl, open side up: the lower half of a spherical shell, outer radius
                  0.4 m (0.8 m across), 0.04 m thick, its bottom on y = 0 and its flat rim at
                  y = 0.4 (a static obstacle for bears to drop into).

Every mesh is closed (each edge in exactly two triangles), consistently oriented with its
normals outwards, and its enclosed volume is checked against the solid's (the exact one for
the torus and the bowl, OpenCASCADE's for the bear) to 2 %. --check writes nothing and only
compares freshly made meshes with the files in --out: same triangle count and volume (the
meshes themselves depend on the Gmsh version). Units: metres, y up.
"""
import argparse
import math
import os
import sys

try:
    import gmsh
except ImportError:  # Debian: python3-gmsh (scripts/install-deps.sh)
    gmsh = None

HERE = os.path.dirname(os.path.abspath(__file__))
ASSETS = os.path.join(os.path.dirname(HERE), "assets")

# Target triangle edge length (m) per asset: the bear at a few thousand triangles.
SIZES = {"gummy_bear": 0.012, "torus": 0.025, "bowl": 0.03}


# The bear's parts: ("sphere", centre, radius) or ("capsule", end, end, radius) (a capsule: a
# cylinder between the ends with a sphere at each).
BEAR = {
    "belly": ("sphere", (0, 0.125, 0), 0.085),
    "head": ("sphere", (0, 0.235, 0), 0.07),
    "snout": ("sphere", (0, 0.222, 0.058), 0.032),
    "ear_left": ("sphere", (0.052, 0.29, -0.005), 0.026),
    "ear_right": ("sphere", (-0.052, 0.29, -0.005), 0.026),
    "arm_left": ("capsule", (0.06, 0.165, 0.02), (0.105, 0.115, 0.045), 0.026),
    "arm_right": ("capsule", (-0.06, 0.165, 0.02), (-0.105, 0.115, 0.045), 0.026),
    "leg_left": ("capsule", (0.05, 0.07, 0.015), (0.062, 0.03, 0.06), 0.03),
    "leg_right": ("capsule", (-0.05, 0.07, 0.015), (-0.062, 0.03, 0.06), 0.03),
}


def bear_solids(occ):
    """The bear's parts as OpenCASCADE solids [(3, tag)]."""
    solids = []
    for kind, *args in BEAR.values():
        if kind == "sphere":
            solids.append((3, occ.addSphere(*args[0], args[1])))
        else:
            solids.append(capsule(occ, *args))
    return solids


def capsule(occ, a, b, r):
    """A capsule from a to b of radius r: the half stadium (half discs at the ends of a strip)
    revolved about its axis, one solid (a cylinder and two spheres fused would meet tangentially
    along circles, which OpenCASCADE's booleans turn into bad faces)."""
    d = [b[i] - a[i] for i in range(3)]
    length = math.sqrt(sum(x * x for x in d))
    h = length / 2
    # In the xy plane about the y axis: bottom pole, equator circles, top pole.
    p = [occ.addPoint(0, -h - r, 0), occ.addPoint(r, -h, 0), occ.addPoint(r, h, 0),
         occ.addPoint(0, h + r, 0), occ.addPoint(0, h, 0), occ.addPoint(0, -h, 0)]
    curves = [occ.addCircleArc(p[0], p[5], p[1]), occ.addLine(p[1], p[2]),
              occ.addCircleArc(p[2], p[4], p[3]), occ.addLine(p[3], p[0])]
    face = occ.addPlaneSurface([occ.addCurveLoop(curves)])
    out = occ.revolve([(2, face)], 0, 0, 0, 0, 1, 0, 2 * math.pi)
    solid = [x for x in out if x[0] == 3]
    # Turn the y axis onto d, move the centre to the midpoint of a and b.
    u = [x / length for x in d]
    axis = [u[2], 0.0, -u[0]]  # y x u
    s = math.sqrt(axis[0] ** 2 + axis[2] ** 2)
    if s > 1e-12:
        occ.rotate(solid, 0, 0, 0, *axis, math.atan2(s, u[1]))
    elif u[1] < 0:
        occ.rotate(solid, 0, 0, 0, 1, 0, 0, math.pi)
    occ.translate(solid, *[(a[i] + b[i]) / 2 for i in range(3)])
    return solid[0]


def part_distance(name, p):
    """Signed distance from p to the bear's part `name`."""
    kind, *args = BEAR[name]
    if kind == "sphere":
        return math.dist(p, args[0]) - args[1]
    a, b, r = args
    ab = [b[i] - a[i] for i in range(3)]
    ap = [p[i] - a[i] for i in range(3)]
    t = min(1.0, max(0.0, sum(ab[i] * ap[i] for i in range(3)) / sum(x * x for x in ab)))
    return math.dist(p, [a[i] + t * ab[i] for i in range(3)]) - r


def build(name):
    """Builds the solid `name` in the current Gmsh model; returns (exact volume or None)."""
    occ = gmsh.model.occ
    if name == "gummy_bear":
        solids = bear_solids(occ)
        occ.fuse(solids[:1], solids[1:])
        return None
    if name == "torus":
        big, small = 0.3, 0.1
        t = occ.addTorus(0, 0, 0, big, small)
        occ.rotate([(3, t)], 0, 0, 0, 1, 0, 0, -math.pi / 2)  # axis z -> y
        occ.translate([(3, t)], 0, small, 0)
        return 2 * math.pi**2 * big * small**2
    if name == "bowl":
        outer, inner = 0.4, 0.36
        a = occ.addSphere(0, outer, 0, outer)
        b = occ.addSphere(0, outer, 0, inner)
        shell, _ = occ.cut([(3, a)], [(3, b)])
        top = occ.addBox(-1, outer, -1, 2, 1, 2)  # everything above the centre goes
        occ.cut(shell, [(3, top)])
        return 2 / 3 * math.pi * (outer**3 - inner**3)
    raise ValueError(name)


def mesh_solid(name):
    """Meshes the solid's boundary; returns (vertices, triangles, solid volume)."""
    gmsh.model.add(name)
    exact = build(name)
    gmsh.model.occ.synchronize()
    volumes = gmsh.model.getEntities(3)
    assert len(volumes) == 1, f"{name}: {len(volumes)} solids, expected one"
    volume = exact if exact is not None else gmsh.model.occ.getMass(*volumes[0])
    gmsh.option.setNumber("Mesh.MeshSizeMin", SIZES[name] / 2)
    gmsh.option.setNumber("Mesh.MeshSizeMax", SIZES[name])
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 12)
    gmsh.option.setNumber("General.Verbosity", 2)
    gmsh.model.mesh.generate(2)

    tags, coords, _ = gmsh.model.mesh.getNodes()
    index = {int(t): i for i, t in enumerate(tags)}
    vertices = [tuple(coords[3 * i:3 * i + 3]) for i in range(len(tags))]
    triangles = []
    # Each boundary surface with its orientation relative to the solid (a negative tag: its
    # triangles face inwards and are turned).
    for dim, tag in gmsh.model.getBoundary(volumes, oriented=True):
        types, _, nodes = gmsh.model.mesh.getElements(2, abs(tag))
        for ty, nn in zip(types, nodes):
            assert ty == 2, f"{name}: element type {ty} on a surface"
            for k in range(0, len(nn), 3):
                t = [index[int(nn[k])], index[int(nn[k + 1])], index[int(nn[k + 2])]]
                triangles.append(t if tag > 0 else [t[0], t[2], t[1]])
    gmsh.model.remove()
    # Keep only the vertices used (curve and point nodes are used; nothing else exists).
    used = sorted({v for t in triangles for v in t})
    renumber = {v: i for i, v in enumerate(used)}
    return ([vertices[v] for v in used], [[renumber[v] for v in t] for t in triangles], volume)


def orient_outwards(name, vertices, triangles):
    """Checks closed and manifold; makes neighbours agree and the normals face outwards."""
    edges = {}
    for f, t in enumerate(triangles):
        for c in range(3):
            a, b = t[c], t[(c + 1) % 3]
            edges.setdefault((min(a, b), max(a, b)), []).append(f)
    bad = [e for e, fs in edges.items() if len(fs) != 2]
    assert not bad, f"{name}: {len(bad)} edges not in exactly two triangles, e.g. {bad[0]}"
    # Breadth-first over neighbours: a triangle whose shared edge runs the same way is turned.
    flip = [None] * len(triangles)
    for seed in range(len(triangles)):
        if flip[seed] is not None:
            continue
        flip[seed] = False
        queue = [seed]
        while queue:
            f = queue.pop()
            t = triangles[f] if not flip[f] else [triangles[f][0], triangles[f][2],
                                                  triangles[f][1]]
            for c in range(3):
                a, b = t[c], t[(c + 1) % 3]
                for g in edges[(min(a, b), max(a, b))]:
                    if g == f:
                        continue
                    u = triangles[g]
                    same = any(u[d] == a and u[(d + 1) % 3] == b for d in range(3))
                    want = same  # same direction: g must be turned (relative to stored)
                    if flip[g] is None:
                        flip[g] = want
                        queue.append(g)
                    else:
                        assert flip[g] == want, f"{name}: not orientable"
    triangles = [[t[0], t[2], t[1]] if fl else t for t, fl in zip(triangles, flip)]
    if enclosed_volume(vertices, triangles) < 0:
        triangles = [[t[0], t[2], t[1]] for t in triangles]
    return triangles


def enclosed_volume(vertices, triangles):
    total = 0.0
    for a, b, c in triangles:
        p, q, r = vertices[a], vertices[b], vertices[c]
        total += (p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) +
                  p[2] * (q[0] * r[1] - q[1] * r[0]))
    return total / 6


def bear_groups(vertices, triangles):
    """Each triangle's part: the part whose surface is nearest its centroid."""
    names = list(BEAR)
    groups = {n: [] for n in names}
    for f, (a, b, c) in enumerate(triangles):
        centroid = [(vertices[a][i] + vertices[b][i] + vertices[c][i]) / 3 for i in range(3)]
        best = min(names, key=lambda n: abs(part_distance(n, centroid)))
        groups[best].append(f)
    return groups


def write_obj(path, title, vertices, triangles, groups=None):
    with open(path, "w") as out:
        out.write(f"# {title}\n# made by scripts/make_assets.py (Gmsh/OpenCASCADE); units m, "
                  f"y up; {len(vertices)} vertices, {len(triangles)} triangles\n")
        for v in vertices:
            out.write("v %.6f %.6f %.6f\n" % v)
        if groups is None:
            groups = {None: range(len(triangles))}
        for g, faces in groups.items():
            if g is not None:
                out.write(f"g {g}\n")
            for f in faces:
                a, b, c = triangles[f]
                out.write(f"f {a + 1} {b + 1} {c + 1}\n")


def read_obj(path):
    vertices, triangles = [], []
    with open(path) as f:
        for line in f:
            w = line.split()
            if w and w[0] == "v":
                vertices.append(tuple(float(x) for x in w[1:4]))
            elif w and w[0] == "f":
                triangles.append([int(x.split("/")[0]) - 1 for x in w[1:4]])
    return vertices, triangles


TITLES = {
    "gummy_bear": "gummy bear from spheres and capsules, 0.32 m tall, on y = 0, facing +z",
    "torus": "torus on y = 0, axis y, radii 0.3 m and 0.1 m",
    "bowl": "bowl, open side up: lower half of a spherical shell, radii 0.4 m and 0.36 m, "
            "bottom on y = 0",
}


def make(name):
    vertices, triangles, solid_volume = mesh_solid(name)
    # Round as written, so that the checks below see the file's numbers.
    vertices = [tuple(float("%.6f" % x) for x in v) for v in vertices]
    triangles = orient_outwards(name, vertices, triangles)
    volume = enclosed_volume(vertices, triangles)
    error = abs(volume - solid_volume) / solid_volume
    assert error < 0.02, f"{name}: mesh volume {volume:.6g}, solid {solid_volume:.6g}"
    groups = bear_groups(vertices, triangles) if name == "gummy_bear" else None
    return vertices, triangles, groups, volume, solid_volume


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=ASSETS, help="folder of the meshes (default assets/)")
    ap.add_argument("--check", action="store_true",
                    help="compare fresh meshes with the files in --out, write nothing")
    ap.add_argument("names", nargs="*", default=list(SIZES), help="assets (default: all)")
    args = ap.parse_args()
    for n in args.names:
        if n not in SIZES:
            print(f"make_assets: unknown asset \"{n}\"; allowed: {', '.join(SIZES)}",
                  file=sys.stderr)
            return 2
    if gmsh is None:
        print("make_assets: needs Gmsh's Python API (Debian: python3-gmsh)", file=sys.stderr)
        return 77 if args.check else 1  # 77: the check is skipped (ctest SKIP_RETURN_CODE)
    gmsh.initialize(["make_assets", "-nopopup"], readConfigFiles=False)
    failed = 0
    for name in args.names:
        vertices, triangles, groups, volume, solid_volume = make(name)
        path = os.path.join(args.out, name + ".obj")
        line = (f"{name}: {len(vertices)} vertices, {len(triangles)} triangles, closed, "
                f"volume {volume:.6g} m^3 (solid {solid_volume:.6g})")
        if args.check:
            v2, t2 = read_obj(path)
            vol2 = enclosed_volume(v2, t2)
            ok = len(t2) == len(triangles) and abs(vol2 - volume) <= 1e-9 + 1e-6 * volume
            print(f"{line}; {path}: {len(t2)} triangles, volume {vol2:.6g}: "
                  f"{'same' if ok else 'DIFFERENT'}")
            failed += not ok
        else:
            os.makedirs(args.out, exist_ok=True)
            write_obj(path, TITLES[name], vertices, triangles, groups)
            print(f"{line} -> {path}")
    gmsh.finalize()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
