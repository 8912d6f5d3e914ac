"""Shared helpers of plot.py and animate.py: read a jelly recording (HDF5) and draw its bodies
(their surfaces, or particles and springs), and its terrains on a matplotlib 3-D axis. The simulation's y axis is up; the plots
show (x, z, y) so that up is up on screen."""
import h5py
import numpy as np

SPRING_TYPES = {0: "structural", 1: "shear", 2: "bending"}


def attr_text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


class Body:
    """One body of a recording: its name, kind, particle range and render surface (triangles
    and vertex positions per frame), as /particles/<name>/ holds them."""

    def __init__(self, name, group, frames):
        self.name = name
        self.kind = attr_text(group.attrs.get("kind", ""))
        self.first_particle = int(group.attrs.get("first_particle", 0))
        self.num_particles = group["position/value"].shape[1]
        self.triangles = None
        self.surface = None  # [T][V][3]
        if "surface" in group:
            self.triangles = group["surface/triangles"][:]
            self.surface = group["surface/position/value"][:frames]


class Recording:
    def __init__(self, path):
        with h5py.File(path, "r") as f:
            groups = sorted(f["particles"].items(),
                            key=lambda item: int(item[1].attrs.get("first_particle", 0)))
            if not groups:
                raise ValueError(f"{path} holds no bodies under /particles")
            first = groups[0][1]
            self.time = first["position/time"][:]
            frames = min([len(self.time)] + [min(len(g["position/value"]), len(g["velocity/value"]))
                                             for _, g in groups])
            self.time = self.time[:frames]
            self.position = np.concatenate([g["position/value"][:frames] for _, g in groups],
                                           axis=1)
            self.velocity = np.concatenate([g["velocity/value"][:frames] for _, g in groups],
                                           axis=1)
            self.bodies = [Body(name, g, frames) for name, g in groups]
            self.springs = f["connectivity/springs"][:]
            self.spring_type = f["connectivity/type"][:]
            self.observables = {name: g["value"][:frames] for name, g in f["observables"].items()}
            self.parameters = {k: v for k, v in f["parameters"].attrs.items()}
            self.terrains = []
            for name, g in f["terrain"].items():
                t = {k: v for k, v in g.attrs.items()}
                t["name"] = name
                t["kind"] = attr_text(t.get("kind", ""))
                t["position"] = g["position/value"][:frames]
                if "rotation" in g:  # [T][3][3]; absent from recordings made before it was
                    t["rotation"] = g["rotation/value"][:frames]
                if "mesh" in g:
                    t["mesh_vertices"] = g["mesh/vertices"][:]
                    t["mesh_triangles"] = g["mesh/triangles"][:]
                self.terrains.append(t)

    @property
    def frames(self):
        return len(self.time)

    def title(self):
        p = self.parameters
        status = attr_text(p.get("run_status", "?"))
        bodies = f"{len(self.bodies)} bodies, " if len(self.bodies) > 1 else ""
        return (f"{bodies}{len(self.position[0]) if self.frames else 0} particles, "
                f"{len(self.springs)} springs, {attr_text(p.get('integrator', '?'))} "
                f"dt={float(p.get('dt', float('nan'))):g} s, run {status}")

    def bounds(self, margin=0.3):
        """Axis limits covering the jelly over the whole run, in plot order (x, z, y)."""
        p = self.position.reshape(-1, 3)
        lo, hi = p.min(axis=0) - margin, p.max(axis=0) + margin
        centre, half = (lo + hi) / 2, (hi - lo).max() / 2
        lo, hi = centre - half, centre + half
        return [(lo[0], hi[0]), (lo[2], hi[2]), (lo[1], hi[1])]


def spring_segments(x, springs):
    """[M][2][3] segments in plot order (x, z, y)."""
    seg = x[springs][:, :, [0, 2, 1]]
    return seg


def surface_polygons(body, frame):
    """[F][3][3] triangles of a body's surface at a frame in plot order (x, z, y), or None."""
    if body.surface is None or len(body.triangles) == 0:
        return None
    return body.surface[frame][body.triangles][:, :, [0, 2, 1]]


def terrain_polygons(rec, frame):
    """Triangles [F][3][3] in plot order of every terrain that is not a plane (obstacles, the
    elevator): its recorded mesh turned by its recorded rotation and moved to its position."""
    polygons = []
    for t in rec.terrains:
        if t["kind"] in ("plane", "slope", "elevator") or "mesh_vertices" not in t:
            continue
        p = t["position"][frame] if len(t["position"]) > frame else t["position"][-1]
        r = np.eye(3)
        if "rotation" in t and len(t["rotation"]):
            r = t["rotation"][min(frame, len(t["rotation"]) - 1)]
        v = t["mesh_vertices"] @ r.T + p
        polygons.append(v[t["mesh_triangles"]][:, :, [0, 2, 1]])
    return polygons


def terrain_surfaces(rec, frame, limits):
    """(X, Z, Y) grids of each terrain's surface at a frame, in plot order."""
    surfaces = []
    (x0, x1), (z0, z1), (y0, y1) = limits
    for t in rec.terrains:
        p = t["position"][frame] if len(t["position"]) > frame else t["position"][-1]
        n = np.asarray(t.get("normal", [0, 1, 0]), dtype=float)
        if t["kind"] == "elevator":
            sx, sz = float(t.get("size_x", 5)) / 2, float(t.get("size_z", 5)) / 2
            X, Z = np.meshgrid([p[0] - sx, p[0] + sx], [p[2] - sz, p[2] + sz])
            Y = np.full_like(X, p[1])
        elif abs(n[1]) > 1e-6:
            X, Z = np.meshgrid(np.linspace(x0, x1, 2), np.linspace(z0, z1, 2))
            Y = p[1] - (n[0] * (X - p[0]) + n[2] * (Z - p[2])) / n[1]
        else:
            continue
        surfaces.append((X, Z, Y))
    return surfaces


def style_axis(ax, limits):
    ax.set_xlim(*limits[0])
    ax.set_ylim(*limits[1])
    ax.set_zlim(*limits[2])
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_zlabel("y (m)")
