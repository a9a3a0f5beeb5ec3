"""A falsification's runs as what they are: continuous samples of its box, not a grid.

A sweep's heatmap gives every distinct value of an axis a column; a search's samples never
repeat a value, so a 12-run search became a 12×12 grid of which 132 cells said "none". Here
each run is a dot at its context (the first two numeric axes as x and y, coloured by the
metric; one numeric axis: the metric against it), the falsifying runs (robustness below 0)
ringed in red and the search's worst run starred: a falsification looks for the worst case,
so no "best" is marked.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.colors import TwoSlopeNorm

from .save import save_png
from .sweepmarks import SCENARIO_KEY

#: ring of a falsifying run, star of the worst
FALSIFYING_COLOUR = "#c0392b"
WORST_COLOUR = "gold"


def _number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def falsifying(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The rows whose robustness is below 0 (the column a search on a robustness writes;
    a search on a metric has none, and falsifies nothing here)."""
    out = []
    for r in rows:
        v = r.get("robustness")
        if isinstance(v, int | float) and not isinstance(v, bool) and v < 0:
            out.append(r)
    return out


def worst_row(rows: list[dict[str, Any]], objective: str, maximise: bool) -> dict[str, Any] | None:
    """The search's worst run: the highest ``objective`` (a metric) or the lowest (a
    robustness); None if no run has a value."""
    valued = [r for r in rows if _number(r.get(objective)) and not r.get("error")]
    if not valued:
        return None
    pick = max if maximise else min
    return pick(valued, key=lambda r: (float(r[objective]), -int(r.get("run", 0))))


def plot_samples(
    rows: list[dict[str, Any]],
    axes: list[str],
    metric: str,
    out: Path,
    title: str,
    scenario: str,
    objective: str,
    maximise: bool,
) -> Path:
    """Draw every run of a falsification at its context, coloured by ``metric``; ring the
    falsifying runs and star the worst one by ``objective`` (maximised or minimised)."""
    ok = [r for r in rows if _number(r.get(metric)) and not r.get("error")]
    numeric = [a for a in axes if ok and all(_number(r.get(a)) for r in ok)]
    fig, ax = plt.subplots(figsize=(8, 5.5), dpi=100)
    values = [float(r[metric]) for r in ok]
    robust = metric == "robustness" or metric.startswith("robustness.")
    norm = None
    cmap = "viridis"
    if robust and values and min(values) < 0 < max(values):
        # below 0 falsifies: red there, blue where the requirement holds, white at the bound
        norm, cmap = TwoSlopeNorm(0.0, min(values), max(values)), "RdBu"
    bad = falsifying(ok)
    worst = worst_row(rows, objective, maximise)
    if len(numeric) >= 2:
        x_axis, y_axis = numeric[0], numeric[1]
        xy = [(float(r[x_axis]), float(r[y_axis])) for r in ok]
        colour_by = values
    elif ok:
        x_axis, y_axis = (numeric[0] if numeric else axes[0]), metric
        xy = [(_position(r[x_axis], ok, x_axis), float(r[metric])) for r in ok]
        colour_by = values
    else:
        x_axis, y_axis, xy, colour_by = (axes[0] if axes else "run"), metric, [], []
        ax.text(0.5, 0.5, "no completed runs to plot", ha="center", transform=ax.transAxes)
    if xy:
        dots = ax.scatter(
            [p[0] for p in xy],
            [p[1] for p in xy],
            c=colour_by,
            cmap=cmap,
            norm=norm,
            s=36,
            edgecolors="0.3",
            linewidths=0.5,
            zorder=2,
            label=f"run ({len(xy)})",
        )
        bar = fig.colorbar(dots, ax=ax, label=metric)
        # the values themselves on the ticks: an offset (``1e-6 + 5.494e-1``) above the bar
        # makes runs that differ in the sixth digit look as far apart as a broken one
        bar.formatter.set_useOffset(False)
        bar.update_ticks()
        if y_axis == metric:
            ax.ticklabel_format(axis="y", useOffset=False)

    def at(r: dict[str, Any]) -> tuple[float, float]:
        if y_axis == metric:
            return _position(r[x_axis], ok, x_axis), float(r[metric])
        return float(r[x_axis]), float(r[y_axis])

    if bad:
        ax.scatter(
            [at(r)[0] for r in bad],
            [at(r)[1] for r in bad],
            s=280,
            facecolors="none",
            edgecolors=FALSIFYING_COLOUR,
            linewidths=2,
            zorder=3,
            label=f"falsifying: robustness < 0 ({len(bad)})",
        )
    if worst is not None and worst in ok:
        ax.plot(
            *at(worst),
            marker="*",
            ms=13,
            color=WORST_COLOUR,
            mec="k",
            ls="none",
            zorder=4,
            label=f"worst {objective} (run {worst.get('run')})",
        )
    if y_axis == metric and robust and xy:  # the bound the falsifying runs fall below
        ax.axhline(0.0, color="black", ls="--", lw=1, zorder=1, label="robustness 0")
    if y_axis == metric and ok and not numeric:
        labels = _categories(ok, x_axis)
        ax.set_xticks(range(len(labels)), [str(v) for v in labels])
    ax.set_xlabel(x_axis)
    ax.set_ylabel(y_axis)
    ax.grid(alpha=0.3)
    if xy:
        # below the axes: over the samples it hid a dot wherever "best" put it
        ax.legend(
            loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3, fontsize=8, frameon=False
        )
    if len(ok) < len(rows):  # a failed run, a point breaking a rule, a metric never reached
        title += f"\n{len(rows) - len(ok)} of {len(rows)} runs have no {metric}: left out"
    ax.set_title(title, fontsize=10)
    return save_png(fig, out, metadata={"Title": title, SCENARIO_KEY: scenario})


def _categories(rows: list[dict[str, Any]], axis: str) -> list[Any]:
    return sorted({r[axis] for r in rows}, key=str)


def _position(v: Any, rows: list[dict[str, Any]], axis: str) -> float:
    """A numeric value as itself; a categorical one as its index among the axis's values."""
    if _number(v):
        return float(v)
    return float(_categories(rows, axis).index(v))
