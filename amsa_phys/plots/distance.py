"""The paper's Fig. 5/6: the quality signal against time, reference, tolerance, phases."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from ..errors import ConfigError
from ..model.params import short_repr
from .save import save_png

#: Values beyond this are not drawn (NaN): matplotlib's limits overflow near the float limit.
PLOTTABLE = 1e200


def read_trace(path: Path) -> tuple[list[str], np.ndarray]:
    """The trace's column names and its values as a 2-D array (read once per file version:
    a run draws several plots from the same trace).

    A file that is not a whole trace -- binary junk, a row cut short (no end of line, as a
    killed writer would leave), rows wider or narrower than the header -- is refused with
    one line naming the file and line (ConfigError), never plotted as if it were one.
    """
    st = Path(path).stat()
    return _read_trace(str(path), st.st_mtime_ns, st.st_size)


@functools.lru_cache(maxsize=2)
def _read_trace(path: str, mtime_ns: int, size: int) -> tuple[list[str], np.ndarray]:
    try:
        with open(path, encoding="utf-8", newline="") as fh:
            text = fh.read()
    except UnicodeDecodeError as exc:
        raise ConfigError(f"not a trace: not UTF-8 text (byte {exc.start})", file=path) from None
    lines = text.split("\n")
    header = lines[0].split(",")
    if header[0] != "t" or not text.endswith("\n"):
        problem = "no header line starting with t" if header[0] != "t" else "cut short"
        where = 1 if header[0] != "t" else len(lines)
        raise ConfigError(f"not a whole trace: {problem}", file=path, line=where)
    rows = lines[1:-1]
    try:
        data = np.loadtxt(rows, delimiter=",", ndmin=2) if rows else np.empty((0, len(header)))
    except ValueError:
        data = np.empty((0, 0))  # found below, with its line
    if data.shape[1:] != (len(header),):
        line, problem = _bad_row(rows, len(header))
        raise ConfigError(f"not a whole trace: {problem}", file=path, line=line)
    data[~(np.abs(data) < PLOTTABLE)] = np.nan  # inf, nan and the unplottable
    data.flags.writeable = False  # shared between callers
    return header, data


def _bad_row(rows: list[str], width: int) -> tuple[int, str]:
    """The first row (as a file line) that is not ``width`` numbers, and what is wrong."""
    for i, row in enumerate(rows):
        cells = row.split(",")
        if len(cells) != width:
            return i + 2, f"{len(cells)} values where the header names {width}"
        for cell in cells:
            try:
                float(cell)
            except ValueError:
                return i + 2, f"{short_repr(cell)} is not a number"
    return 1, "unreadable"


NOTE_PT = 7.5  # phase notes' font size
MAX_NOTE_LINES = 5
FIG_H_IN = 4.5
MARGINS = (0.065, 0.11, 0.985, 0.92)  # left, bottom, right, top: fixed, so the band is known
AXES_HEIGHT_PT = FIG_H_IN * (MARGINS[3] - MARGINS[1]) * 72


def _phase_notes(ax: plt.Axes, phases: list[dict[str, Any]]) -> list[str]:
    """Mark each phase's start and write what it set, one change a line, at the top.

    One change a line keeps a note as narrow as its longest change, so it fits in its phase
    (a one-line note ran past the next phase's line and over its note). Returns the lines of
    the tallest note (the band the caller keeps free above the data).
    """
    tallest: list[str] = []
    for phase in phases:
        start = phase["start"]
        if start > 0:
            ax.axvline(start, color="0.4", lw=0.8, ls=":")
        lines = [f"{k.split('.')[-1]}={v}" for k, v in phase["set"].items()]
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


def plot_distance(trace: Path, metrics: dict[str, Any], out: Path) -> Path:
    """Draw the quality signal of ``trace`` with the phases of ``metrics`` into ``out``."""
    fig = distance_figure(trace, metrics)
    return save_png(fig, out, margins=MARGINS)


def distance_figure(trace: Path, metrics: dict[str, Any]) -> Figure:
    """The figure :func:`plot_distance` saves, laid out with its final margins."""
    header, data = read_trace(trace)
    quality = metrics.get("quality") or {}
    signal = quality.get("signal")
    fig, ax = plt.subplots(figsize=(10, FIG_H_IN), dpi=100)
    if signal in header and data.size and abs(float(quality["reference"])) < PLOTTABLE:
        t = data[:, 0]
        s = data[:, header.index(signal)]
        ref = float(quality["reference"])
        tol = float(quality["tolerance"])
        ax.fill_between(
            [t[0], t[-1]],
            ref - tol,
            ref + tol,
            color="tab:green",
            alpha=0.15,
            label=f"tolerance ±{tol:g} m",
        )
        ax.axhline(ref, color="tab:green", lw=1.2, ls="--", label=f"reference {ref:g} m")
        ax.plot(t, s, color="tab:blue", lw=1.2, label=signal)
        top = max(float(np.nanmax(s)) if np.isfinite(s).any() else 0.0, ref + tol)
        lines = _phase_notes(ax, metrics.get("phases", []))
        # the notes get a band of their own above the data: the curve never runs through them
        band = (len(lines) * NOTE_PT * 1.25 + 8) / AXES_HEIGHT_PT if lines else 0.05
        ax.set_ylim(bottom=0, top=top * 1.05 / max(0.4, 1 - band))
    else:
        ax.text(0.5, 0.5, "no quality signal", ha="center", transform=ax.transAxes)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("distance (m)")
    ax.set_title(f"{metrics.get('scenario', '')} (seed {metrics.get('seed', '')})")
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="lower right", fontsize=8)
    fig.subplots_adjust(*MARGINS)
    return fig
