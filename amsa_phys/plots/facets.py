"""Small multiples for sweeps of three axes or more: one panel per value of the other axes.

A line per grid point with a legend entry each is readable up to a dozen lines; a three-axis
sweep of 13 values each drew 169 entries over the plot. Here two numeric axes become a
heatmap in every panel (one colour scale shared by all panels, so panels compare at a
glance), the remaining axes choose the panel, and the best cell of the whole sweep is framed
in gold in its panel and named in the title. Without two numeric axes each panel holds one
line (metric against the first axis, seed min–max as bars) on a shared y scale.

More than :data:`MAX_PANELS` panels would be too small to read: the panels then follow the
first remaining axis only (the cells are then means over the other remaining axes too, and
the title says so), and if that axis alone has too many values every k-th is shown.
"""

from __future__ import annotations

import math
import textwrap
from collections import defaultdict
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Rectangle

from ..requirements.objective import higher_is_better
from .save import save_png
from .sweepmarks import (
    NEVER_COLOUR,
    SCENARIO_KEY,
    left_out_text,
    mark_nevers,
    nevers,
    text_colour_on,
)

#: Most panels drawn; past it the panels follow one axis (see the module docstring).
MAX_PANELS = 16
#: Most cells a panel writes its values in; past it the colours alone tell.
MAX_LABELLED_CELLS = 36
#: Most tick labels on a panel's axis (every k-th value labelled past it).
MAX_TICKS = 7


def _sort_key(value: Any) -> tuple[str, Any]:
    return (type(value).__name__, value)


def _label(value: Any) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def _ticks(n: int) -> list[int]:
    step = max(1, math.ceil(n / MAX_TICKS))
    return list(range(0, n, step))


def plot_facets(
    rows: list[dict[str, Any]],
    ok: list[dict[str, Any]],
    axes: list[str],
    numeric_axes: list[str],
    metric: str,
    out: Path,
    title: str,
    scenario: str | None,
) -> Path:
    """Draw ``metric`` of a sweep of three axes or more as small multiples into ``out``.

    ``rows`` are every run (grid points without a value are drawn grey), ``ok`` the runs
    with a value of ``metric``; ``numeric_axes`` the axes whose values are all numbers.
    """

    def count(axis: str) -> int:
        return len({r[axis] for r in rows})

    # the heatmap takes the two numeric axes with the most values, the panels the axes with
    # the fewest (each in the sweep's order among equals): fewer, larger panels
    by_size = sorted(numeric_axes, key=lambda a: -count(a))
    heat = len(numeric_axes) >= 2
    x_axis = by_size[0] if numeric_axes else axes[0]
    y_axis = by_size[1] if heat else None
    facet_axes = sorted((a for a in axes if a not in (x_axis, y_axis)), key=count)
    keys = sorted(
        {tuple(r[a] for a in facet_axes) for r in rows}, key=lambda k: [_sort_key(v) for v in k]
    )
    notes: list[str] = []
    if len(keys) > MAX_PANELS:
        first, rest = facet_axes[0], facet_axes[1:]
        values = sorted({r[first] for r in rows}, key=_sort_key)
        if len(values) > MAX_PANELS:
            step = math.ceil(len(values) / MAX_PANELS)
            values = values[::step]
            notes.append(f"every {step}th value of {first} shown")
        if rest:
            notes.append("cells are means over " + ", ".join(rest) + " too")
        facet_axes = [first]
        keys = [(v,) for v in values]
    panel_of = {k: i for i, k in enumerate(keys)}

    xs = sorted({r[x_axis] for r in rows}, key=_sort_key)
    ys = sorted({r[y_axis] for r in rows}, key=_sort_key) if y_axis else [None]
    cells: dict[tuple[int, Any, Any], list[float]] = defaultdict(list)
    for r in ok:
        panel = panel_of.get(tuple(r[a] for a in facet_axes))
        if panel is not None:
            cells[(panel, r[x_axis], r[y_axis] if y_axis else None)].append(float(r[metric]))
    grids = np.full((len(keys), len(ys), len(xs)), np.nan)
    spread = np.full((len(keys), 2, len(xs)), np.nan)  # seed min, max (line panels)
    never = np.zeros(grids.shape, dtype=int)
    for r in nevers(rows, metric):
        panel = panel_of.get(tuple(r[a] for a in facet_axes))
        if panel is not None:
            never[panel, ys.index(r[y_axis] if y_axis else None), xs.index(r[x_axis])] += 1
    for (panel, x, y), vals in cells.items():
        grids[panel, ys.index(y), xs.index(x)] = float(np.mean(vals))
        spread[panel, :, xs.index(x)] = (min(vals), max(vals))

    n = len(keys)
    ncols = math.ceil(math.sqrt(n))
    nrows = math.ceil(n / ncols)
    fig, panels = plt.subplots(
        nrows,
        ncols,
        figsize=(2.9 * ncols + 1.6, 2.4 * nrows + 1.3),
        dpi=100,
        squeeze=False,
        sharex=True,
        sharey=True,
        layout="constrained",
    )
    flat = list(panels.flat)
    for ax in flat[n:]:
        ax.set_visible(False)
    finite = grids[np.isfinite(grids)]
    high = higher_is_better(metric)  # a requirement's robustness: its highest is best
    pick = np.nanargmax if high else np.nanargmin
    best = np.unravel_index(int(pick(grids)), grids.shape) if finite.size else None
    best_text = ""
    if heat:
        cmap = plt.get_cmap("viridis").with_extremes(bad="0.88")
        lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
        image = None
        for i, ax in enumerate(flat[:n]):
            image = ax.imshow(
                np.ma.masked_invalid(grids[i]),
                origin="lower",
                aspect="auto",
                cmap=cmap,
                vmin=lo,
                vmax=hi if hi > lo else lo + 1.0,
            )
            if len(xs) * len(ys) <= MAX_LABELLED_CELLS:
                for (j, k), value in np.ndenumerate(grids[i]):
                    ok_value = bool(np.isfinite(value))
                    colour = text_colour_on(cmap(image.norm(value))) if ok_value else "0.4"
                    text = f"{value:.3g}" if ok_value else "none"
                    if never[i, j, k]:
                        text = f"{text}\n+{never[i, j, k]} never" if ok_value else "never"
                        colour = colour if ok_value else NEVER_COLOUR
                    ax.text(k, j, text, ha="center", va="center", fontsize=6.5, color=colour)
        if best is not None:
            p, j, k = (int(v) for v in best)
            flat[p].add_patch(
                Rectangle((k - 0.46, j - 0.46), 0.92, 0.92, fill=False, ec="gold", lw=2.5)
            )
            flat[p].plot(k, j - 0.25, marker="*", ms=10, color="gold", mec="k", ls="none")
            best_text = f"{x_axis}={_label(xs[k])}, {y_axis}={_label(ys[j])}"
        if image is not None and finite.size:  # no scale when every cell says "never"
            most = "highest" if high else "lowest"
            fig.colorbar(image, ax=flat[:n], label=f"{metric} (seed mean; {most} ★)", shrink=0.9)
        for ax in flat[:n]:
            ax.set_xticks(_ticks(len(xs)), [_label(xs[t]) for t in _ticks(len(xs))])
            ax.set_yticks(_ticks(len(ys)), [_label(ys[t]) for t in _ticks(len(ys))])
        fig.supxlabel(x_axis, fontsize=9)
        fig.supylabel(str(y_axis), fontsize=9)
    else:
        positions = list(range(len(xs))) if not numeric_axes else [float(x) for x in xs]
        for i, ax in enumerate(flat[:n]):
            mean = grids[i, 0]
            have = np.isfinite(mean)
            pos = [p for p, h in zip(positions, have, strict=True) if h]
            m = mean[have]
            err = [np.maximum(0.0, m - spread[i, 0][have]), np.maximum(0.0, spread[i, 1][have] - m)]
            ax.errorbar(pos, m, yerr=err, marker="o", ms=3, capsize=2)
            # runs that never reached the metric: marked above their x, inside the panel
            marks = [(float(positions[k]), int(c)) for k, c in enumerate(never[i, 0]) if c]
            mark_nevers(ax, marks, fontsize=6.5)
            ax.grid(alpha=0.3)
        if best is not None:
            p, _, k = (int(v) for v in best)
            flat[p].plot(positions[k], grids[p, 0, k], marker="*", ms=12, color="gold", mec="k")
            best_text = f"{x_axis}={_label(xs[k])}"
        if not numeric_axes:
            for ax in flat[:n]:
                ax.set_xticks(positions, [_label(x) for x in xs])
        fig.supxlabel(x_axis, fontsize=9)
        fig.supylabel(f"{metric} (seed min–max as bars, ★ best)", fontsize=9)
    for key, ax in zip(keys, flat[:n], strict=True):
        ax.set_title(
            ", ".join(
                f"{a.rpartition('.')[2]}={_label(v)}" for a, v in zip(facet_axes, key, strict=True)
            ),
            fontsize=8,
        )
    if best is not None:
        p = int(best[0])
        where = ", ".join(f"{a}={_label(v)}" for a, v in zip(facet_axes, keys[p], strict=True))
        best_text = f"★ best: {best_text}, {where}"
        # equal values (axes that did not matter in these runs): the star marks the first,
        # and the title says the others are as good rather than implying one winner
        top = finite.max() if high else finite.min()
        ties = int(np.count_nonzero(np.isclose(finite, top, rtol=1e-9, atol=0.0))) - 1
        if ties:
            best_text += f" (tied with {ties} other grid point{'s' if ties > 1 else ''})"
    lines = [title, *left_out_text(rows, ok, metric).splitlines()[1:]]
    if notes:
        lines.append("; ".join(notes))
    if best_text:
        lines.append(best_text)
    # wrapped to the figure's width: a best point of three long axis names ran off both
    # edges of a two-panel figure (~5.4 pt a character at 9 pt)
    chars = max(40, int(fig.get_figwidth() * 72 / 5.4))
    full = "\n".join(textwrap.fill(line, chars) for line in lines)
    fig.suptitle(full, fontsize=9)
    name = scenario if scenario is not None else title.split("\n")[0].rpartition(": ")[0]
    return save_png(fig, out, metadata={"Title": full, SCENARIO_KEY: name})
