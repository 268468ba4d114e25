"""Figures from the tables of `mpmtb suite` (results/suites by default).

Every function takes the suite folder, draws what its tables hold and
returns the written PNG paths (empty when the table is absent):

  convergence/<case>.png      log-log error against h per kernel, one line per
                              transfer, reference slopes 1 and 2
  convergence/<case>_dt.png   the same against dt at a fixed grid
  stability/stability_map.png largest stable CFL per method and case x ppc
                              (a method: transfer-kernel, /integrator for the
                              implicit ones; ">=" where no tried CFL failed)
  stability/failure_modes.png the failure-mode metrics per method
  speed_accuracy/<case>_work_precision.png  work-precision diagram: error
                              against time per run and particle-steps, one
                              panel per kernel, Pareto front in black
                              (work_precision.py)
  speed_accuracy/throughput.png     particle-steps per second per method
"""
import glob
import os

import numpy as np

import mpmtb_plots as mp
import work_precision as wp

plt = mp.plt


def read_rows(path):
    """Rows of a suite table, or [] when it does not exist."""
    if not os.path.isfile(path):
        return []
    return mp.read_table(path)[1]


def num(row, key):
    """A table cell as float; empty or absent is nan."""
    try:
        return mp.parse_float(row.get(key, ""))
    except ValueError:
        return np.nan


def ordered(names, known):
    """Unique names, the known ones first in canonical order."""
    unique = list(dict.fromkeys(names))
    return sorted(unique, key=lambda n: (known.index(n) if n in known
                                         else len(known), n))


def method_name(row):
    return mp.method_label(row["transfer"], row["kernel"],
                           mp.integrator_of(row))


def method_key(row):
    """(transfer, kernel, integrator) of a table row."""
    return (row["transfer"], row["kernel"], mp.integrator_of(row))


def methods_of(rows):
    """The (transfer, kernel, integrator) triples of the rows: the explicit
    methods first, then each implicit integrator's, in canonical order."""
    triples = {method_key(r) for r in rows}
    return sorted(triples, key=lambda p: (
        mp.INTEGRATORS.index(p[2]) if p[2] in mp.INTEGRATORS else 99,
        mp.TRANSFERS.index(p[0]) if p[0] in mp.TRANSFERS else 99,
        mp.KERNELS.index(p[1]) if p[1] in mp.KERNELS else 99, p))


# ---------------------------------------------------------- convergence --

def reference_slopes(ax, xs, ys):
    """Dashed lines of slope 1 and 2 through the finest points' geometric mean."""
    x0, x1 = min(xs), max(xs)
    finest = [y for x, y in zip(xs, ys) if x == x0]
    y0 = float(np.exp(np.mean(np.log(finest))))
    for slope, style in ((1, ":"), (2, "--")):
        x = np.array([x0, x1])
        ax.plot(x, y0 * (x / x0) ** slope, color="black", linestyle=style,
                linewidth=1.0, label=f"slope {slope}")


def plot_convergence_table(path, xkey, xlabel):
    rows = read_rows(path)
    kernels = ordered([r["kernel"] for r in rows], mp.KERNELS)
    if not kernels:
        return []
    case = os.path.basename(path)[:-4]
    fig, axes = plt.subplots(1, len(kernels), squeeze=False, sharey=True,
                             figsize=(3.6 * len(kernels) + 1.6, 3.8))
    drawn = False
    for ax, kernel in zip(axes[0], kernels):
        xs_all, ys_all = [], []
        lines = [(t, i) for t, k, i in methods_of(rows) if k == kernel]
        for transfer, integrator in lines:
            pts = [(num(r, xkey), num(r, "error")) for r in rows
                   if method_key(r) == (transfer, kernel, integrator)]
            pts = [(x, y) for x, y in pts if x > 0 and y > 0]
            if not pts:
                continue
            x, y = zip(*pts)
            label = transfer if integrator == "explicit" else \
                f"{transfer}/{integrator}"
            ax.plot(x, y, marker=mp.integrator_marker(integrator),
                    markersize=3.5, label=label,
                    **mp.line_style(transfer, kernel))
            xs_all += x
            ys_all += y
        if xs_all:
            reference_slopes(ax, xs_all, ys_all)
            ax.set_xscale("log")
            ax.set_yscale("log")
            drawn = True
        ax.set_title(kernel)
        ax.set_xlabel(xlabel)
        ax.grid(True, which="both", alpha=0.3)
    if not drawn:
        plt.close(fig)
        return []
    axes[0][0].set_ylabel("error")
    fig.suptitle(f"convergence: {case} (ok runs; missing points are "
                 "unstable runs)")
    mp.legend_outside(fig, axes[0][-1])
    out = path[:-4] + ".png"
    mp.save_figure(fig, out)
    return [out]


def plot_convergence(suites):
    out = []
    for path in sorted(glob.glob(os.path.join(suites, "convergence", "*.csv"))):
        name = os.path.basename(path)
        if name == "orders.csv":
            continue
        if name.endswith("_dt.csv"):
            out += plot_convergence_table(path, "dt", "time step dt (fixed grid)")
        else:
            out += plot_convergence_table(path, "h", "cell size h (dt ~ h)")
    return out


# ------------------------------------------------------------ stability --

def stable_text(row):
    """The largest stable CFL of a stable_cfl.csv row as shown: ">=" where no
    tried value failed (the implicit integrators), "-" where none was
    stable."""
    c = num(row, "stable_cfl")
    if not np.isfinite(c):
        return "-"
    return f"{c:.2f}" if row.get("first_unstable_cfl") else f">={c:g}"


def plot_stability_map(suites):
    path = os.path.join(suites, "stability", "stable_cfl.csv")
    rows = read_rows(path)
    if not rows:
        return []
    methods = methods_of(rows)
    columns = list(dict.fromkeys((r["case"], r["ppc"]) for r in rows))
    grid = np.full((len(methods), len(columns)), np.nan)
    text = [["-"] * len(columns) for _ in methods]
    for r in rows:
        i = methods.index(method_key(r))
        j = columns.index((r["case"], r["ppc"]))
        grid[i, j] = num(r, "stable_cfl")
        text[i][j] = stable_text(r)
    fig, ax = plt.subplots(figsize=(max(5.5, 1.3 + 0.9 * len(columns)),
                                    1.2 + 0.38 * len(methods)))
    finite = grid[np.isfinite(grid) & (grid > 0)]
    # The implicit integrators' CFL reaches 100 beside explicit limits near 1:
    # a log colour scale keeps both readable.
    log = finite.size and finite.max() > 10 * finite.min()
    norm = mp.matplotlib.colors.LogNorm() if log else None
    image = ax.imshow(np.ma.masked_invalid(grid), cmap="viridis",
                      aspect="auto", norm=norm)
    middle = (np.exp(np.mean(np.log(finite))) if log else np.mean(finite)) \
        if finite.size else np.nan
    for i in range(len(methods)):
        for j in range(len(columns)):
            ax.text(j, i, text[i][j], ha="center", va="center", fontsize=8,
                    color="white" if np.isfinite(grid[i, j]) and
                    grid[i, j] < middle else "black")
    # A line between the explicit methods and each implicit integrator's.
    for i in range(1, len(methods)):
        if methods[i][2] != methods[i - 1][2]:
            ax.axhline(i - 0.5, color="red", linewidth=1.2)
    ax.set_xticks(range(len(columns)),
                  [f"{c}\nppc {p}" for c, p in columns], fontsize=8)
    ax.set_yticks(range(len(methods)),
                  [mp.method_label(*m) for m in methods])
    estimates = {}
    for r in rows:
        if mp.integrator_of(r) == "explicit":
            estimates[r["kernel"]] = (r["vn_low"], r["vn_high"])
    note = ", ".join(f"{k} {lo}" + ("" if lo == hi else f"-{hi}")
                     for k, (lo, hi) in estimates.items())
    title = f"largest stable CFL (von Neumann: {note})"
    if any(m[2] != "explicit" for m in methods):
        title += ("\nimplicit (below the red line): >= the largest CFL "
                  "tried when none failed")
    ax.set_title(title, fontsize=9)
    fig.colorbar(image, ax=ax, label="CFL")
    fig.tight_layout()
    out = os.path.join(suites, "stability", "stability_map.png")
    mp.save_figure(fig, out)
    return [out]


METRIC_LABELS = {
    "strain_max_rel": "max strain energy / E0",
    "energy_kept": "energy kept E(end)/E0",
    "L_change": "|L - L0| / |L0|",
}


def plot_failure_modes(suites):
    rows = read_rows(os.path.join(suites, "stability", "failure_modes.csv"))
    cases = list(dict.fromkeys(r["case"] for r in rows))
    if not cases:
        return []
    methods = methods_of(rows)
    fig, axes = plt.subplots(1, len(cases), squeeze=False,
                             figsize=(3.2 * len(cases) + 0.6,
                                      1.2 + 0.3 * len(methods)))
    for ax, case in zip(axes[0], cases):
        by_method = {method_key(r): r for r in rows if r["case"] == case}
        values = [num(by_method[m], "value") if m in by_method else np.nan
                  for m in methods]
        floor = 1e-17
        log = mp.spans_decades(values)
        for i, (m, v) in enumerate(zip(methods, values)):
            if np.isfinite(v):
                ax.barh(i, max(abs(v), floor) if log else v,
                        **mp.bar_style(m[0], m[1]))
            else:
                status = by_method.get(m, {}).get("status", "missing")
                ax.text(0.02, i, status, va="center", fontsize=7,
                        transform=ax.get_yaxis_transform(), color="red")
        if log:
            ax.set_xscale("log")
        ax.set_yticks(range(len(methods)),
                      [mp.method_label(*m) for m in methods], fontsize=8)
        ax.invert_yaxis()
        metric = next(r["metric"] for r in rows if r["case"] == case)
        ax.set_xlabel(METRIC_LABELS.get(metric, metric), fontsize=8)
        ax.set_title(case, fontsize=9)
        ax.grid(True, axis="x", alpha=0.3)
    fig.suptitle("failure modes shown on purpose")
    fig.tight_layout()
    out = os.path.join(suites, "stability", "failure_modes.png")
    mp.save_figure(fig, out)
    return [out]


# ------------------------------------------------------- speed-accuracy --

def series_label(row):
    """A work-precision series: the method, with its CFL for an implicit
    one."""
    name = method_name(row)
    if mp.integrator_of(row) == "explicit":
        return name
    return f"{name} CFL {num(row, 'cfl'):g}"


def finest_throughput(rows):
    """{series label: particle-steps/s of the finest ok level}, in the rows'
    order (a series: a method, and for an implicit one its CFL)."""
    best = {}
    for r in rows:
        if r["status"] != "ok":
            continue
        key = series_label(r)
        level = num(r, "level")
        if key not in best or level > best[key][0]:
            best[key] = (level, num(r, "particle_steps_per_second"))
    return {k: v for k, (_, v) in best.items() if np.isfinite(v)}


def plot_throughput(suites, tables):
    cases = [(os.path.basename(p)[:-4], finest_throughput(read_rows(p)))
             for p in tables]
    cases = [(c, t) for c, t in cases if t]
    if not cases:
        return []
    fig, axes = plt.subplots(1, len(cases), squeeze=False,
                             figsize=(4.0 * len(cases) + 1.0, 4.2))
    for ax, (case, rates) in zip(axes[0], cases):
        rows = {series_label(r): r for r in read_rows(
            os.path.join(suites, "speed_accuracy", case + ".csv"))}
        labels = list(rates)
        for i, m in enumerate(labels):
            ax.barh(i, rates[m], **mp.bar_style(rows[m]["transfer"],
                                                rows[m]["kernel"]))
            ax.annotate(f" {rates[m]:.3g}", (rates[m], i), va="center",
                        fontsize=7)
        ax.set_yticks(range(len(labels)), labels, fontsize=8)
        ax.invert_yaxis()
        ax.margins(x=0.2)
        ax.set_xlabel("particle-steps per second (finest level, 1 thread, "
                      "median of 3, alone)")
        ax.set_title(case, fontsize=9)
        ax.grid(True, axis="x", alpha=0.3)
    fig.tight_layout()
    out = os.path.join(suites, "speed_accuracy", "throughput.png")
    mp.save_figure(fig, out)
    return [out]


def speed_tables(suites):
    return sorted(glob.glob(os.path.join(suites, "speed_accuracy", "*.csv")))


def plot_speed_accuracy(suites):
    out = []
    tables = speed_tables(suites)
    for path in tables:
        out += wp.plot_work_precision(path)
    out += plot_throughput(suites, tables)
    return out


def plot_all_suites(suites):
    """Every suite figure under the suite folder; returns their paths."""
    return (plot_convergence(suites) + plot_stability_map(suites)
            + plot_failure_modes(suites) + plot_speed_accuracy(suites))
