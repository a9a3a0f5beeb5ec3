"""Trajectories: every true path (``X.posX``/``X.posY``) and every GPS track, to scale."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from .distance import read_trace
from .save import save_png
from .zones import draw_zones, zones_of_run


def plot_trajectory(trace: Path, metrics: dict[str, Any], out: Path) -> Path:
    """Draw the paths in ``trace`` into ``out`` (equal axes, start and end marked)."""
    header, data = read_trace(trace)
    fig, ax = plt.subplots(figsize=(7, 6), dpi=100)
    zones = zones_of_run(trace.parent / "scenario.yaml")  # terrain, from the run's own file
    draw_zones(ax, zones)
    drawn = False
    for name in header:
        if name.endswith(".posX") and name[:-4] + "posY" in header:
            comp = name[: -len(".posX")]
            x, y = data[:, header.index(name)], data[:, header.index(comp + ".posY")]
            (line,) = ax.plot(x, y, lw=1.6, label=f"{comp} (true)", zorder=3)
            ax.plot(x[0], y[0], "o", color=line.get_color(), ms=5, zorder=4)
            ax.plot(x[-1], y[-1], "s", color=line.get_color(), ms=6, zorder=4)
            drawn = True
        elif name.endswith(".gpsPosX") and name[:-7] + "gpsPosY" in header:
            comp = name[: -len(".gpsPosX")]
            x, y = data[:, header.index(name)], data[:, header.index(comp + ".gpsPosY")]
            ax.plot(x, y, ".", ms=3, alpha=0.35, label=f"{comp} (measured)", zorder=2)
            drawn = True
    if drawn:
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(fontsize=8, loc="best")
    else:
        ax.text(0.5, 0.5, "no positions in the trace", ha="center", transform=ax.transAxes)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(alpha=0.3)
    ax.set_title(f"{metrics.get('scenario', '')}: trajectories (o start, ■ end)")
    return save_png(fig, out, margins=(0.12, 0.09, 0.97, 0.93))
