"""Shared helpers for the mpmtb plotting scripts.

Reading the files a sweep writes (runs.csv, <run>/series.csv), atomic
output, one visual style for every figure (a colour per transfer, a line
style per kernel) and a registry of case plotters keyed by the series
columns they need, so that a new case only adds one decorated function.
"""
import contextlib
import csv
import math
import os
import tempfile
import zlib

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

STATUSES = ("ok", "unstable", "invalid")
TIME_LABEL = "time t [s]"


class DataError(Exception):
    """A results file does not follow the mpmtb data contract."""


# --------------------------------------------------------------- reading --

def parse_float(text):
    """Float of a CSV cell; an empty cell is nan. Raises ValueError."""
    text = text.strip()
    return math.nan if not text else float(text)


def read_table(path):
    """Return (header, rows) of a CSV file, rows as dicts of stripped str.

    Raises DataError if the file is empty, the header repeats a name or a
    row has a different number of fields than the header.
    """
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            reader = csv.reader(handle)
            header = [name.strip() for name in next(reader, [])]
            if not header or not any(header):
                raise DataError(f"{path}: empty file or empty header")
            if len(set(header)) != len(header):
                raise DataError(f"{path}: header repeats a column name")
            rows = []
            for fields in reader:
                if not fields:
                    continue
                if len(fields) != len(header):
                    raise DataError(
                        f"{path}:{reader.line_num}: {len(fields)} fields, "
                        f"header has {len(header)}")
                rows.append(dict(zip(header, (f.strip() for f in fields))))
    except (UnicodeDecodeError, csv.Error) as exc:
        raise DataError(f"{path}: not a readable CSV file ({exc})") from exc
    return header, rows


def columns_as_arrays(header, rows):
    """Dict column -> numpy array; float (empty -> nan) where every cell
    parses as a number, str otherwise."""
    arrays = {}
    for name in header:
        cells = [row[name] for row in rows]
        try:
            arrays[name] = np.array([parse_float(c) for c in cells], float)
        except ValueError:
            arrays[name] = np.array(cells, dtype=str)
    return arrays


def read_csv_arrays(path):
    """Read a CSV file into a dict of numpy arrays (see columns_as_arrays)."""
    return columns_as_arrays(*read_table(path))


# ---------------------------------------------------------------- output --

def _atomic_write(path, write):
    """Call write(binary_handle) on a temp file next to path, then rename."""
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(
        dir=folder, prefix=f".{os.path.basename(path)}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as handle:
            write(handle)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def save_text(path, text):
    """Write text (UTF-8) to path atomically."""
    _atomic_write(path, lambda handle: handle.write(text.encode("utf-8")))


def save_figure(fig, path):
    """Save fig as PNG to path atomically, then close it."""
    try:
        _atomic_write(path, lambda handle: fig.savefig(
            handle, format="png", dpi=120, bbox_inches="tight"))
    finally:
        plt.close(fig)


# ----------------------------------------------------------------- style --

TRANSFERS = ("pic", "flip", "apic", "mls", "tpic", "polypic", "xpic", "aflip",
             "asflip")
KERNELS = ("linear", "quadratic", "cubic", "gimp", "cpgimp", "cpdi")
TRANSFER_COLOURS = {"pic": "tab:blue", "flip": "tab:orange",
                    "apic": "tab:green", "mls": "tab:red",
                    "tpic": "tab:purple", "polypic": "tab:brown",
                    "xpic": "tab:pink", "aflip": "tab:olive",
                    "asflip": "tab:cyan"}
KERNEL_LINESTYLES = {"linear": ":", "quadratic": "-", "cubic": "-.",
                     "gimp": (0, (5, 1)), "cpgimp": (0, (5, 1, 1, 1)),
                     "cpdi": (0, (8, 2))}
KERNEL_HATCHES = {"linear": "..", "quadratic": "", "cubic": "//", "gimp": "xx",
                  "cpgimp": "++", "cpdi": "--"}
# Time integrators (issue 19): a method of the suites is transfer x kernel x
# integrator; explicit is the default and keeps the plain "transfer-kernel"
# name.
INTEGRATORS = ("explicit", "backward-euler", "newmark")
INTEGRATOR_MARKERS = {"explicit": "o", "backward-euler": "s", "newmark": "^"}
INTEGRATOR_SHORT = {"explicit": "", "backward-euler": "BE", "newmark": "NM"}
# Black and "--" are kept for exact / reference curves.
EXACT_STYLE = {"color": "black", "linestyle": "--", "linewidth": 1.2}
_SPARE_COLOURS = ("tab:gray", "gold", "navy", "lime")
_SPARE_LINESTYLES = ((0, (3, 1, 1, 1, 1, 1)), (0, (1, 3)))
_SPARE_HATCHES = ("\\\\", "oo")


def _pick(name, table, spares):
    """table[name], or a spare chosen by a stable hash of an unknown name."""
    if name in table:
        return table[name]
    return spares[zlib.crc32(name.encode()) % len(spares)]


def line_style(transfer, kernel):
    """Keyword arguments for ax.plot for a run."""
    return {"color": _pick(transfer, TRANSFER_COLOURS, _SPARE_COLOURS),
            "linestyle": _pick(kernel, KERNEL_LINESTYLES, _SPARE_LINESTYLES),
            "linewidth": 1.4}


def bar_style(transfer, kernel):
    """Keyword arguments for ax.bar / ax.barh for a run."""
    return {"color": _pick(transfer, TRANSFER_COLOURS, _SPARE_COLOURS),
            "hatch": _pick(kernel, KERNEL_HATCHES, _SPARE_HATCHES),
            "edgecolor": "black", "linewidth": 0.6}


def integrator_of(row):
    """A suite table row's integrator; tables from before the integrator
    column are explicit."""
    return row.get("integrator") or "explicit"


def method_label(transfer, kernel, integrator="explicit"):
    """transfer-kernel, with /integrator for an implicit one."""
    base = f"{transfer}-{kernel}"
    return base if integrator == "explicit" else f"{base}/{integrator}"


def integrator_marker(integrator):
    return _pick(integrator, INTEGRATOR_MARKERS, ("D", "v", "P"))


def _rank(name, known):
    return (known.index(name), "") if name in known else (len(known), name)


def run_order(run):
    """Sort key: known transfers and kernels in their canonical order."""
    return (_rank(run.transfer, TRANSFERS), _rank(run.kernel, KERNELS),
            run.name)


def new_figure(nrows, title, width=8.0, row_height=2.4):
    """A figure with nrows stacked axes sharing the time axis."""
    fig, axes = plt.subplots(nrows, 1, sharex=True, squeeze=False,
                             figsize=(width, 0.8 + row_height * nrows))
    axes = list(axes[:, 0])
    fig.suptitle(title)
    for ax in axes:
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel(TIME_LABEL)
    return fig, axes


def legend_outside(fig, ax):
    """One legend for the figure, right of the axes, from ax's lines."""
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="center left",
                   bbox_to_anchor=(1.0, 0.5), frameon=False)
    fig.tight_layout()


def spans_decades(values, decades=2.0):
    """True if the positive finite |values| span more than `decades`."""
    mags = np.abs(np.asarray(values, float))
    mags = mags[np.isfinite(mags) & (mags > 0)]
    return mags.size > 1 and np.log10(mags.max() / mags.min()) > decades


# ------------------------------------------------------------- sweep data --

class Run:
    """One row of runs.csv, with its time series once loaded."""

    def __init__(self, row, sweep_dir):
        self.row = row
        self.name = row["run"]
        self.transfer = row["transfer"]
        self.kernel = row["kernel"]
        self.status = row["status"]
        self.folder = os.path.join(sweep_dir, self.name)
        self.series = None  # dict of arrays from series.csv

    @property
    def ok(self):
        return self.status == "ok"

    def value(self, column):
        """Numeric value of a runs.csv column (nan if empty or absent)."""
        return parse_float(self.row.get(column, ""))

    def plot(self, ax, y, **extra):
        """Plot y against this run's time, in the run's style."""
        style = line_style(self.transfer, self.kernel)
        style.update(extra)
        ax.plot(self.series["t"], y, label=self.name, **style)


# -------------------------------------------------------- case registry --

CASE_PLOTTERS = {}


def case_plotter(*columns):
    """Register fn(title, runs, out_dir) -> [file names written].

    It is called for a sweep when every plotted run's series has all of
    `columns`; runs are the ok runs with a series, in run_order.
    """
    def register(fn):
        CASE_PLOTTERS[frozenset(columns)] = fn
        return fn
    return register


def plotters_for(columns):
    """Registered case plotters whose signature is within columns."""
    available = set(columns)
    return [fn for signature, fn in CASE_PLOTTERS.items()
            if signature <= available]


@case_plotter("vcm", "vcm_exact")
def plot_vcm(title, runs, out_dir):
    """Vibrating bar: centre-of-mass velocity against the exact one."""
    fig, (top, bottom) = new_figure(2, f"{title}: centre-of-mass velocity")
    for run in runs:
        run.plot(top, run.series["vcm"])
        run.plot(bottom, run.series["vcm"] - run.series["vcm_exact"])
    longest = max(runs, key=lambda r: len(r.series["t"]))
    top.plot(longest.series["t"], longest.series["vcm_exact"],
             label="exact", **EXACT_STYLE)
    top.set_ylabel("$v_{cm}$ [m/s]")
    bottom.set_ylabel("$v_{cm} - v_{cm}^{exact}$ [m/s]")
    bottom.axhline(0.0, color="black", linewidth=0.6)
    legend_outside(fig, top)
    save_figure(fig, os.path.join(out_dir, "vcm.png"))
    return ["vcm.png"]
