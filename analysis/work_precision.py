"""Work-precision diagrams and "cheapest method for a tolerance" tables.

Reads the speed-accuracy tables of `mpmtb suite speed-accuracy`
(`<suites>/speed_accuracy/<case>.csv`, cases/suite/README.md): per run the
error against the exact solution and the cost of one run, the median of
3 repetitions timed alone, each of at least 0.5 s of stepping (`time_s`,
min and max in `time_min_s`, `time_max_s`), its CPU time and its
particle-steps. The diagrams follow the form of the SciML benchmarks for ODE
solvers (error against time, one line per method through its grids): small
multiples, one panel per kernel, one line per transfer, the spread of the
repetitions as horizontal error bars, and the Pareto front of the whole case
(no run is both cheaper and more accurate) in black.

A method is transfer x kernel x time integrator: the implicit integrators
(backward Euler, Newmark) run the same grids at larger steps (the `cfl`
column), one line per integrator and CFL, marked by integrator (circle:
explicit, square: backward Euler, triangle: Newmark) and dashed by CFL.

  <case>_work_precision.png  error against time per run (top row) and against
                             particle-steps (bottom row), one column per kernel
"""
import math
import os

import numpy as np

import mpmtb_plots as mp

plt = mp.plt


def num(row, key):
    try:
        return mp.parse_float(row.get(key, ""))
    except ValueError:
        return np.nan


def usable(rows):
    """Ok runs with a positive error and a timed cost."""
    return [r for r in rows if r.get("status") == "ok"
            and num(r, "error") > 0 and num(r, "time_s") > 0]


def kernels_of(rows):
    names = list(dict.fromkeys(r["kernel"] for r in rows))
    return sorted(names, key=lambda k: (mp.KERNELS.index(k)
                                        if k in mp.KERNELS else 99, k))


def transfers_of(rows):
    names = list(dict.fromkeys(r["transfer"] for r in rows))
    return sorted(names, key=lambda t: (mp.TRANSFERS.index(t)
                                        if t in mp.TRANSFERS else 99, t))


def lines_of(rows):
    """The lines of a panel: (transfer, integrator, cfl), the explicit ones
    first, each integrator's CFLs ascending."""
    keys = {line_key(r) for r in rows}
    return sorted(keys, key=lambda k: (
        mp.INTEGRATORS.index(k[1]) if k[1] in mp.INTEGRATORS else 99,
        mp.TRANSFERS.index(k[0]) if k[0] in mp.TRANSFERS else 99, k[0],
        cfl_value(k[2])))


def cfl_value(text):
    """A CFL cell as a number (0 where the table has none)."""
    v = num({"cfl": text}, "cfl")
    return v if np.isfinite(v) else 0.0


def line_key(row):
    """(transfer, integrator, CFL as printed): a line through the grids."""
    return (row["transfer"], mp.integrator_of(row), row.get("cfl", ""))


def line_label(transfer, integrator, cfl):
    if integrator == "explicit":
        return transfer
    return f"{transfer}/{integrator} CFL {cfl_value(cfl):g}"


CFL_DASHES = ("--", "-.", ":", (0, (5, 1)))


def line_dash(rows, transfer, integrator, cfl):
    """Solid for the explicit lines; for an implicit integrator's lines a
    dash pattern by the rank of the CFL among its CFLs."""
    if integrator == "explicit":
        return "-"
    cfls = sorted({cfl_value(r.get("cfl", "")) for r in rows
                   if mp.integrator_of(r) == integrator})
    return CFL_DASHES[cfls.index(cfl_value(cfl)) % len(CFL_DASHES)]


def error_label(rows):
    key = rows[0].get("error_key", "") if rows else ""
    return {"field_rel": "displacement field error / amplitude (max over t)",
            "disp_l2": "displacement L2 error (max over t)"}.get(key, key or
                                                                 "error")


def plot_work_precision(path):
    """Draw <case>_work_precision.png next to the table; returns [path]."""
    rows = usable(mp.read_table(path)[1]) if os.path.isfile(path) else []
    if not rows:
        return []
    case = os.path.basename(path)[:-4]
    kernels = kernels_of(rows)
    fig, axes = plt.subplots(2, len(kernels), squeeze=False, sharey=True,
                             figsize=(3.6 * len(kernels) + 1.2, 7.0))
    for row_axes, cost, flag, label in (
            (axes[0], "time_s", "pareto_time",
             "time per run [s] (median of 3, bars: min-max)"),
            (axes[1], "particle_steps", "pareto_work", "particle-steps")):
        front = sorted((num(r, cost), num(r, "error")) for r in rows
                       if r.get(flag) == "1")
        for ax, kernel in zip(row_axes, kernels):
            mine = [r for r in rows if r["kernel"] == kernel]
            for key in lines_of(mine):
                transfer, integrator, cfl = key
                pts = sorted(((num(r, cost), num(r, "error"), i, r)
                              for i, r in enumerate(mine)
                              if line_key(r) == key), key=lambda p: p[:3])
                x = np.array([p[0] for p in pts])
                y = np.array([p[1] for p in pts])
                style = mp.line_style(transfer, kernel)
                style["linestyle"] = line_dash(rows, *key)
                marker = mp.integrator_marker(integrator)
                name = line_label(*key)
                if cost == "time_s":
                    lo = x - np.array([num(p[3], "time_min_s") for p in pts])
                    hi = np.array([num(p[3], "time_max_s") for p in pts]) - x
                    ax.errorbar(x, y, xerr=[np.nan_to_num(lo),
                                            np.nan_to_num(hi)],
                                marker=marker, markersize=3.5, capsize=2,
                                label=name, **style)
                else:
                    ax.plot(x, y, marker=marker, markersize=3.5, label=name,
                            **style)
            if front:
                fx, fy = zip(*front)
                ax.step(fx, fy, where="post", color="black", linewidth=0.8,
                        alpha=0.6, label="Pareto front (all kernels)")
            on_front = [(num(r, cost), num(r, "error")) for r in mine
                        if r.get(flag) == "1"]
            if on_front:
                ox, oy = zip(*on_front)
                ax.scatter(ox, oy, s=70, facecolors="none",
                           edgecolors="black", zorder=3)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.grid(True, which="both", alpha=0.3)
            ax.set_xlabel(label, fontsize=8)
            ax.set_title(kernel, fontsize=9)
        row_axes[0].set_ylabel(error_label(rows), fontsize=8)
    fig.suptitle(f"work-precision: {case} (each run alone, one thread; "
                 "circled: on the Pareto front)")
    seen = {}
    for ax in axes[0]:
        handles, labels = ax.get_legend_handles_labels()
        for h, lab in zip(handles, labels):
            seen.setdefault(lab, h)
    fig.legend(list(seen.values()), list(seen.keys()), loc="center left",
               bbox_to_anchor=(1.0, 0.5), fontsize=8)
    fig.tight_layout()
    out = path[:-4] + "_work_precision.png"
    mp.save_figure(fig, out)
    return [out]


# ------------------------------------------------------ cheapest tables --

def tolerances(rows):
    """Tolerances 1 and 3 times 10^k, largest first, from the largest decade
    below the case's largest error down to its smallest error: the range where
    the choice of method matters (a tolerance above every error is met by the
    cheapest run of all)."""
    errors = [num(r, "error") for r in rows]
    top = math.floor(math.log10(max(errors)) + 1e-9)
    bottom = math.log10(min(errors))
    tols = []
    for k in range(top, math.floor(bottom) - 1, -1):
        for m in (1.0, 0.3):
            t = m * 10.0 ** k
            if t <= 10.0 ** top * (1 + 1e-9) and math.log10(t) >= bottom - 1e-9:
                tols.append(t)
    return tols


def cheapest(rows, tol, count=3):
    """The `count` cheapest methods (each with its cheapest grid and, for an
    implicit integrator, step) whose error is at most tol, by median time per
    run."""
    best = {}
    for r in rows:
        if num(r, "error") <= tol:
            key = (r["transfer"], r["kernel"], mp.integrator_of(r))
            if key not in best or num(r, "time_s") < num(best[key], "time_s"):
                best[key] = r
    return sorted(best.values(), key=lambda r: num(r, "time_s"))[:count]


def cost_text(r):
    return (f"{num(r, 'time_s'):.3g} s ({num(r, 'time_min_s'):.3g}-"
            f"{num(r, 'time_max_s'):.3g})")


def run_name(r):
    """`method` as the tables print it: with its CFL for an implicit one."""
    name = mp.method_label(r["transfer"], r["kernel"], mp.integrator_of(r))
    if mp.integrator_of(r) == "explicit":
        return f"`{name}`"
    return f"`{name}` CFL {num(r, 'cfl'):g}"


def pick_text(r):
    return (f"{run_name(r)} {r['cells']} cells: "
            f"{cost_text(r)}, error {num(r, 'error'):.2g}")


def cheapest_table(rows):
    """Markdown rows: tolerance, then the cheapest three methods reaching it."""
    body = []
    for tol in tolerances(rows):
        picks = cheapest(rows, tol)
        cells = [pick_text(r) for r in picks] + ["-"] * (3 - len(picks))
        body.append([f"{tol:.0e}".replace("e-0", "e-")] + cells)
    return body


def front_text(rows, flag):
    """The runs on a front, cheapest first: method, cells, field error and
    period error."""
    front = sorted((r for r in rows if r.get(flag) == "1"),
                   key=lambda r: num(r, "time_s"))
    return ", ".join(f"{run_name(r)} {r['cells']} "
                     f"(error {num(r, 'error'):.2g}, period "
                     f"{num(r, 'period_error'):.2g})" for r in front)
