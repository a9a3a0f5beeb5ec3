"""A sweep's summary: a metric against one grid axis (lines, one per other value, with the
seed spread as error bars), against two numeric axes (heatmap of the seed mean), or, from
three axes on, as small multiples (one panel per value of the other axes, see
:mod:`.facets`): a legend entry per line stops being readable at a dozen lines, and a
three-axis sweep of 13 values each had 169."""

from __future__ import annotations

import re
from collections import defaultdict
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Rectangle
from matplotlib.ticker import MaxNLocator

from ..model.wording import plural
from ..requirements.objective import higher_is_better
from .facets import plot_facets
from .save import save_png
from .sweepmarks import (
    NEVER_COLOUR,
    SCENARIO_KEY,
    left_out_text,
    mark_nevers,
    nevers,
    text_colour_on,
)

#: metrics that count events: integer ticks
COUNT_METRICS = frozenset({"collisions"})
#: the best cell's frame, inside the cell by this much (cell widths)
FRAME_INSET = 0.04


def _numeric(values: list[Any]) -> bool:
    return all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)


#: From this many seeds a grid point on, the line plot draws its seeds as a spread (every
#: seed a dot, quartiles and min–max as bands) instead of min–max bars.
BAND_SEEDS = 10


def plot_summary(
    rows: list[dict[str, Any]],
    axes: list[str],
    metric: str,
    out: Path,
    title: str,
    scenario: str | None = None,
    spread: str = "auto",
) -> Path:
    """Draw ``metric`` of ``rows`` against the grid ``axes`` into ``out``.

    The PNG keeps ``title`` and ``scenario`` (the scenario's name, else the title up to its
    ``": "``) as text chunks: ``amsa-phys plot SWEEPDIR`` titles a redraw with the scenario's
    name from them (results.csv does not hold it, and the folder may be named anything).

    ``spread`` is how the line plot shows the seeds of a grid point: ``bars`` (min–max),
    ``band`` (each seed a dot, quartile and min–max bands) or ``auto`` (bands from
    :data:`BAND_SEEDS` seeds on, where bars would hide how the seeds spread).
    """
    ok = [r for r in rows if r.get(metric) is not None and not r.get("error")]
    # the best point is starred: a metric's lowest, a requirement's robustness's highest
    high = higher_is_better(metric)
    best_word = "highest" if high else "lowest"
    # what is drawn: the runs with a value and those that never reached it ("never"), so a
    # sweep where no run settled still shows its grid, every cell saying "never"
    drawn = ok + nevers(rows, metric)
    numeric_axes = [a for a in axes if _numeric([r[a] for r in drawn])]
    if drawn and len(axes) >= 3:
        return plot_facets(rows, ok, axes, numeric_axes, metric, out, title, scenario)
    fig, ax = plt.subplots(figsize=(8, 5), dpi=100)
    if not drawn or not axes:
        ax.text(0.5, 0.5, "no completed runs to plot", ha="center", transform=ax.transAxes)
    elif len(axes) == 2 and len(numeric_axes) == 2:
        # every grid point gets a cell, those without a value too (drawn grey, "none")
        xs = sorted({r[axes[0]] for r in rows if _numeric([r[axes[0]]])})
        ys = sorted({r[axes[1]] for r in rows if _numeric([r[axes[1]]])})
        grid = np.full((len(ys), len(xs)), np.nan)
        cells: dict[tuple[Any, Any], list[float]] = defaultdict(list)
        for r in ok:
            cells[(r[axes[0]], r[axes[1]])].append(float(r[metric]))
        for (x, y), vals in cells.items():
            grid[ys.index(y), xs.index(x)] = float(np.mean(vals))
        never = np.zeros(grid.shape, dtype=int)
        for r in nevers(rows, metric):
            if _numeric([r[axes[0]], r[axes[1]]]):
                never[ys.index(r[axes[1]]), xs.index(r[axes[0]])] += 1
        cmap = plt.get_cmap("viridis").with_extremes(bad="0.88")
        im = ax.imshow(np.ma.masked_invalid(grid), origin="lower", aspect="auto", cmap=cmap)
        _cell_values(ax, grid, im.norm, cmap, never)
        if np.isfinite(grid).any():
            pick = np.nanargmax if high else np.nanargmin
            j, i = np.unravel_index(int(pick(grid)), grid.shape)
            ax.add_patch(  # the best cell framed in gold (its value starred below), the
                # frame inside the cell: on its border an edge cell's frame was cut in half
                Rectangle(
                    (i - 0.5 + FRAME_INSET, j - 0.5 + FRAME_INSET),
                    1 - 2 * FRAME_INSET,
                    1 - 2 * FRAME_INSET,
                    fill=False,
                    ec="gold",
                    lw=3.5,
                    zorder=3,
                    clip_on=False,
                )
            )
            ax.plot(i, j - 0.25, marker="*", ms=13, color="gold", mec="k", ls="none", zorder=4)
            finite = grid[np.isfinite(grid)]
            top = finite.max() if high else finite.min()
            ties = int(np.count_nonzero(np.isclose(finite, top, rtol=1e-9, atol=0.0)))
            tied = f" (tied with {ties - 1} other grid point{'s' if ties > 2 else ''})"
            best = f"★ best: {axes[0]}={xs[i]:g}, {axes[1]}={ys[j]:g}"
            ax.set_title(best + (tied if ties > 1 else ""), fontsize=9)
        ax.set_xticks(range(len(xs)), [f"{x:g}" for x in xs])
        ax.set_yticks(range(len(ys)), [f"{y:g}" for y in ys])
        ax.set_xlabel(axes[0])
        ax.set_ylabel(axes[1])
        if np.isfinite(grid).any():  # no scale to show when every cell says "never"
            bar = fig.colorbar(im, ax=ax, label=f"{metric} (seed mean; {best_word} ★)")
            if is_count(metric):
                bar.ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    else:
        x_axis = numeric_axes[0] if numeric_axes else axes[0]
        others = [a for a in axes if a != x_axis]
        groups: dict[tuple[Any, ...], dict[Any, list[float]]] = defaultdict(
            lambda: defaultdict(list)
        )
        for r in ok:
            groups[tuple(r[a] for a in others)][r[x_axis]].append(float(r[metric]))
        most = max((len(v) for by_x in groups.values() for v in by_x.values()), default=1)
        band = spread == "band" or (spread == "auto" and most >= BAND_SEEDS)
        widest = 0.0  # the largest seed spread of a grid point: said, as bars can vanish
        starred = False
        for key, by_x in groups.items():
            xs = sorted(by_x, key=lambda v: (str(type(v)), v))
            mean = [float(np.mean(by_x[x])) for x in xs]
            # clamped: the mean of equal values can land 1 ulp outside [min, max], and
            # matplotlib refuses a negative error bar (no summary.png at all)
            lo = [max(0.0, m - min(by_x[x])) for m, x in zip(mean, xs, strict=True)]
            hi = [max(0.0, max(by_x[x]) - m) for m, x in zip(mean, xs, strict=True)]
            widest = max([widest, *(max(by_x[x]) - min(by_x[x]) for x in xs)])
            # one line: the legend says what its marks are (its name was just the metric)
            label = ", ".join(f"{a}={v}" for a, v in zip(others, key, strict=True)) or (
                f"mean of {plural(most, 'seed')}" + ("" if band else ", min–max bar")
            )
            positions = xs if _numeric(xs) else list(range(len(xs)))
            if band:
                _spread(ax, positions, [by_x[x] for x in xs], mean, label)
            else:
                bars = ax.errorbar(
                    positions, mean, yerr=[lo, hi], marker="o", ms=4, capsize=6, label=label
                )
                if most > 1:  # every seed a dot too: a spread below a marker still shows
                    for at, x in zip(positions, xs, strict=True):
                        ax.plot(
                            [at] * len(by_x[x]),
                            by_x[x],
                            ls="none",
                            marker=".",
                            ms=5,
                            color=bars.lines[0].get_color(),
                            gid="seed",
                        )
            best = int(np.argmax(mean) if high else np.argmin(mean))
            if others:
                star = f"{best_word} mean of each line" if not starred else "_"
            else:
                shown = f"{xs[best]:g}" if _numeric([xs[best]]) else str(xs[best])
                star = f"best: {x_axis}={shown} ({mean[best]:.4g})"
            starred = True
            ax.plot(
                [positions[best]],
                [mean[best]],
                marker="*",
                ms=14,
                color="gold",
                markeredgecolor="k",
                ls="none",
                zorder=5,
                label=star,
            )
        never_at: dict[Any, int] = defaultdict(int)
        for r in nevers(rows, metric):
            never_at[r[x_axis]] += 1
        labels = sorted({r[x_axis] for r in drawn}, key=str)
        marks = []
        for x, count in sorted(never_at.items(), key=lambda kv: str(kv[0])):
            at = x if _numeric([x]) else (labels.index(x) if x in labels else None)
            if at is not None:
                marks.append((float(at), count))
        mark_nevers(ax, marks)
        if not _numeric([r[x_axis] for r in drawn]):
            ax.set_xticks(range(len(labels)), [str(v) for v in labels])
        ax.set_xlabel(x_axis)
        ax.set_ylabel(
            metric
            + (
                f" ({most} seeds: dots, quartiles, min–max; ★ best mean)"
                if band
                else " (seed min–max as bars, ★ best)"
                if most > 1
                else " (★ best)"  # one seed: no spread to draw
            )
        )
        if is_count(metric):  # 0, 1, 2 collisions: no tick at 0.5 of one
            low, high = ax.get_ylim()  # at least 0..1 shown: all-zero counts get 0 and 1
            ax.set_ylim(min(low, -0.25), max(high, 1.25))
            ax.yaxis.set_major_locator(MaxNLocator(integer=True))
        ax.grid(alpha=0.3)
        if groups:  # no line when every run said "never"
            ax.legend(fontsize=8)
            if most > 1 and not band:
                low, high = ax.get_ylim()
                share = widest / (high - low) if high > low else 0.0
                if share < 0.02:  # bars this short read as "no spread": say how small
                    ax.set_title(
                        f"largest seed spread (min–max) {widest:.3g}: {axis_share(share)}"
                        f" ({plural(most, 'seed')} each)",
                        fontsize=9,
                    )
    title += left_out_text(rows, ok, metric)
    if ax.get_title():  # the heatmap's best cell
        title += "\n" + ax.get_title()
    ax.set_title(title, fontsize=10)
    name = scenario if scenario is not None else title.split("\n")[0].rpartition(": ")[0]
    return save_png(fig, out, metadata={"Title": title, SCENARIO_KEY: name})


def cut_note(duration: float, full: float) -> str:
    """What a summary's title says of a sweep whose runs ``--duration`` shortened (the
    scenario's ``full`` length cut to ``duration``): a metric of 30 s is not one of 500 s."""
    return f"runs cut to {duration:g} s of {full:g} s"


#: :func:`cut_note`'s words in a title, read back by :func:`cut_of`
_CUT = re.compile(r"runs cut to [0-9.e+]+ s of [0-9.e+]+ s")


def cut_of(summary_png: Path) -> str | None:
    """The :func:`cut_note` a sweep's ``summary.png`` title carries (None if none): a redraw
    (``plot SWEEPDIR``) says it again; results.csv does not hold the runs' length."""
    from .save import png_text

    found = _CUT.search(png_text(summary_png).get("Title", ""))
    return found.group(0) if found else None


def scenario_of(summary_png: Path) -> str | None:
    """The scenario's name a sweep's ``summary.png`` was drawn for (None if not known)."""
    from .save import png_text

    return png_text(summary_png).get(SCENARIO_KEY) or None


def is_count(metric: str) -> bool:
    """Whether a metric counts events (``collisions``, ``phase1.collisions``): its axis
    gets integer ticks."""
    return metric.rpartition(".")[2] in COUNT_METRICS


def _spread(
    ax: plt.Axes, xs: list[Any], values: list[list[float]], mean: list[float], label: str
) -> None:
    """One line's seeds: the mean as a line, every seed a dot, the quartiles and the
    min–max as bands in the line's colour."""
    (line,) = ax.plot(xs, mean, marker="o", ms=3, label=label)
    color = line.get_color()
    lo, q1, q3, hi = (
        [float(np.percentile(v, q)) for v in values] for q in (0.0, 25.0, 75.0, 100.0)
    )
    ax.fill_between(xs, lo, hi, color=color, alpha=0.1, lw=0)
    ax.fill_between(xs, q1, q3, color=color, alpha=0.25, lw=0)
    for x, v in zip(xs, values, strict=True):
        ax.plot([x] * len(v), v, ls="none", marker=".", ms=2.5, color=color, alpha=0.45)


def _cell_values(
    ax: plt.Axes, grid: np.ndarray, norm: Any, cmap: Any, never: np.ndarray | None = None
) -> None:
    """Each heatmap cell's value, in black or white by its cell's luminance; a cell whose
    runs never reached the metric (never settled) says so, with how many."""
    for (j, i), value in np.ndenumerate(grid):
        finite = bool(np.isfinite(value))
        count = int(never[j, i]) if never is not None else 0
        colour = text_colour_on(cmap(norm(value))) if finite else "0.4"
        text = f"{value:.3g}" if finite else "none"
        if count:
            text = f"{text}\n+{count} never" if finite else "never"
            colour = colour if finite else NEVER_COLOUR
        ax.text(
            i,
            j,
            text,
            ha="center",
            va="center",
            fontsize=8,
            color=colour,
        )


def axis_share(share: float) -> str:
    """A spread's share of the axis as the title says it: ``0.9% of the axis``; a spread
    below what one decimal shows is not called 0.0 % (``none``: the seeds agree exactly;
    ``under 0.1% of the axis`` otherwise)."""
    if share <= 0.0:
        return "none (the seeds agree exactly)"
    if share < 0.0005:
        return "under 0.1% of the axis"
    return f"{share:.1%} of the axis"
