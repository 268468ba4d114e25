"""The summary section of results/README.md from the suite tables.

Key tables (observed orders, stable CFL, failure modes with the energy kept,
throughput, Pareto winners) and the suite figures, with paths relative to the
results folder.
"""
import os

import numpy as np

import mpmtb_plots as mp
import suite_plots as sp
import work_precision as wp


def table(head, rows, align=None):
    align = align or ["---"] + ["--:"] * (len(head) - 1)
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join(align) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return lines + [""]


def cell(value, spec=".2f"):
    return "" if not np.isfinite(value) else format(value, spec)


def pivot(rows, column_key, value):
    """Rows: methods; columns: column_key(row) in first-seen order."""
    columns = list(dict.fromkeys(column_key(r) for r in rows))
    methods = sp.methods_of(rows)
    grid = {(m, c): "" for m in methods for c in columns}
    for r in rows:
        grid[(sp.method_key(r), column_key(r))] = value(r)
    body = [[f"`{mp.method_label(*m)}`"] + [grid[(m, c)] for c in columns]
            for m in methods]
    return columns, body


def orders_section(suites):
    rows = sp.read_rows(os.path.join(suites, "convergence", "orders.csv"))
    if not rows:
        return []

    def value(r):
        order = sp.num(r, "fitted_order")
        if not np.isfinite(order):
            return f"unstable ({r['levels_ok']}/{r['levels']} ok)"
        span = f" (L{r['fit_from_level']}-{r['fit_to_level']})"
        note = "" if r["levels_ok"] == r["levels"] else \
            f", {r['levels_ok']}/{r['levels']} ok"
        return f"{order:.2f}{span}{note}"
    columns, body = pivot(rows, lambda r: f"{r['case']} {r['study']}", value)
    return (["### Observed orders", "",
             "Fitted order of the error over the asymptotic range (levels "
             "Lk in brackets: from the finest three levels, extended to "
             "coarser ones while each observed order log2(e_k-1/e_k) stays "
             "within max(0.3, 15 %) of the fit; cases/suite/analysis.hpp). "
             "`grid`: h and dt halve together at a fixed CFL; `dt`: dt "
             "halves on a fixed grid. Per-level tables: "
             "`suites/convergence/<case>.csv`.", ""]
            + table(["method"] + columns, body))


def stability_section(suites):
    rows = sp.read_rows(os.path.join(suites, "stability", "stable_cfl.csv"))
    if not rows:
        return []

    def value(r):
        text = sp.stable_text(r)
        return "none" if text == "-" else text
    columns, body = pivot(rows, lambda r: f"{r['case']} ppc {r['ppc']}",
                          value)
    failures = sorted({r["failure"] for r in rows if r["failure"]})
    return (["### Largest stable CFL", "",
             "dt = CFL dx / (c_p + max|v|); a run is unstable when it stops "
             "with NaN/Inf, J <= 0, a particle leaving the domain or energy "
             "above twice the energy put in (failure classes seen: "
             f"{', '.join(failures) or 'none'}). von Neumann estimate "
             "(REFERENCE.md, 1D lumped mass): 1.0 linear, 1.5-1.7 "
             "quadratic, 1.9 cubic. `bar_fixed` fills the domain between two "
             "fixed ends (every node has a full mass); `bar` has a free end "
             "whose outer nodes carry tiny masses. PIC's limit is lower: "
             "its grid-particle-grid projection P damps the highest mode "
             "and symplectic Euler is stable for omega^2 dt^2 <= 2 (1 + P) "
             "(derived in tests/e2e_suites.sh: 0.79 linear, 1.42 quadratic, "
             "1.56 cubic at ppc 2). The implicit integrators "
             "(`/backward-euler`, `/newmark`: Newton on the incremental "
             "potential, unconditionally stable for linear elasticity) run "
             "their own CFL values far beyond the explicit limit; `>=` marks "
             "the largest one tried where none failed. Every run: "
             "`suites/stability/<case>.csv`.", ""]
            + table(["method"] + columns, body))


METRIC_NOTES = {
    "strain_max_rel": "max strain energy / initial energy",
    "energy_kept": "total energy at the end / at the start",
    "L_change": "|L(end) - L(0)| / |L(0)|",
}


def failure_section(suites):
    rows = sp.read_rows(os.path.join(suites, "stability", "failure_modes.csv"))
    if not rows:
        return []

    def value(r):
        v = sp.num(r, "value")
        return r["status"] if not np.isfinite(v) else f"{v:.3g}"
    columns, body = pivot(rows, lambda r: r["case"], value)
    metrics = list(dict.fromkeys((r["case"], r["metric"]) for r in rows))
    notes = "; ".join(f"`{c}`: {METRIC_NOTES.get(m, m)}" for c, m in metrics)
    return (["### Failure modes and energy kept", "",
             f"{notes}. `translate`: a free block in rigid translation "
             "(exact: no strain); `translate_spin`: the same block also "
             "spinning, so stressed particles cross cell faces; `disks`: "
             "Sulsky's colliding disks (energy kept, PIC dissipation); "
             "`rotating`: a free spinning square (angular momentum; PIC "
             "loses it, FLIP is noisy, APIC/MLS keep it to round-off).", ""]
            + table(["method"] + columns, body))


def speed_section(suites):
    lines = []
    for path in sp.speed_tables(suites):
        rows = sp.read_rows(path)
        case = os.path.basename(path)[:-4]
        rates = sp.finest_throughput(rows)
        if rates:
            body = [[f"`{label}`", f"{rate:.3g}"]
                    for label, rate in rates.items()]
            lines += [f"### Throughput: {case}", "",
                      "Particle-steps per second at the finest level, one "
                      "thread, each run alone, median of 3 repetitions of at "
                      "least 0.5 s of stepping.", ""]
            lines += table(["method", "particle-steps/s"], body)
        good = wp.usable(rows)
        if not good:
            continue
        key = good[0].get("error_key", "error")
        front = [r for r in good if r["pareto_time"] == "1"]
        front.sort(key=lambda r: sp.num(r, "time_s"))
        body = [[wp.run_name(r), r["cells"],
                 f"{sp.num(r, 'error'):.3g}", f"{sp.num(r, 'energy_error'):.2g}",
                 wp.cost_text(r), f"{sp.num(r, 'cpu_s'):.3g}",
                 f"{sp.num(r, 'particle_steps'):.3g}",
                 "yes" if r["pareto_work"] == "1" else ""] for r in front]
        lines += [f"### Pareto front: {case}", "",
                  f"Error `error.{key}` against the time of one run (median "
                  "of 3 repetitions timed alone, min-max in brackets): the "
                  "runs no other run beats in both (an implicit integrator's "
                  "runs with their CFL). Energy error, CPU time "
                  "and particle-steps beside them; the last column: also on "
                  "the front of error against particle-steps. Figure: "
                  f"`suites/speed_accuracy/{case}_work_precision.png`.", ""]
        lines += table(["method", "cells", "error", "energy error",
                        "time per run [s]", "CPU [s]", "particle-steps",
                        "work front"], body)
        if any(r.get("pareto_period") == "1" for r in good):
            lines += ["", "What the period error alone would call the front "
                      "(`error.period_rel` against the same times): "
                      + wp.front_text(good, "pareto_period") + ".",
                      "", "The front of the field error: "
                      + wp.front_text(good, "pareto_time") + "."]
        lines += ["", f"### Cheapest method for a tolerance: {case}", "",
                  f"For each tolerance on `error.{key}`, the cheapest method "
                  "(transfer-kernel, its cheapest grid) that reaches it, and "
                  "the next two; cost: median time per run (min-max).", ""]
        lines += table(["tolerance", "cheapest", "second", "third"],
                       wp.cheapest_table(good))
        lines += [""]
    return lines


KEY_FIGURES = (
    ("energy over time per transfer: colliding disks", "disks/2d/energy.png"),
    ("energy over time per transfer: vibrating bar 1D", "bar/1d/energy.png"),
    ("angular momentum over time: rotating square",
     "rotating/2d/angular_momentum.png"),
)


def summary(results_dir, suites):
    """Markdown lines of the summary; draws the suite figures first."""
    figures = sp.plot_all_suites(suites) if os.path.isdir(suites) else []
    lines = ["## Summary", ""]
    if os.path.isdir(suites):
        lines += [f"Suite tables: `{os.path.relpath(suites, results_dir)}/` "
                  "(regenerate with `build/cases/mpmtb suite all --quick`).",
                  ""]
    lines += orders_section(suites) + stability_section(suites)
    lines += failure_section(suites) + speed_section(suites)
    for title, rel in KEY_FIGURES:
        if os.path.isfile(os.path.join(results_dir, rel)):
            figures.append(os.path.join(results_dir, rel))
    if figures:
        lines += ["### Figures", ""]
    for path in figures:
        rel = os.path.relpath(path, results_dir).replace(os.sep, "/")
        lines += [f"![{rel[:-4]}]({rel})", ""]
    return lines
