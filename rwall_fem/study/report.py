"""The study's report: what an accuracy target costs, tables and plots.

The cost of an accuracy target is read from the data by linear interpolation of
log(error) against log(time) (and log(cells)) between the two runs that bracket it; beyond
the data the slope of the two nearest runs extrapolates, and the summary says so. Rank 0
writes ``study.csv``, ``study.md`` (summary and tables), ``summary.md`` and
``study_<case>.png`` (error against wall time, log-log, one line per element technology x
dt_scale, slope guides).
"""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path

import numpy as np

from rwall_fem.study.cases import Case

__all__ = ["cost_at", "plot", "summarise", "write_outputs"]


def cost_at(errors, seconds, cells, target: float):
    """(seconds, cells, how) at which |error| reaches ``target``, by log-log interpolation
    between the two runs that bracket it (``how`` = "interpolated"), else along the slope
    of the two runs nearest to it ("extrapolated"); None if the errors do not fall."""
    e = np.abs(np.asarray(errors, float))
    t, n = np.asarray(seconds, float), np.asarray(cells, float)
    keep = np.isfinite(e) & (e > 0)
    e, t, n = e[keep], t[keep], n[keep]
    if len(e) < 2:
        return None
    order = np.argsort(t)
    e, t, n = np.log(e[order]), np.log(t[order]), np.log(n[order])
    goal = math.log(target)
    pair, how = None, "extrapolated"
    for i in range(len(e) - 1):
        if (e[i] - goal) * (e[i + 1] - goal) <= 0 and e[i] != e[i + 1]:
            pair, how = (i, i + 1), "interpolated"
            break
    if pair is None:
        pair = (len(e) - 2, len(e) - 1) if e[-1] > goal else (0, 1)
    i, j = pair
    if e[j] >= e[i]:
        return None  # no decrease to follow
    w = (goal - e[i]) / (e[j] - e[i])
    return (
        math.exp(t[i] + w * (t[j] - t[i])),
        math.exp(n[i] + w * (n[j] - n[i])),
        how,
    )


def _cost(series, quantity: str, target: float):
    """:func:`cost_at` of ``quantity`` along a series of runs (coarse to fine), or None when
    the finest run is not more accurate than the coarsest: no cost to read where refining
    does not help, even if two runs on the way happen to bracket the target."""
    errors = [r[f"error_{quantity}"] for r in series]
    if len(errors) < 2 or not abs(errors[-1]) < abs(errors[0]):
        return None
    return cost_at(
        errors, [r["wall_seconds"] for r in series], [r["cells"] for r in series], target
    )


def _slope(errors, seconds) -> float:
    """Least-squares slope of log|error| against log(time) over the runs (nan if < 2)."""
    e, t = np.abs(np.asarray(errors, float)), np.asarray(seconds, float)
    keep = np.isfinite(e) & (e > 0)
    if keep.sum() < 2:
        return math.nan
    return float(np.polyfit(np.log(t[keep]), np.log(e[keep]), 1)[0])


# Names of the technologies (rwall_fem.study.runner.TECHNOLOGIES), in the order they are shown.
NAMES = {
    "tet": "P1 tet",
    "hex": "Q1 hex 1-point, physical hourglass",
    "hex_full": "Q1 hex 2x2x2",
    "hex_fb": "Q1 hex 1-point, FB stiffness 0.1",
}


# Colour and marker of each technology's lines in the plots.
STYLES = {"tet": ("C0", "o"), "hex": ("C1", "s"), "hex_full": ("C2", "D"), "hex_fb": ("C3", "^")}


def _technologies(rows):
    """(element, dt_scale) of the rows, technologies in the order of NAMES."""
    order = list(NAMES)
    pairs = {(r["element"], r["dt_scale"]) for r in rows}
    return sorted(pairs, key=lambda p: (order.index(p[0]) if p[0] in order else len(order), p))


def _series(rows, case, element, dt_scale):
    chosen = [
        r for r in rows if (r["case"], r["element"], r["dt_scale"]) == (case, element, dt_scale)
    ]
    return sorted(chosen, key=lambda r: -r["element_size"])


def _label(element: str, dt_scale: float) -> str:
    return f"{NAMES.get(element, element)}, dt_scale {dt_scale:g}"


def summarise(rows, cases, target: float = 0.01) -> str:
    """Plain-words markdown: what ``target`` relative error costs, for each headline quantity."""
    lines = ["# What accuracy costs in time", ""]
    ranks = rows[0]["ranks"] if rows else 1
    lines.append(
        f"Computed from {len(rows)} runs on {ranks} MPI rank(s); time is the wall time of the "
        "time loop (median of repeats for short runs), set-up (meshing, mass, stable step) "
        "excluded. Costs are interpolated in log-log between the two runs that bracket the "
        "target (or extrapolated along the nearest two, as marked)."
    )
    lines.append("")
    lines += _cost_table(rows, cases, target)
    for case in cases:
        label = case.quantities[case.headline]
        lines.append(f"**{case.title}**, {label}:")
        lines.append("")
        best = None
        for element, dt_scale in _technologies([r for r in rows if r["case"] == case.name]):
            series = _series(rows, case.name, element, dt_scale)
            errors = [r[f"error_{case.headline}"] for r in series]
            seconds = [r["wall_seconds"] for r in series]
            one = _cost(series, case.headline, target)
            half = _cost(series, case.headline, target / 2)
            slope = _slope(errors, seconds)
            name = _label(element, dt_scale)
            if one is None:
                lines.append(
                    f"- {name}: the error does not fall with refinement here "
                    f"({', '.join(f'{100 * e:+.2f} %' for e in errors)})."
                )
                continue
            text = (
                f"- {name}: {100 * target:g} % {label} error takes about {one[1]:,.0f} cells and "
                f"{one[0]:.3g} s ({one[2]})"
            )
            if half is not None:
                text += f"; halving it costs {half[0] / one[0]:.3g}x the time ({half[2]})"
            text += f" (error ~ time^{slope:.2f} over the runs)."
            lines.append(text)
            if best is None or one[0] < best[1]:
                best = (name, one[0], one[1])
        if best is not None:
            lines.append("")
            where = case.name.replace("_", " ")
            lines.append(
                f"In one line: {100 * target:g} % {label} error on the {where}"
                f" costs {best[2]:,.0f} cells and {best[1]:.3g} s with the cheapest technology "
                f"({best[0]})."
            )
        if case.note:
            lines += ["", case.note]
        lines.append("")
    lines.append(
        "Guides: an O(h) error at a cost growing like h^-4 (h^-3 cells times h^-1 steps) "
        "falls like time^-1/4, so halving it costs 16x; O(h^2) falls like time^-1/2 (4x)."
    )
    return "\n".join(lines) + "\n"


def _cost_table(rows, cases, target: float) -> list[str]:
    """Markdown lines: the cells and seconds that ``target`` error in each case's headline
    quantity costs, one row per technology x dt_scale (x: extrapolated; -: the error does
    not fall)."""
    head = ["technology"] + [
        f"{c.name.replace('_', ' ')}: {c.quantities[c.headline]}" for c in cases
    ]
    lines = [
        f"**Cost of {100 * target:g} % error, per element technology** (cells, seconds of "
        "time loop; x: extrapolated beyond the finest run):",
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    for element, dt_scale in _technologies(rows):
        cells = [_label(element, dt_scale)]
        for case in cases:
            series = _series(rows, case.name, element, dt_scale)
            if not series:
                cells.append("")
                continue
            one = _cost(series, case.headline, target)
            if one is None:
                cells.append("-")
                continue
            mark = "" if one[2] == "interpolated" else " x"
            cells.append(f"{one[1]:,.0f} cells, {one[0]:.3g} s{mark}")
        lines.append("| " + " | ".join(cells) + " |")
    lines.append("")
    same = _spread(rows, cases, "hex", "hex_full")
    if same is not None:
        text = (
            "On these meshes of parallelepipeds the physical hourglass form is the 2x2x2 "
            f"element: their errors differ by at most {100 * max(same.values()):.1g} "
            "percentage points (every quantity, size and dt_scale), so the table prices "
            "the same answers."
        )
        fb = _spread(rows, cases, "hex_fb", "hex_full")
        if fb is not None:
            text += (
                " The Flanagan-Belytschko stiffness form differs from them by at most "
                + ", ".join(
                    f"{100 * x:.2g} points in the {name.replace('_', ' ')} case"
                    for name, x in fb.items()
                )
                + "."
            )
        lines += [text, ""]
    return lines


def _spread(rows, cases, first: str, second: str):
    """Per case, the largest difference of a relative error between the technologies
    ``first`` and ``second`` run at the same element size and dt_scale; None if they were
    never run together."""
    runs = {(r["case"], r["element"], r["element_size"], r["dt_scale"]): r for r in rows}
    spread = {}
    for case in cases:
        for (name, element, h, dt_scale), r in runs.items():
            other = runs.get((name, second, h, dt_scale))
            if name != case.name or element != first or other is None:
                continue
            for key in case.quantities:
                gap = abs(r[f"error_{key}"] - other[f"error_{key}"])
                spread[case.name] = max(spread.get(case.name, 0.0), gap)
    return spread or None


def _table(rows, case: Case) -> str:
    keys = list(case.quantities)
    head = (
        ["technology", "dt_scale", "h (mm)", "cells", "steps", "dt (s)", "loop (s)", "ns/cell-step"]
        + [f"{case.quantities[k]} err" for k in keys]
        + ["wall share", "balance err"]
    )
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for element, dt_scale in _technologies([r for r in rows if r["case"] == case.name]):
        for r in _series(rows, case.name, element, dt_scale):
            cells = [
                NAMES.get(element, element),
                f"{dt_scale:g}",
                f"{1e3 * r['element_size']:g}",
                f"{r['cells']:,}",
                f"{r['steps']}",
                f"{r['dt']:.3g}",
                f"{r['wall_seconds']:.3g}",
                f"{r['ns_per_cell_step']:.0f}",
                *(f"{100 * r[f'error_{k}']:+.3f} %" for k in keys),
                f"{100 * r['wall_share']:.3f} %",
                f"{r['balance_error']:.1e}",
            ]
            out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out) + "\n"


def plot(rows, case: Case, path: Path) -> None:
    """Error against wall time, log-log, one panel per quantity, one line per technology."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = list(case.quantities)
    fig, axes = plt.subplots(1, len(keys), figsize=(4.2 * len(keys), 5.0), squeeze=False)
    mine = [r for r in rows if r["case"] == case.name]
    largest = max((dt_scale for _, dt_scale in _technologies(mine)), default=None)
    for ax, key in zip(axes[0], keys, strict=True):
        every_t, every_e = [], []
        for element, dt_scale in _technologies(mine):
            series = _series(rows, case.name, element, dt_scale)
            t = np.array([r["wall_seconds"] for r in series])
            e = 100 * np.abs([r[f"error_{key}"] for r in series])
            good = e > 0
            # One colour and marker per technology; dashed: the smaller dt_scales.
            color, marker = STYLES.get(element, ("k", "x"))
            ax.loglog(
                t[good],
                e[good],
                color=color,
                marker=marker,
                ms=4,
                lw=1.1,
                ls="-" if dt_scale == largest else "--",
                label=_label(element, dt_scale),
            )
            every_t += list(t[good])
            every_e += list(e[good])
        if every_t:
            # Slope guides through the middle of the data.
            t0 = math.exp(np.mean(np.log(every_t)))
            e0 = math.exp(np.mean(np.log(every_e)))
            span = np.array([min(every_t), max(every_t)])
            for power, style in ((-0.25, ":"), (-0.5, "-.")):
                ax.loglog(
                    span, e0 * (span / t0) ** power, "k" + style, lw=0.8, label=f"slope {power:g}"
                )
        ax.axhline(1.0, color="grey", lw=0.6)
        ax.set_xlabel("wall time of the time loop (s)")
        ax.set_ylabel("|relative error| (%)")
        ax.set_title(case.quantities[key], fontsize=10)
        ax.grid(True, which="both", lw=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 3), fontsize=7)
    fig.suptitle(case.title, fontsize=11)
    fig.tight_layout(rect=(0, 0.05 * (1 + len(labels) // 3), 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_outputs(rows, cases, out: Path, seconds: float, load=None) -> None:
    """study.csv, study.md (summary + tables), summary.md, study_<case>.png (rank 0 only)."""
    out.mkdir(parents=True, exist_ok=True)
    columns = list(dict.fromkeys(k for r in rows for k in r))
    with open(out / "study.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, columns, restval="")
        writer.writeheader()
        writer.writerows(rows)
    summary = summarise(rows, cases)
    (out / "summary.md").write_text(summary)
    took = f"The whole study took {seconds:.0f} s (set-up included) on {os.cpu_count()} cores"
    if load is not None:
        # Timings are only as good as the machine was quiet: say how busy it was.
        took += f"; 1-minute load average {load[0]:.2f} before, {load[1]:.2f} after"
    parts = [summary, took + ".", ""]
    for case in cases:
        plot(rows, case, out / f"study_{case.name}.png")
        parts += [
            f"## {case.title}",
            "",
            f"![{case.name}](study_{case.name}.png)",
            "",
            _table(rows, case),
        ]
    parts += [
        "Columns: relative errors are signed (computed - exact) / exact; *wall share* is the "
        "energy the wall dissipated over the energy put in (initial plus external work); "
        "*balance err* the largest energy balance error of the run; *loop* the wall time "
        "of the time loop. Every run and its reference: `rwall_fem/study/cases.py`.",
        "",
    ]
    (out / "study.md").write_text("\n".join(parts))
