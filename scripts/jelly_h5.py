"""Shared helpers of plot.py and animate.py: read a jelly recording (HDF5) and draw the jelly,
its springs and its terrains on a matplotlib 3-D axis. The simulation's y axis is up; the plots
show (x, z, y) so that up is up on screen."""
import h5py
import numpy as np

SPRING_TYPES = {0: "structural", 1: "shear", 2: "bending"}


def attr_text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


class Recording:
    def __init__(self, path):
        with h5py.File(path, "r") as f:
            jelly = f["particles/jelly"]
            self.position = jelly["position/value"][:]
            self.velocity = jelly["velocity/value"][:]
            self.time = jelly["position/time"][:]
            frames = min(len(self.time), len(self.position), len(self.velocity))
            self.position, self.velocity, self.time = (
                self.position[:frames], self.velocity[:frames], self.time[:frames])
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
                self.terrains.append(t)

    @property
    def frames(self):
        return len(self.time)

    def title(self):
        p = self.parameters
        status = attr_text(p.get("run_status", "?"))
        return (f"{len(self.position[0]) if self.frames else 0} particles, "
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
