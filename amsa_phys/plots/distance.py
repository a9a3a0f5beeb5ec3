"""The paper's Fig. 5/6: the quality signal against time, reference, tolerance, phases."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..engine.traceread import MAX_LINE_BYTES, read_rows
from ..palette import COLLISION, PHASE, REFERENCE, SIGNAL, hex_colour
from ..valuetext import value_text
from .adaptmarks import adapt_switches
from .save import save_png

#: Values beyond this are not drawn (NaN): matplotlib's limits overflow near the float limit.
PLOTTABLE = 1e200


def read_trace(path: Path, keep: frozenset[str] | None = None) -> tuple[list[str], np.ndarray]:
    """The trace's column names and its values as a 2-D array (read once per file version:
    a run draws several plots from the same trace).

    ``keep``: only these columns (and ``t``) are converted and returned, in the trace's
    order; a 200-rover trace has 3600 columns and its plots need a third of them, which
    halves the read. Every row is still checked to be as wide as the header.

    A file that is not a whole trace -- binary junk, a row cut short (no end of line, as a
    killed writer would leave), rows wider or narrower than the header -- is refused with
    one line naming the file and line (ConfigError), never plotted as if it were one.
    """
    st = Path(path).stat()
    return _read_trace(str(path), st.st_mtime_ns, st.st_size, keep)


def trace_header(path: Path) -> list[str]:
    """The column names on a trace's first line (what :func:`read_trace` may ``keep``)."""
    with open(path, "rb") as fh:
        head = fh.readline(MAX_LINE_BYTES)
    return head.decode("utf-8", "replace").rstrip("\n").split(",")


@functools.lru_cache(maxsize=2)
def _read_trace(
    path: str, mtime_ns: int, size: int, keep: frozenset[str] | None = None
) -> tuple[list[str], np.ndarray]:
    # streamed, judged row by row, decimated to a bounded size (traceread.py)
    header, data, _stride = read_rows(Path(path), keep)
    data[~(np.abs(data) < PLOTTABLE)] = np.nan  # inf, nan and the unplottable
    data.flags.writeable = False  # shared between callers
    return header, data


NOTE_PT = 7.5  # phase notes' font size
MAX_NOTE_LINES = 5
FIG_H_IN = 4.5
MARGINS = (0.065, 0.11, 0.985, 0.92)  # left, bottom, right, top: fixed, so the band is known
AXES_HEIGHT_PT = FIG_H_IN * (MARGINS[3] - MARGINS[1]) * 72


def _phase_notes(ax: Axes, phases: list[dict[str, Any]]) -> list[str]:
    """Mark each phase's start and write what it set, one change a line, at the top.

    One change a line keeps a note as narrow as its longest change, so it fits in its phase
    (a one-line note ran past the next phase's line and over its note). Returns the lines of
    the tallest note (the band the caller keeps free above the data).
    """
    tallest: list[str] = []
    for phase in phases:
        start = phase["start"]
        if start > 0:
            ax.axvline(start, color=hex_colour(PHASE), lw=0.8, ls=":")
        lines = [f"{k.split('.')[-1]}={value_text(v)}" for k, v in phase["set"].items()]
        if len(lines) > MAX_NOTE_LINES:
            lines = [*lines[: MAX_NOTE_LINES - 1], f"+{len(lines) - MAX_NOTE_LINES + 1} more"]
        if phase.get("label"):
            lines.insert(0, str(phase["label"]))
        if not lines:
            continue
        ax.annotate(
            "\n".join(lines),
            (start, 1.0),
            xycoords=("data", "axes fraction"),
            xytext=(3, -3),
            textcoords="offset points",
            va="top",
            fontsize=NOTE_PT,
            color="0.25",
            linespacing=1.1,
        )
        tallest = max(tallest, lines, key=len)
    return tallest


def _inner_changes(ax: Axes, phases: list[dict[str, Any]]) -> list[float]:
    """Mark changes made inside a phase (live in the window, ``new_phase: false``): a dashed
    line in the timeline's grey (``palette.PHASE``; phase starts are dotted) and what was
    set, upright along the bottom so it never meets the phase notes; one legend entry for
    them all. Returns their times (the legend is kept off them)."""
    times = []
    for phase in phases:
        for change in phase.get("changes", []):
            at = change["at"]
            times.append(float(at))
            ax.axvline(
                at,
                color=hex_colour(PHASE),
                lw=0.8,
                ls="--",
                alpha=0.8,
                label="change inside a phase" if len(times) == 1 else None,
            )
            what = ", ".join(
                f"{k.split('.')[-1]}={value_text(v)}" for k, v in change["set"].items()
            )
            label = change.get("label")
            ax.annotate(
                f"{label}: {what}" if label else what,
                (at, 0.0),
                xycoords=("data", "axes fraction"),
                xytext=(-2, 4),
                textcoords="offset points",
                rotation=90,
                ha="right",
                va="bottom",
                fontsize=NOTE_PT - 0.5,
                color=hex_colour(PHASE),
                zorder=6,  # over the legend, should they ever meet
            )
    return times


#: where the legend may go, and the span of the time axis (fractions) it covers there
LEGEND_PLACES = (("lower right", 0.6, 1.0), ("lower left", 0.0, 0.4), ("lower center", 0.3, 0.7))


def _legend_place(ax: Axes, times: list[float]) -> str:
    """The first of :data:`LEGEND_PLACES` whose span holds no live-change label (those
    stand upright along the bottom, just left of their line); "lower right" when every
    span has one (the labels are drawn over the legend then)."""
    lo, hi = ax.get_xlim()
    at = [(t - lo) / (hi - lo) for t in times] if hi > lo else []
    for place, start, end in LEGEND_PLACES:
        if not any(start - 0.01 <= x <= end + 0.03 for x in at):
            return place
    return LEGEND_PLACES[0][0]


def _collisions(ax: Axes, events: list[dict[str, Any]], t: np.ndarray, s: np.ndarray) -> None:
    """``palette.COLLISION`` on the curve at every collision (its detail names who touched)."""
    at = np.array([e["t"] for e in events if e.get("kind") == "collision"], dtype=float)
    if not at.size:
        return
    ax.plot(
        at,
        np.interp(at, t, s),
        COLLISION.marker,
        color=hex_colour(COLLISION.colour),
        mec="k",
        ms=7,
        mew=0.8,
        ls="",
        zorder=5,
        label=f"collision ({at.size})",
    )


def _shortened(metrics: dict[str, Any], ran: float) -> str:
    """`` — shortened to 60 s of 500 s by --duration (1 of 4 phases, the last cut)``; a run
    whose metrics predate ``planned`` (or cannot be read) says ``its last phase cut``."""
    planned = metrics.get("planned")
    done = metrics.get("phases")
    try:
        total = int(planned["phases"])
        end = float(planned["end"])
    except (KeyError, TypeError, ValueError):
        total, end = 0, 0.0
    if not total or not isinstance(done, list) or not done:
        return f" — shortened to {ran:g} s by --duration (its last phase cut)"
    what = "its one phase" if total == 1 else f"{len(done)} of {total} phases, the last"
    return f" — shortened to {ran:g} s of {end:g} s by --duration ({what} cut)"


def cut_note(metrics: dict[str, Any]) -> str:
    """`` — cut at 42.5 s of 500 s (closed in the window)`` for a run that stopped before
    its end (the window closed, Ctrl-C, a fault, ``--duration``); empty for a whole run.

    Every plot of the run puts it in its title: a curve that ends at 42.5 s must say that
    the run ended there, not that the scenario is 42.5 s long.
    """
    try:
        ran = float(metrics.get("simulated", metrics.get("duration", 0)))
        planned = float(metrics.get("duration", ran))
    except (TypeError, ValueError):
        return ""
    status = str(metrics.get("status") or "completed")
    if status == "completed" and ran >= planned:
        # a whole run of a scenario that --duration shortened: its last phase is cut
        overall = metrics.get("overall")
        if isinstance(overall, dict) and overall.get("partial"):
            return _shortened(metrics, ran)
        return ""
    why = {"interrupted": "interrupted (Ctrl-C)"}.get(status, status)
    why = why.split(" at t=")[0]  # "closed in the window at t=42.5 s": the time is said once
    if why.startswith("fault"):
        why = "a fault"
    return f" — cut at {ran:g} s of {planned:g} s ({why})"


def plot_distance(
    trace: Path, metrics: dict[str, Any], out: Path, keep: frozenset[str] | None = None
) -> Path:
    """Draw the quality signal of ``trace`` with the phases of ``metrics`` into ``out``
    (``keep``: the columns to read, :func:`read_trace`)."""
    fig = distance_figure(trace, metrics, keep)
    return save_png(fig, out, margins=MARGINS)


def distance_figure(
    trace: Path, metrics: dict[str, Any], keep: frozenset[str] | None = None
) -> Figure:
    """The figure :func:`plot_distance` saves, laid out with its final margins."""
    header, data = read_trace(trace, keep)
    quality = metrics.get("quality") or {}
    signal = quality.get("signal")
    fig = Figure(figsize=(10, FIG_H_IN), dpi=100)  # not pyplot's: the child never imports it
    FigureCanvasAgg(fig)  # the canvas pyplot would give it (callers draw and measure on it)
    ax = fig.subplots()
    changes: list[float] = []
    if signal in header and data.size:
        t = data[:, 0]
        s = data[:, header.index(signal)]
        ref = float(quality["reference"])
        tol = float(quality["tolerance"])
        # a tolerance near the float limit (the schema takes any finite one) is drawn to
        # PLOTTABLE: the axis's top, its edge with headroom, would overflow to inf
        band = min(tol, PLOTTABLE)
        ref_colour = hex_colour(REFERENCE)
        top = float(np.nanmax(s)) if np.isfinite(s).any() else 0.0
        if abs(ref) < PLOTTABLE:
            ax.fill_between(
                [t[0], t[-1]],
                ref - band,
                ref + band,
                color=ref_colour,
                alpha=0.15,
                label=f"tolerance ±{tol:g} m",
            )
            ax.axhline(ref, color=ref_colour, lw=1.2, ls="--", label=f"reference {ref:g} m")
            top = max(top, ref + band)
        else:  # a legal reference near the float limit: the signal still has its plot
            ax.plot(
                [],
                [],
                color=ref_colour,
                lw=1.2,
                ls="--",
                label=f"reference {ref:g} m (off the scale)",
            )
        # palette.SIGNAL, near-black: blue and orange are the rovers' colours everywhere
        ax.plot(t, s, color=hex_colour(SIGNAL), lw=1.2, label=signal)
        lines = _phase_notes(ax, metrics.get("phases", []))
        changes = _inner_changes(ax, metrics.get("phases", []))
        _collisions(ax, metrics.get("events", []), t, s)
        adapt_switches(ax, metrics.get("events", []), t, s)
        # the notes get a band of their own above the data: the curve never runs through them
        band = (len(lines) * NOTE_PT * 1.25 + 8) / AXES_HEIGHT_PT if lines else 0.05
        ax.set_ylim(bottom=0, top=top * 1.05 / max(0.4, 1 - band))
    else:
        ax.text(0.5, 0.5, "no quality signal", ha="center", transform=ax.transAxes)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("distance (m)")
    ax.set_title(
        f"{metrics.get('scenario', '')} (seed {metrics.get('seed', '')}){cut_note(metrics)}"
    )
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc=_legend_place(ax, changes), fontsize=8)
    fig.subplots_adjust(*MARGINS)
    return fig
