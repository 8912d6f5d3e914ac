#!/usr/bin/python3
"""Renders a jelly recording as a video: the jelly, its structural springs and the terrain in 3-D.

    scripts/animate.py out/slope.h5 [-o out/slope.mp4|out/slope.gif] [--fps 30] [--max-frames N]

mp4 goes through ffmpeg (matplotlib's FFMpegWriter); gif through Pillow when it is installed,
else ffmpeg. Frames are skipped or repeated so that playback runs at real time.
"""
import argparse
import importlib.util
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib import animation  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import jelly_h5  # noqa: E402


def writer_for(output, fps):
    if output.endswith(".gif") and importlib.util.find_spec("PIL") is not None:
        return animation.PillowWriter(fps=fps)
    if not animation.FFMpegWriter.isAvailable():
        sys.exit("error: ffmpeg is not installed (apt-get install ffmpeg)")
    return animation.FFMpegWriter(fps=fps, bitrate=2400)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file", help="a recording written by jelly (HDF5)")
    parser.add_argument("-o", "--output", help="an .mp4 or .gif path (default: FILE with .mp4)")
    parser.add_argument("--fps", type=float, default=30, help="frames per second (default 30)")
    parser.add_argument("--max-frames", type=int, default=0, help="stop after this many frames")
    parser.add_argument("--all-springs", action="store_true", help="draw every spring")
    args = parser.parse_args()
    rec = jelly_h5.Recording(args.file)
    if rec.frames == 0:
        sys.exit(f"error: {args.file} holds no frames")
    output = args.output or os.path.splitext(args.file)[0] + ".mp4"

    # Real time: video frame k shows the recorded frame nearest t0 + k / fps.
    times = np.arange(rec.time[0], rec.time[-1] + 1e-9, 1.0 / args.fps)
    frames = np.searchsorted(rec.time, times).clip(0, rec.frames - 1)
    if args.max_frames > 0:
        frames = frames[:args.max_frames]

    keep = np.ones(len(rec.springs), bool) if args.all_springs else rec.spring_type == 0
    springs = rec.springs[keep]
    limits = rec.bounds()
    fig = plt.figure(figsize=(7, 7))
    ax = fig.add_subplot(projection="3d")
    jelly_h5.style_axis(ax, limits)
    ax.view_init(elev=15, azim=-70)
    lines = Line3DCollection(jelly_h5.spring_segments(rec.position[0], springs),
                             colors="tab:blue", linewidths=0.6)
    ax.add_collection3d(lines)
    dots = ax.scatter([], [], [], s=3, c="navy", depthshade=False)
    surfaces = []
    title = ax.set_title("")
    fig.suptitle(f"{os.path.basename(args.file)}: {rec.title()}", fontsize=9)

    def draw(frame):
        x = rec.position[frame]
        lines.set_segments(jelly_h5.spring_segments(x, springs))
        dots._offsets3d = (x[:, 0], x[:, 2], x[:, 1])
        for s in surfaces:
            s.remove()
        surfaces.clear()
        for X, Z, Y in jelly_h5.terrain_surfaces(rec, frame, limits):
            surfaces.append(ax.plot_surface(X, Z, Y, color="tan", alpha=0.35, linewidth=0))
        title.set_text(f"t = {rec.time[frame]:.2f} s")
        return [lines, dots, title]

    movie = animation.FuncAnimation(fig, draw, frames=frames, blit=False)
    movie.save(output, writer=writer_for(output, args.fps), dpi=100)
    print(f"wrote {output} ({len(frames)} frames)")


if __name__ == "__main__":
    main()
