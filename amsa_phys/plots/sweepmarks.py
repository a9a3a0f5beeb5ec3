"""What a sweep's summary and its small multiples both draw (``summary.py``, ``facets.py``):
the runs that never reached a metric and their marks, the line on runs left out, a text
colour readable on a cell, and the PNG key naming the sweep's scenario. Apart, so that
neither plot imports the other for them.
"""

from __future__ import annotations

from typing import Any

import matplotlib.pyplot as plt

#: the PNG text chunk holding the sweep's scenario name
SCENARIO_KEY = "amsa-phys scenario"
#: metrics whose empty value means "it never happened" (the distance never settled), not a
#: failed run: such runs are drawn as "never", not left out
NEVER_METRICS = frozenset({"settling_time"})


#: the colour "never" is written in (a dark red: the run did not reach the metric)
NEVER_COLOUR = "#a01010"


def mark_nevers(ax: plt.Axes, marks: list[tuple[float, int]], fontsize: float = 8) -> None:
    """Runs that never reached the metric, drawn in the plot above their x: a hollow ▼ on
    the top edge and ``N never`` under it, in :data:`NEVER_COLOUR`.

    The marks are data on the x axis (a line in the axes' x transform), so autoscaling
    widens the x range to hold them: a grid point where no run settled has no line point,
    and its note (an annotation, which autoscaling ignores) fell outside the axes (hidden, and
    ``tight_layout`` warned on the terminal that it could not fit the figure).
    """
    if not marks:
        return
    xs = [x for x, _ in marks]
    edge = ax.get_xaxis_transform()  # x in data, y in axes fraction
    ax.plot(xs, [0.985] * len(xs), transform=edge, ls="none", marker="v", ms=8, mfc="none")
    ax.lines[-1].set(mec=NEVER_COLOUR, mew=1.6, clip_on=False, label="_never")
    for x, count in marks:
        ax.text(
            x,
            0.95,
            f"{count} never",
            transform=edge,
            ha="center",
            va="top",
            fontsize=fontsize,
            fontweight="bold",
            color=NEVER_COLOUR,
        )


def nevers(rows: list[dict[str, Any]], metric: str) -> list[dict[str, Any]]:
    """The runs that completed without ever reaching ``metric`` (``settling_time`` empty:
    the distance never settled); empty for metrics where no value means a failed run."""
    if metric.rpartition(".")[2] not in NEVER_METRICS:
        return []
    return [r for r in rows if r.get(metric) is None and not r.get("error")]


def left_out_text(rows: list[dict[str, Any]], ok: list[dict[str, Any]], metric: str) -> str:
    """The title's line on runs without a value: never reached (drawn as "never") apart
    from failed or empty runs (left out)."""
    never = len(nevers(rows, metric))
    dropped = len(rows) - len(ok) - never
    text = ""
    if never:
        text += f"\n{never} of {len(rows)} runs never reached a {metric} (drawn as 'never')"
    if dropped:
        text += f"\n{dropped} of {len(rows)} runs have no {metric} and are left out"
    return text


def luminance(rgba: tuple[float, ...]) -> float:
    """Relative luminance (WCAG, 0 black .. 1 white) of an sRGB colour."""

    def linear(c: float) -> float:
        return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4

    r, g, b = (linear(float(c)) for c in rgba[:3])
    return 0.2126 * r + 0.7152 * g + 0.0722 * b


def text_colour_on(rgba: tuple[float, ...]) -> str:
    """Black or white, whichever contrasts more with the background ``rgba`` (WCAG: black
    above a luminance of 0.179): black on viridis' yellow and green, white on its blue."""
    return "black" if luminance(rgba) > 0.179 else "white"
