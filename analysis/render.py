#!/usr/bin/python3
"""Draws a run's particle frames without ParaView: PNG, and a GIF or MP4.

    /usr/bin/python3 analysis/render.py RUN_DIR [--field F] [--frame N] [--out PNG]
        [--gif OUT.gif | --mp4 OUT.mp4] [--view auto|x|y|z|iso] [--cut AXIS=VALUE]
        [--size WxH] [--vmin V --vmax V] [--fps N] [--max-frames N]

RUN_DIR holds particles.pvd and frames/*.vtp written by
`mpmtb run ... --frames-every K` or `--frames-dt T`. Fields: every point array
in the frames (velocity, mass, volume, J, von_mises, damage, ...), a vector
component as NAME_x/_y/_z, or `speed` (|velocity|). The default field depends
on the scene (bar: velocity_x, disks/spheres: von_mises, pinned_block: damage,
rotating: speed).

2D runs are drawn as they are; 3D runs as a depth-shaded projection along the
view axis (nearest particles on top, farther ones darker; `auto` looks along
the thinnest extent of the body), or as a one-particle-thick slab with
--cut z=0.25. 1D runs give a space-time picture (x across, t up) for the PNG
and a profile per frame for animations. The colour range is fixed over all
frames so that frames compare. Frames are parsed with numpy here (VTK XML
PolyData, appended raw little-endian data with UInt64 headers, as mpmtb writes).
"""

import argparse
import json
import os
import re
import shutil
import sys
import xml.etree.ElementTree as ET

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import animation, cm, colors  # noqa: E402

DEFAULT_FIELD = {"bar": "velocity_x", "disks": "von_mises", "spheres": "von_mises",
                 "pinned_block": "damage", "rotating": "speed"}
DTYPES = {"Float64": "<f8", "Float32": "<f4", "Int64": "<i8", "Int32": "<i4",
          "UInt8": "u1", "UInt64": "<u8"}
DPI = 100


def read_vtp(path):
    """Returns (points (n, 3), {name: array}, time) of one VTK XML PolyData file."""
    with open(path, "rb") as f:
        raw = f.read()
    start = raw.find(b"<AppendedData")
    if start < 0:
        raise ValueError(f"{path}: no <AppendedData> block (only appended raw data is read)")
    root = ET.fromstring(raw[:start] + b"</VTKFile>")
    if root.get("byte_order") != "LittleEndian" or root.get("header_type") != "UInt64":
        raise ValueError(f"{path}: expected byte_order LittleEndian and header_type UInt64")
    head = raw[start:raw.find(b">", start) + 1]
    if b'encoding="raw"' not in head:
        raise ValueError(f"{path}: appended data must be raw")
    data = raw.find(b"_", start + len(head)) + 1

    def array(el):
        offset = data + int(el.get("offset"))
        nbytes = int(np.frombuffer(raw, "<u8", 1, offset)[0])
        values = np.frombuffer(raw, DTYPES[el.get("type")], nbytes // np.dtype(DTYPES[el.get("type")]).itemsize,
                               offset + 8)
        ncomp = int(el.get("NumberOfComponents", "1"))
        return values.reshape(-1, ncomp) if ncomp > 1 else values

    piece = root.find("PolyData/Piece")
    n = int(piece.get("NumberOfPoints"))
    points = array(piece.find("Points/DataArray"))
    fields = {el.get("Name"): array(el) for el in piece.findall("PointData/DataArray")}
    for name, a in fields.items():
        if len(a) != n:
            raise ValueError(f"{path}: array {name} has {len(a)} tuples for {n} points")
    time = None
    for el in root.findall("PolyData/FieldData/DataArray"):
        if el.get("Name") == "TimeValue":
            time = float(el.text)
    return points, fields, time


def read_pvd(path):
    """[(time, absolute file)] of a ParaView collection, in time order."""
    root = ET.parse(path).getroot()
    base = os.path.dirname(path)
    items = [(float(d.get("timestep")), os.path.join(base, d.get("file")))
             for d in root.iter("DataSet")]
    return sorted(items, key=lambda i: i[0])


def field_values(fields, name):
    if name == "speed":
        return np.linalg.norm(fields["velocity"], axis=1)
    m = re.fullmatch(r"(.+)_([xyz])", name)
    if name not in fields and m and m.group(1) in fields and fields[m.group(1)].ndim == 2:
        return fields[m.group(1)][:, "xyz".index(m.group(2))]
    if name not in fields:
        allowed = sorted(fields) + ["speed"] + [f"{k}_x" for k, v in fields.items() if v.ndim == 2]
        sys.exit(f"render: no field '{name}'; allowed: {', '.join(allowed)}")
    v = fields[name]
    return np.linalg.norm(v, axis=1) if v.ndim == 2 else v.astype(float)


class Run:
    def __init__(self, run_dir):
        pvd = os.path.join(run_dir, "particles.pvd")
        if not os.path.exists(pvd):
            sys.exit(f"render: {pvd} not found: run with `mpmtb run ... --frames-every K` "
                     "or `--frames-dt T`")
        self.frames = read_pvd(pvd)
        with open(os.path.join(run_dir, "summary.json")) as f:
            self.summary = json.load(f)
        self.scene = self.summary.get("scene", "")
        self.dim = int(self.summary.get("dim", 3))
        self.spacing = float(self.summary["dx"]) / int(self.summary["ppc"])
        config = self.summary.get("config", {})
        dom = config.get("domain", {})
        self.lo = np.array(dom.get("min", [0, 0, 0]), float)
        self.hi = np.array(dom.get("max", [1, 1, 1]), float)
        self.colliders = config.get("colliders", [])
        # Up: against gravity when there is some, else z.
        g = np.array(config.get("physics", {}).get("gravity", [0, 0, 0]), float)
        self.up = int(np.argmax(np.abs(g))) if np.any(g) else 2
        self.cache = {}

    def load(self, k):
        if k not in self.cache:
            self.cache = {k: read_vtp(self.frames[k][1])}  # keep one: frames can be large
        return self.cache[k]


def color_range(run, field, picks, vmin, vmax):
    """Fixed over the frames: damage [0, 1]; signed fields symmetric; else [0 or min, max]."""
    if field == "damage":
        lo, hi = 0.0, 1.0
    else:
        values = np.concatenate([field_values(run.load(k)[1], field) for k in picks])
        values = values[np.isfinite(values)]
        # 0.1 and 99.9 percentiles: a few extreme particles do not wash out the rest.
        lo, hi = (float(np.percentile(values, 0.1)), float(np.percentile(values, 99.9))) \
            if values.size else (0.0, 1.0)
        if lo < 0 < hi:
            lo, hi = -max(-lo, hi), max(-lo, hi)
        elif lo >= 0 and field != "J":
            lo = 0.0
        if hi <= lo:
            hi = lo + (abs(lo) or 1.0) * 1e-6
    return (lo if vmin is None else vmin), (hi if vmax is None else vmax)


def colormap(field, lo, hi):
    if field == "damage":
        return plt.get_cmap("YlOrRd")
    return plt.get_cmap("RdBu_r" if lo < 0 < hi else "viridis")


def view_axes(run, view, points):
    """(screen x axis, screen y axis, depth axis) for a 3D projection."""
    if view == "auto":
        extent = points.max(axis=0) - points.min(axis=0)
        view = "xyz"[int(np.argmin(extent))]
    return {"x": (1, 2, 0), "y": (0, 2, 1), "z": (0, 1, 2)}.get(view, "iso"), view


def project(points, axes, up):
    """Screen coordinates (n, 2) and depth (larger = nearer the camera)."""
    if axes == "iso":
        # Camera 30 degrees around the up axis from the next axis, 25 degrees above.
        u = np.eye(3)[up]
        a, b = np.eye(3)[(up + 1) % 3], np.eye(3)[(up + 2) % 3]  # (a, b, up) right-handed
        az, el = np.radians(30.0), np.radians(25.0)
        toward = np.cos(el) * (np.cos(az) * a + np.sin(az) * b) + np.sin(el) * u
        right = np.cross(u, toward)
        right /= np.linalg.norm(right)
        screen_up = np.cross(toward, right)
        return np.stack([points @ right, points @ screen_up], axis=1), points @ toward
    a, b, d = axes
    return points[:, [a, b]], points[:, d]


def draw_frame(fig, ax, cax, run, k, field, norm, cmap, args):
    ax.clear()
    points, fields, time = run.load(k)
    values = field_values(fields, field)
    if time is None:
        time = run.frames[k][0]
    label = field.replace("_", " ")
    if run.dim == 1:
        ax.plot(points[:, 0], values, ".-", color="0.3", ms=3, lw=0.8)
        ax.scatter(points[:, 0], values, c=values, cmap=cmap, norm=norm, s=14, zorder=3)
        ax.set_xlim(run.lo[0], run.hi[0])
        pad = 0.05 * (norm.vmax - norm.vmin)
        ax.set_ylim(norm.vmin - pad, norm.vmax + pad)
        ax.set_xlabel("x")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    else:
        names = "xyz"
        if run.dim == 2:
            xy, depth, sx, sy = points[:, :2], None, 0, 1
        else:
            axes, view = view_axes(run, args.view, points)
            keep = np.ones(len(points), bool)
            if args.cut:
                axis, value = args.cut
                keep = np.abs(points[:, axis] - value) <= 0.5 * run.spacing
                if axes != "iso":
                    others = [i for i in range(3) if i != axis]
                    axes = (others[0], others[1], axis)
            points, values = points[keep], values[keep]
            xy, depth = project(points, axes, run.up)
            sx, sy = (axes[0], axes[1]) if axes != "iso" else (None, None)
        rgba = cmap(norm(values))
        if depth is not None and len(depth):
            order = np.argsort(depth)  # far first, near on top
            xy, rgba, depth = xy[order], rgba[order], depth[order]
            span = depth.max() - depth.min()
            shade = 0.55 + 0.45 * ((depth - depth.min()) / span if span > 0 else 1.0)
            rgba[:, :3] *= shade[:, None]
        ax.set_aspect("equal", adjustable="box")
        if sx is not None:
            ax.set_xlim(run.lo[sx], run.hi[sx])
            ax.set_ylim(run.lo[sy], run.hi[sy])
            ax.set_xlabel(names[sx])
            ax.set_ylabel(names[sy])
        else:
            ax.set_xlim(xy[:, 0].min() - 0.1, xy[:, 0].max() + 0.1)
            ax.set_ylim(xy[:, 1].min() - 0.1, xy[:, 1].max() + 0.1)
            ax.set_xticks([])
            ax.set_yticks([])
        # Squares one particle spacing wide, in points^2.
        ax.apply_aspect()
        width_px = ax.get_position().width * fig.get_figwidth() * DPI
        px_per_unit = width_px / (ax.get_xlim()[1] - ax.get_xlim()[0])
        size = (1.15 * run.spacing * px_per_unit * 72.0 / DPI) ** 2
        ax.scatter(xy[:, 0], xy[:, 1], c=rgba, s=max(size, 0.5), marker="s", linewidths=0)
        if sx is not None:
            for c in run.colliders:  # the kinematic ball, where it is at this time
                center = np.array(c["center"], float) + time * np.array(c.get("velocity", [0, 0, 0]), float)
                r2 = float(c["radius"]) ** 2
                if run.dim == 3 and args.cut:  # its section by the cut plane
                    r2 -= (center[args.cut[0]] - args.cut[1]) ** 2
                if r2 > 0:
                    ax.add_patch(plt.Circle((center[sx], center[sy]), np.sqrt(r2), fill=False,
                                            ls="--", lw=1.2, color="0.2", zorder=3))
    cut = f", cut {'xyz'[args.cut[0]]} = {args.cut[1]:g}" if args.cut else ""
    ax.set_title(f"{run.scene} ({run.dim}D): {label}, t = {time:.4g}{cut}")
    cax.clear()
    fig.colorbar(cm.ScalarMappable(norm=norm, cmap=cmap), cax=cax, label=label)


def spacetime(fig, ax, cax, run, field, norm, cmap):
    """1D: the field over x (across) and t (up), one row per frame."""
    times, xs, vs = [], [], []
    for k in range(len(run.frames)):
        points, fields, time = run.load(k)
        times.append(run.frames[k][0] if time is None else time)
        xs.append(points[:, 0])
        vs.append(field_values(fields, field))
    xs, vs = np.array(xs), np.array(vs)
    t = np.array(times)
    tt = np.repeat(t[:, None], xs.shape[1], axis=1)
    ax.pcolormesh(xs, tt, vs, cmap=cmap, norm=norm, shading="gouraud")
    ax.set_xlim(run.lo[0], run.hi[0])
    ax.set_xlabel("x")
    ax.set_ylabel("t")
    ax.set_title(f"{run.scene} (1D): {field.replace('_', ' ')} over x and t")
    fig.colorbar(cm.ScalarMappable(norm=norm, cmap=cmap), cax=cax, label=field.replace("_", " "))


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("run_dir")
    p.add_argument("--field", help="field to colour by (default: by scene)")
    p.add_argument("--frame", default="last", help="frame index, or `last` (default)")
    p.add_argument("--out", help="PNG to write (default: RUN_DIR/render_FIELD.png)")
    p.add_argument("--gif", help="also write an animation as GIF (matplotlib PillowWriter)")
    p.add_argument("--mp4", help="also write an animation as MP4 (needs ffmpeg)")
    p.add_argument("--view", default="auto", choices=["auto", "x", "y", "z", "iso"],
                   help="3D: look along this axis, or iso (default auto: the thinnest extent)")
    p.add_argument("--cut", help="3D: draw only the slab AXIS=VALUE, one particle thick")
    p.add_argument("--size", default="1000x800", help="image size in pixels, WxH (default 1000x800)")
    p.add_argument("--anim-size", default="640x512", help="animation size, WxH (default 640x512)")
    p.add_argument("--vmin", type=float)
    p.add_argument("--vmax", type=float)
    p.add_argument("--fps", type=int, default=10)
    p.add_argument("--max-frames", type=int, default=60, help="animation frames at most (default 60)")
    args = p.parse_args(argv)
    if args.cut:
        m = re.fullmatch(r"([xyz])=(.+)", args.cut)
        if not m:
            p.error("--cut must be AXIS=VALUE with AXIS x, y or z, e.g. --cut z=0.25")
        args.cut = ("xyz".index(m.group(1)), float(m.group(2)))
    return args


def figure(size):
    w, h = (int(v) for v in size.lower().split("x"))
    fig = plt.figure(figsize=(w / DPI, h / DPI), dpi=DPI)
    ax = fig.add_axes([0.12, 0.1, 0.68, 0.8])
    cax = fig.add_axes([0.83, 0.1, 0.03, 0.8])
    return fig, ax, cax


def main(argv):
    args = parse_args(argv)
    run = Run(args.run_dir)
    field = args.field or DEFAULT_FIELD.get(run.scene, "von_mises")
    n = len(run.frames)
    frame = n - 1 if args.frame == "last" else int(args.frame)
    if not 0 <= frame < n:
        sys.exit(f"render: --frame {args.frame}: the run has frames 0..{n - 1}")
    anim_frames = list(range(n))
    if len(anim_frames) > args.max_frames:
        anim_frames = sorted(set(np.linspace(0, n - 1, args.max_frames).round().astype(int)))
    picks = sorted(set(anim_frames if (args.gif or args.mp4 or run.dim == 1) else [0, frame, n - 1]))
    lo, hi = color_range(run, field, picks, args.vmin, args.vmax)
    norm = colors.Normalize(lo, hi)
    cmap = colormap(field, lo, hi)

    out = args.out or os.path.join(args.run_dir, f"render_{field}.png")
    fig, ax, cax = figure(args.size)
    if run.dim == 1 and args.frame == "last" and n > 1:
        spacetime(fig, ax, cax, run, field, norm, cmap)
    else:
        draw_frame(fig, ax, cax, run, frame, field, norm, cmap, args)
    fig.savefig(out, dpi=DPI)
    plt.close(fig)
    print(out)

    for path, kind in ((args.gif, "gif"), (args.mp4, "mp4")):
        if not path:
            continue
        if kind == "gif":
            try:
                import PIL  # noqa: F401
            except ImportError:
                sys.exit("render: GIF needs Pillow (Debian: apt-get install python3-pil)")
            writer = animation.PillowWriter(fps=args.fps)
        else:
            if not shutil.which("ffmpeg"):
                sys.exit("render: MP4 needs ffmpeg (Debian: apt-get install ffmpeg); "
                         "use --gif instead")
            writer = animation.FFMpegWriter(fps=args.fps)
        fig, ax, cax = figure(args.anim_size)
        with writer.saving(fig, path, DPI):
            for k in anim_frames:
                draw_frame(fig, ax, cax, run, k, field, norm, cmap, args)
                writer.grab_frame()
        plt.close(fig)
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
