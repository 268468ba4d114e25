"""Draw every mpmtb sweep under a results folder and index them.

Usage: /usr/bin/python3 analysis/plot_all.py [--results DIR]

For each sweep folder (one holding runs.csv) it writes energy.png,
throughput.png, errors.png (if runs.csv has error_* columns) and the
figures of the matching case plotters (e.g. vcm.png) next to runs.csv,
then DIR/README.md with one section per sweep.
"""
import argparse
import os
import re
import sys

import numpy as np

import mpmtb_plots as mp
import suite_report

RUNS_COLUMNS = (
    "run", "transfer", "kernel", "dim", "status", "reason", "particles",
    "steps", "wall_seconds", "particle_steps_per_second", "drift_energy",
    "drift_momentum", "drift_angular_momentum", "drift_volume")
NUMERIC_COLUMNS = ("dim", "particles", "steps", "wall_seconds",
                   "particle_steps_per_second", "drift_energy",
                   "drift_momentum", "drift_angular_momentum", "drift_volume")
SERIES_COLUMNS = ("t", "total", "kinetic", "strain")
DEFAULT_RESULTS = os.path.join(
    os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "results")


class Sweep:
    """A folder with runs.csv: its runs and the figures drawn for it."""

    def __init__(self, results_dir, csv_path):
        self.dir = os.path.dirname(csv_path)
        rel = os.path.relpath(self.dir, results_dir)
        self.rel = "" if rel == "." else rel.replace(os.sep, "/")
        header, rows = mp.read_table(csv_path)
        check_runs(csv_path, header, rows)
        self.error_columns = [c for c in header if c.startswith("error_")]
        self.measured_columns = [c for c in header if c.startswith("measured_")]
        self.runs = sorted((mp.Run(row, self.dir) for row in rows),
                           key=mp.run_order)
        self.figures = []

    @property
    def title(self):
        return self.rel or "results"

    def sort_key(self):
        parts = self.rel.split("/") if self.rel else [""]
        dim = re.fullmatch(r"(\d+)d", parts[1]) if len(parts) > 1 else None
        return (parts[0], int(dim.group(1)) if dim else float("inf"), parts)

    def plotted_runs(self):
        """The ok runs whose series could be read."""
        return [run for run in self.runs if run.ok and run.series]


# ------------------------------------------------------------- reading --

def check_runs(path, header, rows):
    """Raise DataError unless runs.csv follows the contract."""
    missing = [c for c in RUNS_COLUMNS if c not in header]
    if missing:
        raise mp.DataError(f"{path}: missing column(s) {', '.join(missing)}")
    numeric = list(NUMERIC_COLUMNS) + [c for c in header
                                       if c.startswith(("error_", "measured_"))]
    seen = set()
    for line, row in enumerate(rows, start=2):
        where = f"{path}: row {line} (run '{row['run']}')"
        if not re.fullmatch(r"[A-Za-z0-9_.+-]+", row["run"]) \
                or row["run"] in (".", ".."):
            raise mp.DataError(f"{where}: bad run name")
        if row["run"] in seen:
            raise mp.DataError(f"{where}: run listed twice")
        seen.add(row["run"])
        if row["status"] not in mp.STATUSES:
            raise mp.DataError(f"{where}: status '{row['status']}' is not "
                               f"one of {', '.join(mp.STATUSES)}")
        for column in numeric:
            try:
                mp.parse_float(row[column])
            except ValueError:
                raise mp.DataError(f"{where}: {column} '{row[column]}' is "
                                   "not a number") from None


def find_sweeps(results_dir):
    """Every sweep under results_dir, sorted by case then dimension."""
    sweeps = []
    for folder, subdirs, files in os.walk(results_dir):
        subdirs.sort()
        if "runs.csv" in files:
            sweeps.append(Sweep(results_dir,
                                os.path.join(folder, "runs.csv")))
    return sorted(sweeps, key=Sweep.sort_key)


def load_series(run):
    """Attach series.csv to an ok run; warn and leave None on problems."""
    path = os.path.join(run.folder, "series.csv")
    try:
        series = mp.read_csv_arrays(path)
    except (OSError, mp.DataError) as exc:
        warn(f"skipping series of {run.folder}: {exc}")
        return
    missing = [c for c in SERIES_COLUMNS
               if c not in series or series[c].dtype.kind != "f"]
    if missing or not len(series["t"]):
        warn(f"skipping {path}: no rows or no numeric {', '.join(missing)}")
        return
    run.series = series


def warn(message):
    print(f"plot_all.py: warning: {message}", file=sys.stderr)


# ------------------------------------------------------------- figures --

def plot_energy(sweep, runs):
    """Relative total energy, kinetic and strain energy over time."""
    e0 = [run.series["total"][0] for run in runs]
    relative = all(np.isfinite(e) and e != 0 for e in e0)
    fig, axes = mp.new_figure(3, f"{sweep.title}: energy")
    for run, start in zip(runs, e0):
        drift = run.series["total"] - start
        run.plot(axes[0], drift / start if relative else drift)
        run.plot(axes[1], run.series["kinetic"])
        run.plot(axes[2], run.series["strain"])
    axes[0].set_ylabel("$(E - E_0)/E_0$" if relative else "$E - E_0$")
    axes[1].set_ylabel("kinetic $E_{kin}$")
    axes[2].set_ylabel("strain $E_{strain}$")
    mp.legend_outside(fig, axes[0])
    mp.save_figure(fig, os.path.join(sweep.dir, "energy.png"))
    return ["energy.png"]


def plot_angular_momentum(sweep, runs):
    """|L - L0| / |L0| over time, linear and logarithmic (round-off shows)."""
    def vector(run):
        return np.stack([run.series[c] for c in ("Lx", "Ly", "Lz")], axis=1)
    starts = [np.linalg.norm(vector(run)[0]) for run in runs]
    scale = max(starts) if starts else 0.0
    if not np.isfinite(scale) or scale <= 0:
        return []
    spinning = [(run, s) for run, s in zip(runs, starts) if s > 1e-9 * scale]
    if not spinning:
        return []
    fig, axes = mp.new_figure(2, f"{sweep.title}: angular momentum")
    for run, start in spinning:
        L = vector(run)
        signed = (np.linalg.norm(L, axis=1) - start) / start
        change = np.linalg.norm(L - L[0], axis=1) / start
        run.plot(axes[0], signed)
        run.plot(axes[1], np.maximum(change, 1e-17))
    axes[0].set_ylabel("$(|L| - |L_0|)/|L_0|$")
    axes[1].set_ylabel("$|L - L_0|/|L_0|$")
    axes[1].set_yscale("log")
    mp.legend_outside(fig, axes[0])
    mp.save_figure(fig, os.path.join(sweep.dir, "angular_momentum.png"))
    return ["angular_momentum.png"]


def plot_errors(sweep, runs):
    """Grouped bars: one group per error_* column, one bar per run."""
    values = np.array([[run.value(c) for c in sweep.error_columns]
                       for run in runs])
    if not np.isfinite(values).any():
        return []
    log = mp.spans_decades(values)
    if log:
        values = np.abs(values)
    groups = np.arange(len(sweep.error_columns))
    width = 0.8 / len(runs)
    fig, ax = mp.plt.subplots(
        figsize=(min(12.0, max(6.0, 1.2 + 0.45 * values.size)), 4.0))
    for i, run in enumerate(runs):
        ax.bar(groups + (i - (len(runs) - 1) / 2) * width, values[i], width,
               label=run.name, **mp.bar_style(run.transfer, run.kernel))
    ax.set_xticks(groups, [c[len("error_"):] for c in sweep.error_columns])
    ax.set_ylabel("|error|" if log else "error")
    if log:
        ax.set_yscale("log")
    else:
        ax.axhline(0.0, color="black", linewidth=0.6)
    ax.grid(True, axis="y", alpha=0.3)
    ax.set_title(f"{sweep.title}: errors (ok runs)")
    mp.legend_outside(fig, ax)
    mp.save_figure(fig, os.path.join(sweep.dir, "errors.png"))
    return ["errors.png"]


def plot_throughput(sweep, runs):
    """Horizontal bars of particle-steps per second, one per run."""
    runs = [run for run in runs
            if np.isfinite(run.value("particle_steps_per_second"))]
    if not runs:
        return []
    rates = [run.value("particle_steps_per_second") for run in runs]
    fig, ax = mp.plt.subplots(figsize=(7.0, max(2.8, 1.2 + 0.45 * len(runs))))
    rows = np.arange(len(runs))
    for row, run, rate in zip(rows, runs, rates):
        ax.barh(row, rate, **mp.bar_style(run.transfer, run.kernel))
        ax.annotate(" " + sig3(rate), (rate, row), va="center", fontsize=8)
    ax.set_yticks(rows, [run.name for run in runs])
    ax.invert_yaxis()
    if mp.spans_decades(rates):
        ax.set_xscale("log")
    ax.margins(x=0.15)
    ax.set_xlabel("particle-steps per second [1/s]")
    ax.grid(True, axis="x", alpha=0.3)
    ax.set_title(f"{sweep.title}: throughput (ok runs)")
    fig.tight_layout()
    mp.save_figure(fig, os.path.join(sweep.dir, "throughput.png"))
    return ["throughput.png"]


def plot_sweep(sweep):
    """Draw every figure of a sweep; record their names on it."""
    ok_runs = [run for run in sweep.runs if run.ok]
    for run in ok_runs:
        load_series(run)
    plotted = sweep.plotted_runs()
    if plotted:
        sweep.figures += plot_energy(sweep, plotted)
        sweep.figures += plot_angular_momentum(sweep, plotted)
        common = set.intersection(*(set(r.series) for r in plotted))
        for plotter in mp.plotters_for(common):
            sweep.figures += plotter(sweep.title, plotted, sweep.dir)
    if sweep.error_columns and ok_runs:
        sweep.figures += plot_errors(sweep, ok_runs)
    if ok_runs:
        sweep.figures += plot_throughput(sweep, ok_runs)


# -------------------------------------------------------------- README --

def sig3(value):
    """A number with 3 significant digits, trailing zeros kept."""
    return format(value, "#.3g").rstrip(".")


def fmt(value, spec):
    """Format a number for a table cell; nan is an empty cell.

    spec: "int" (whole numbers as such), "sig3" or a format() spec.
    """
    if not np.isfinite(value):
        return ""
    if spec == "int" and value == int(value):
        return str(int(value))
    if spec in ("int", "sig3"):
        return sig3(value)
    return format(value, spec)


def cell(text):
    return text.replace("|", "\\|").replace("\n", " ")


def runs_table(sweep):
    """Markdown table of a sweep's runs.csv."""
    head = ["run", "status", "reason", "particles", "steps",
            "particle-steps/s"] + sweep.error_columns + sweep.measured_columns + ["drift_energy"]
    lines = ["| " + " | ".join(head) + " |",
             "|" + "---|" * 2 + "---|" + "--:|" * (len(head) - 3)]
    for run in sweep.runs:
        cells = [f"`{run.name}`", run.status,
                 "" if run.ok else cell(run.row["reason"]),
                 fmt(run.value("particles"), "int"),
                 fmt(run.value("steps"), "int"),
                 fmt(run.value("particle_steps_per_second"), "sig3")]
        cells += [fmt(run.value(c), ".2e") for c in sweep.error_columns]
        cells += [fmt(run.value(c), "sig3") for c in sweep.measured_columns]
        cells.append(fmt(run.value("drift_energy"), ".2e"))
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def sweep_section(sweep):
    lines = [f"### {sweep.title}", ""] + runs_table(sweep) + [""]
    if not sweep.figures:
        lines += ["No figures: no run finished with status ok.", ""]
    for name in sweep.figures:
        path = f"{sweep.rel}/{name}" if sweep.rel else name
        lines += [f"![{sweep.title} {name[:-4]}]({path})", ""]
    return lines


def readme(sweeps, summary=()):
    lines = ["# mpmtb results", "",
             "Generated by `analysis/plot_all.py`; do not hand-edit, run "
             "`/usr/bin/python3 analysis/plot_all.py` again instead.", ""]
    lines += list(summary)
    if sweeps:
        lines += ["## Canonical sweeps", ""]
    if not sweeps:
        lines += ["No results yet: no `runs.csv` was found under this "
                  "folder.", ""]
    for sweep in sweeps:
        lines += sweep_section(sweep)
    return "\n".join(lines).rstrip("\n") + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", default=DEFAULT_RESULTS,
                        help="results folder (default: %(default)s)")
    parser.add_argument("--suites", default=None,
                        help="suite tables (default: RESULTS/suites)")
    args = parser.parse_args(argv)
    suites = args.suites or os.path.join(args.results, "suites")
    if not os.path.isdir(args.results):
        print(f"plot_all.py: error: no results folder {args.results}",
              file=sys.stderr)
        return 2
    try:
        sweeps = find_sweeps(args.results)
    except (OSError, mp.DataError) as exc:
        print(f"plot_all.py: error: malformed runs.csv: {exc}",
              file=sys.stderr)
        return 1
    for sweep in sweeps:
        plot_sweep(sweep)
        print(f"{sweep.title}: {', '.join(sweep.figures) or 'no figures'}")
    try:
        summary = suite_report.summary(args.results, suites)
    except (OSError, mp.DataError) as exc:
        print(f"plot_all.py: error: malformed suite table: {exc}",
              file=sys.stderr)
        return 1
    text = readme(sweeps, summary)
    if os.path.exists(os.path.join(args.results, "gallery", "README.md")):
        text += ("\n## Gallery\n\nPictures drawn from ParaView frames by analysis/render.py "
                 "(`bash scripts/gallery.sh`): [gallery/README.md](gallery/README.md)\n")
    mp.save_text(os.path.join(args.results, "README.md"), text)
    print(f"wrote {os.path.join(args.results, 'README.md')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
