#!/usr/bin/python3
"""End-to-end checks of frames, rendering, --config re-runs and progress output.

    /usr/bin/python3 tests/e2e_visual.py MPMTB SOURCE_DIR WORK_DIR CHECK

CHECK is one of: frames, render, reproduce, progress. Frames are read back
with VTK's own XML reader (Debian python3-vtk9) when it is installed, else
with the strict numpy reader of analysis/render.py (which checks the header
type, byte order and every array length), and the test says which it used.
The frame values are checked against the run's own series.csv, which mpmtb
computes separately (core/diagnostics): kinetic energy, momentum, volume, the
J range and the damaged fraction must agree to round-off.
"""

import csv
import glob
import json
import os
import shutil
import struct
import subprocess
import sys

import numpy as np

MPMTB, SOURCE, WORK = sys.argv[1:4]
sys.path.insert(0, os.path.join(SOURCE, "analysis"))
import render  # noqa: E402


def run(*args, expect=0, **kw):
    r = subprocess.run([MPMTB, *args], capture_output=True, text=True, **kw)
    if r.returncode != expect:
        sys.exit(f"mpmtb {' '.join(args)}: exit {r.returncode}, expected {expect}\n{r.stderr}")
    return r


def fresh(name):
    d = os.path.join(WORK, name)
    shutil.rmtree(d, ignore_errors=True)
    return d


def series(d):
    with open(os.path.join(d, "series.csv")) as f:
        rows = list(csv.DictReader(f))
    return {int(float(r["step"])): {k: float(v) for k, v in r.items()} for r in rows}


def reader():
    """(name, read(path) -> (points, {name: array}, n_verts, time))."""
    try:
        import vtk
        from vtk.util.numpy_support import vtk_to_numpy
    except ImportError:
        def own(path):
            points, fields, time = render.read_vtp(path)
            return points, fields, len(points), time
        return "own strict reader (python3-vtk9 not installed)", own

    def read(path):
        r = vtk.vtkXMLPolyDataReader()
        r.SetFileName(path)
        r.Update()
        if r.GetErrorCode():
            sys.exit(f"VTK cannot read {path}")
        o = r.GetOutput()
        pd = o.GetPointData()
        fields = {pd.GetArrayName(i): vtk_to_numpy(pd.GetArray(i)) for i in range(pd.GetNumberOfArrays())}
        time = o.GetFieldData().GetArray("TimeValue").GetValue(0)
        return vtk_to_numpy(o.GetPoints().GetData()), fields, o.GetNumberOfVerts(), time
    return f"VTK {vtk.vtkVersion.GetVTKVersion()} vtkXMLPolyDataReader", read


def close(a, b, scale, what, tol=1e-12):
    if abs(a - b) > tol * scale:
        sys.exit(f"{what}: frame {a!r} vs series {b!r} (scale {scale:g})")


def check_frames_of(d, name, read):
    summary = json.load(open(os.path.join(d, "summary.json")))
    rows = series(d)
    pvd = render.read_pvd(os.path.join(d, "particles.pvd"))
    files = sorted(glob.glob(os.path.join(d, "frames", "particles_*.vtp")))
    # The collection references every frame, once, in time order, from 0 to t_end.
    assert sorted(f for _, f in pvd) == files, (pvd, files)
    times = [t for t, _ in pvd]
    assert times == sorted(set(times)) and times[0] == 0.0, times
    assert abs(times[-1] - summary["t_end"]) < 1e-12 * summary["t_end"], times[-1]
    assert summary["frames"]["count"] == len(files)
    # Atomic writes leave no temporary file behind.
    left = glob.glob(os.path.join(d, "**", "*.tmp*"), recursive=True)
    assert not left, left
    compared = 0
    for t, path in pvd:
        points, f, verts, time = read(path)
        n = summary["particles"]
        assert len(points) == n and verts == n, (path, len(points), verts, n)
        assert time == t, (time, t)
        m, v = f["mass"], f["velocity"]
        assert f["J"].shape == (n,) and f["von_mises"].shape == (n,) and f["material"].shape == (n,)
        row = rows[min(rows, key=lambda s: abs(rows[s]["t"] - t))]
        if row["t"] != t:
            continue
        compared += 1
        K = 0.5 * float(np.sum(m * np.sum(v * v, axis=1)))
        scale = max(row["kinetic"], 1e-300)
        close(K, row["kinetic"], scale, f"{name} kinetic at t={t}")
        p_scale = float(np.sum(m * np.linalg.norm(v, axis=1))) + 1e-300
        for a, c in enumerate("xyz"):
            close(float(np.sum(m * v[:, a])), row["p" + c], p_scale, f"{name} p{c} at t={t}")
        close(float(np.sum(f["volume"])), row["volume"], row["volume"], f"{name} volume at t={t}")
        assert float(f["J"].min()) == row["J_min"] and float(f["J"].max()) == row["J_max"], name
        if "damaged_fraction" in row:
            d_ = f["damage"]
            assert d_.min() >= 0 and d_.max() <= 1
            V0 = f["volume"] / f["J"]
            close(float(np.sum(V0[d_ >= 0.5]) / np.sum(V0)), row["damaged_fraction"], 1,
                  f"{name} damaged fraction at t={t}")
        if t == 0:
            # In the rest shape (F = I) every model is stress free.
            assert float(f["von_mises"].max()) < 1e-9, name
    assert compared >= 2, f"{name}: only {compared} frames coincide with series rows"
    return summary, pvd


def check_frames():
    how, read = reader()
    print(f"frames read with {how}")
    # 2D disks: frames every 20 steps, series every 10 (dt = 1e-3, output 0.01), and the grid.
    d = fresh("frames_disks")
    run("run", "disks", "--cells", "10", "--t-end", "0.2", "--frames-every", "20", "--frames-grid",
        "--quiet", "--out", d)
    summary, pvd = check_frames_of(d, "disks", read)
    assert len(pvd) == 11, len(pvd)
    _, f0, _, _ = read(pvd[0][1])
    assert np.all(np.abs(np.abs(f0["velocity"][:, :2]) - 0.1) < 1e-15), "initial rigid velocity"
    assert np.all(f0["von_mises"] < 1e-9), "stress free at rest"
    # The grid carries the particles' mass exactly (partition of unity).
    grids = render.read_pvd(os.path.join(d, "grid.pvd"))
    assert len(grids) == len(pvd)
    total = float(np.sum(f0["mass"]))
    try:
        import vtk
        from vtk.util.numpy_support import vtk_to_numpy
        r = vtk.vtkXMLImageDataReader()
        r.SetFileName(grids[-1][1])
        r.Update()
        gm = vtk_to_numpy(r.GetOutput().GetPointData().GetArray("mass"))
        assert abs(float(gm.sum()) - total) < 1e-12 * total, (gm.sum(), total)
    except ImportError:
        print("grid: vtk not installed, grid mass not checked")
    # 3D with damage: the pinned block on a coarse grid, frames by time.
    d = fresh("frames_block")
    run("run", "pinned_block", "--cells", "16", "--t-end", "0.1", "--frames-dt", "0.01", "--quiet",
        "--threads", "1", "--out", d)
    _, pvd = check_frames_of(d, "pinned_block", read)
    assert len(pvd) >= 11, len(pvd)
    _, f, _, _ = read(pvd[-1][1])
    assert "damage" in f and float(f["damage"].max()) > 0, "damage grows where the ball strikes"
    assert set(np.unique(f["pinned"])) <= {0, 1} and set(np.unique(f["material"])) == {0}


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n", path
    return struct.unpack(">II", head[16:24])


def check_render():
    import matplotlib.image as mpimg
    d2 = fresh("render_disks")
    run("run", "disks", "--cells", "10", "--t-end", "1.8", "--frames-dt", "0.3", "--quiet", "--out", d2)
    d3 = fresh("render_block")
    run("run", "pinned_block", "--cells", "16", "--t-end", "0.1", "--frames-dt", "0.05", "--quiet",
        "--threads", "1", "--out", d3)
    for d, extra in ((d2, []), (d3, []), (d3, ["--cut", "z=0.25", "--field", "von_mises"]),
                     (d3, ["--view", "iso", "--field", "speed"])):
        out = os.path.join(d, f"img{len(extra)}.png")
        r = subprocess.run(["/usr/bin/python3", os.path.join(SOURCE, "analysis", "render.py"), d,
                            "--size", "480x360", "--out", out, *extra], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        assert png_size(out) == (480, 360), png_size(out)
        img = mpimg.imread(out)
        colours = len(np.unique(img.reshape(-1, img.shape[-1]), axis=0))
        assert colours > 50, f"{out}: only {colours} colours: nothing drawn?"
    gif = os.path.join(d2, "anim.gif")
    r = subprocess.run([MPMTB, "render", d2, "--gif", gif, "--anim-size", "320x240",
                        "--out", os.path.join(d2, "x.png")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    from PIL import Image
    with Image.open(gif) as im:
        assert im.size == (320, 240) and im.n_frames == 7, (im.size, im.n_frames)
    r = subprocess.run([MPMTB, "render", d2, "--field", "nonsense"], capture_output=True, text=True)
    assert r.returncode != 0 and "allowed" in r.stderr, r.stderr


def check_reproduce():
    a, b = fresh("repro_a"), fresh("repro_b")
    run("run", "bar", "--dim", "2", "--cells", "12", "--set", "materials.bar.E=150", "--t-end", "3",
        "--kernel", "cubic", "--quiet", "--out", a)
    s = json.load(open(os.path.join(a, "summary.json")))
    assert s["config"]["materials"]["bar"]["E"] == 150 and s["config"]["grid"]["cells"] == 12
    assert s["git_revision"] and s["build_type"]
    run("run", "--config", os.path.join(a, "summary.json"), "--quiet", "--out", b)
    sa, sb = (open(os.path.join(x, "series.csv"), "rb").read() for x in (a, b))
    assert sa == sb, "series.csv differs after --config"
    s2 = json.load(open(os.path.join(b, "summary.json")))
    assert s2["config"] == s["config"]
    # Overrides on top of a recorded configuration still apply.
    c = fresh("repro_c")
    run("run", "--config", os.path.join(a, "summary.json"), "--t-end", "1", "--quiet", "--out", c)
    assert json.load(open(os.path.join(c, "summary.json")))["t_end"] == 1
    r = run("run", "bar", "--config", os.path.join(a, "summary.json"), "--out", c, expect=2)
    assert "excludes" in r.stderr or "config" in r.stderr, r.stderr


def check_progress():
    d = fresh("progress")
    # Not a terminal: stderr holds only the status line, no carriage return, no escape.
    r = run("run", "bar", "--t-end", "10", "--out", d)
    assert r.stderr.split() == ["bar", "ok"], repr(r.stderr)
    r = run("run", "bar", "--t-end", "10", "--quiet", "--out", d)
    assert r.stderr == "", repr(r.stderr)
    # On a terminal (script(1) gives the run a pseudo-terminal) the line appears.
    if shutil.which("script"):
        cmd = f"{MPMTB} run bar --t-end 10 --out {d}"
        r = subprocess.run(["script", "-qec", cmd, "/dev/null"], capture_output=True)
        assert b"%" in r.stdout and b"steps/s" in r.stdout and b"\r" in r.stdout, r.stdout
        r = subprocess.run(["script", "-qec", cmd + " --quiet", "/dev/null"], capture_output=True)
        assert b"steps/s" not in r.stdout, r.stdout
    else:
        print("script(1) not found: the terminal case is not checked")


if __name__ == "__main__":
    os.makedirs(WORK, exist_ok=True)
    {"frames": check_frames, "render": check_render, "reproduce": check_reproduce,
     "progress": check_progress}[sys.argv[4]]()
    print(f"e2e_visual {sys.argv[4]}: ok")
