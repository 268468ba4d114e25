"""Draw the throughput table of scripts/bench.sh.

Usage: /usr/bin/python3 analysis/bench_plots.py [results/bench/throughput.csv]

Writes next to the table:
  targets.png    the issue's scenes (block, pinned block, snow88), double and
                 float, 1 and 2 threads, with the target rates as lines
  scaling.png    particle-steps per second against the particle count, 1 and
                 2 threads (flat = cost linear in the particle count), with
                 the 4x-domain block beside the plain one
  transfers.png  every transfer x kernel, 3D and 2D, 2 threads
Rows missing from the table are left out of the figures.
"""
import os
import sys

import numpy as np

import mpmtb_plots as mp

# The targets (3D MLS-MPM, quadratic, neo-Hookean, 32,768 particles,
# 2 threads) and the 88-line reference's 2D snow rate (float, one thread).
TARGETS = {("target", "double", 2): 12e6, ("target", "float", 2): 20e6,
           ("snow88", "float", 1): 7.4e6}
NUMERIC = ("dim", "particles", "threads", "particle_steps_per_second",
           "domain")


def read_rows(path):
    _, rows = mp.read_table(path)
    for row in rows:
        for key in NUMERIC:
            row[key] = mp.parse_float(row[key])
    return rows


def plot_targets(rows, out_dir):
    picked = [r for r in rows
              if r["case"] in ("target", "pinned_block", "pinned_tearing", "snow88")]
    if not picked:
        return []
    fig, ax = mp.plt.subplots(figsize=(7.5, 1.2 + 0.42 * len(picked)))
    for i, r in enumerate(picked):
        rate = r["particle_steps_per_second"]
        colour = "tab:blue" if r["real"] == "double" else "tab:orange"
        ax.barh(i, rate / 1e6, color=colour,
                hatch="" if r["threads"] == 1 else "//", edgecolor="black")
        ax.annotate(f" {rate / 1e6:.2f} M", (rate / 1e6, i), va="center",
                    fontsize=8)
        target = TARGETS.get((r["case"], r["real"], int(r["threads"])))
        if target:
            ax.plot([target / 1e6] * 2, [i - 0.45, i + 0.45], color="black",
                    linestyle="--", linewidth=1.2)
    ax.set_yticks(range(len(picked)),
                  [f"{r['case']} {int(r['dim'])}D {r['real']} "
                   f"{int(r['threads'])}T" for r in picked])
    ax.invert_yaxis()
    ax.margins(x=0.15)
    ax.set_xlabel("million particle-steps per second (dashed: target)")
    ax.grid(True, axis="x", alpha=0.3)
    ax.set_title("throughput of the target scenes (blue double, orange "
                 "float; hatched 2 threads)", fontsize=9)
    fig.tight_layout()
    mp.save_figure(fig, os.path.join(out_dir, "targets.png"))
    return ["targets.png"]


def plot_scaling(rows, out_dir):
    scaling = [r for r in rows if r["case"] == "scaling"]
    if not scaling:
        return []
    fig, ax = mp.plt.subplots(figsize=(6.5, 4.0))
    for threads, marker in ((1, "o"), (2, "s")):
        pts = sorted((r["particles"], r["particle_steps_per_second"])
                     for r in scaling if r["threads"] == threads)
        if pts:
            n, rate = np.array(pts).T
            ax.plot(n, rate / 1e6, marker=marker,
                    label=f"{threads} thread{'s' * (threads > 1)}")
    for r in rows:
        if r["case"] == "domain4x":
            ax.plot(r["particles"], r["particle_steps_per_second"] / 1e6,
                    marker="x", color="black", linestyle="none",
                    label=f"4x domain, {int(r['threads'])}T")
    ax.set_xscale("log")
    ax.set_ylim(bottom=0)
    ax.set_xlabel("particles")
    ax.set_ylabel("million particle-steps per second")
    ax.set_title("3D block, MLS-MPM quadratic, double: cost per particle-step",
                 fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    mp.save_figure(fig, os.path.join(out_dir, "scaling.png"))
    return ["scaling.png"]


def plot_transfers(rows, out_dir):
    matrix = [r for r in rows if r["case"] == "transfers"]
    dims = sorted({int(r["dim"]) for r in matrix}, reverse=True)
    if not dims:
        return []
    transfers = [t for t in mp.TRANSFERS
                 if any(r["transfer"] == t for r in matrix)]
    kernels = [k for k in mp.KERNELS if any(r["kernel"] == k for r in matrix)]
    fig, axes = mp.plt.subplots(1, len(dims), squeeze=False,
                                figsize=(5.5 * len(dims), 4.2))
    width = 0.8 / max(1, len(kernels))
    for ax, dim in zip(axes[0], dims):
        for j, kernel in enumerate(kernels):
            for i, transfer in enumerate(transfers):
                for r in matrix:
                    if (int(r["dim"]) == dim and r["transfer"] == transfer
                            and r["kernel"] == kernel):
                        ax.bar(i + (j - (len(kernels) - 1) / 2) * width,
                               r["particle_steps_per_second"] / 1e6, width,
                               label=kernel if i == 0 else None,
                               **mp.bar_style(transfer, kernel))
        ax.set_xticks(range(len(transfers)), transfers, rotation=45)
        ax.set_ylabel("million particle-steps per second")
        ax.set_title(f"{dim}D, 2 threads (hatch = kernel)", fontsize=9)
        ax.grid(True, axis="y", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    mp.save_figure(fig, os.path.join(out_dir, "transfers.png"))
    return ["transfers.png"]


def main(argv):
    path = argv[1] if len(argv) > 1 else os.path.join(
        os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
        "results", "bench", "throughput.csv")
    try:
        rows = read_rows(path)
    except (OSError, mp.DataError, KeyError, ValueError) as exc:
        print(f"bench_plots: {path}: {exc}", file=sys.stderr)
        return 2
    out_dir = os.path.dirname(os.path.abspath(path))
    figures = (plot_targets(rows, out_dir) + plot_scaling(rows, out_dir)
               + plot_transfers(rows, out_dir))
    print("bench_plots: wrote " + ", ".join(
        os.path.join(out_dir, f) for f in figures))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
