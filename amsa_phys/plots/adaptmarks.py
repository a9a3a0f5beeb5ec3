"""Markers for ``adapt:`` rule switches on the distance plot (and Fig. 7).

A switch is an ``adapt`` event of ``metrics.json`` (``engine/adapt.py`` words it as
``rule 3 (worn motors): MyFollowerController.Kv=0.35 (MotorMonitor.delivered=0.51)``): a
triangle on the curve where it happened and the values it set, short names, beside it.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.axes import Axes

from ..palette import ADAPT_SWITCH, hex_colour

#: ``palette.ADAPT_SWITCH``: the timeline's grey (a switch is a change, not an alert: red is)
COLOR = hex_colour(ADAPT_SWITCH.colour)


def switch_text(detail: str) -> str:
    """``Kv=0.35`` from an adapt event's detail (the values set, parameter names short)."""
    sets = detail.split(": ", 1)[-1].rsplit(" (", 1)[0]
    out = []
    for part in sets.split(", "):
        key, _, value = part.strip().partition("=")
        out.append(f"{key.rsplit('.', 1)[-1]}={value}")
    return ", ".join(out)


def adapt_switches(
    ax: Axes, events: list[dict[str, Any]], t: np.ndarray, s: np.ndarray, color: str = COLOR
) -> int:
    """Mark every rule switch of ``events`` on the curve (t, s); returns how many."""
    switches = [e for e in events if e.get("kind") == "adapt"]
    if not switches or not t.size:
        return 0
    at = np.array([e["t"] for e in switches], dtype=float)
    y = np.interp(at, t, s)
    ax.plot(
        at,
        y,
        ADAPT_SWITCH.marker,
        color=color,
        ms=7,
        zorder=5,
        label=f"adapt: rule switch ({len(switches)})",
    )
    for x, yy, e in zip(at, y, switches, strict=True):
        ax.annotate(
            switch_text(e["detail"]),
            (x, yy),
            xytext=(0, 7),
            textcoords="offset points",
            ha="center",
            va="bottom",
            fontsize=7,
            color=color,
            zorder=6,
        )
    return len(switches)
