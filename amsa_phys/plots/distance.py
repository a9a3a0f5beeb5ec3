"""The paper's Fig. 5/6: the quality signal against time, reference, tolerance, phases."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from .save import save_png


def read_trace(path: Path) -> tuple[list[str], np.ndarray]:
    """The trace's column names and its values as a 2-D array (read once per file version:
    a run draws several plots from the same trace)."""
    st = Path(path).stat()
    return _read_trace(str(path), st.st_mtime_ns, st.st_size)


@functools.lru_cache(maxsize=2)
def _read_trace(path: str, mtime_ns: int, size: int) -> tuple[list[str], np.ndarray]:
    with open(path, encoding="utf-8") as fh:
        header = fh.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    data.flags.writeable = False  # shared between callers
    return header, data


def plot_distance(trace: Path, metrics: dict[str, Any], out: Path) -> Path:
    """Draw the quality signal of ``trace`` with the phases of ``metrics`` into ``out``."""
    header, data = read_trace(trace)
    quality = metrics.get("quality") or {}
    signal = quality.get("signal")
    fig, ax = plt.subplots(figsize=(10, 4.5), dpi=100)
    if signal in header and data.size:
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
        top = max(float(np.max(s)), ref + tol)
        for i, phase in enumerate(metrics.get("phases", [])):
            start = phase["start"]
            if start > 0:
                ax.axvline(start, color="0.4", lw=0.8, ls=":")
            text = ", ".join(f"{k.split('.')[-1]}={v}" for k, v in phase["set"].items())
            ax.annotate(
                text,
                (start, top),
                xytext=(3, -2 - 11 * (i % 2)),
                textcoords="offset points",
                va="top",
                fontsize=8,
                color="0.25",
            )
        ax.set_ylim(bottom=0, top=top * 1.15)
    else:
        ax.text(0.5, 0.5, "no quality signal", ha="center", transform=ax.transAxes)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("distance (m)")
    ax.set_title(f"{metrics.get('scenario', '')} (seed {metrics.get('seed', '')})")
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="lower right", fontsize=8)
    return save_png(fig, out, margins=(0.065, 0.11, 0.985, 0.92))
