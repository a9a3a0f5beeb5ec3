"""Terrain zones on the trajectory plot: each zone's polygon and ground, and the timeline's
changes to it in its label.

A zone is a component whose template declares a :class:`~amsa_phys.templatemarks.Zone` mark
(the built-in ``frictionZone``, ``physics/zones.py``, or a user's own). The caller gives the
zones' parameters (the world's), their marks and the run's
:class:`~amsa_phys.model.timeline.Timeline` (the one the run ran, or
``runs.rundata.timeline_of`` a run directory's, read as data): the plot says "Mud: μ 0.8,
from 60 s μ 0.3" without the run's objects and without reading a file itself. Drawn under
the paths, in the colours the window uses.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Any

import numpy as np

from ..model.timeline import Timeline
from ..physics.terrain import zone_colours
from ..templatemarks import Zone

if TYPE_CHECKING:
    from matplotlib.axes import Axes


@dataclass(frozen=True)
class ZoneShape:
    """A zone as plotted: path, polygon, values at t = 0 and a one-line label."""

    name: str
    polygon: tuple[tuple[float, float], ...]
    friction: float
    rolling_resistance: float
    label: str


def zones_of(
    params: Mapping[str, Mapping[str, Any]], declared: Mapping[str, Zone], timeline: Timeline
) -> list[ZoneShape]:
    """The zones of a run: ``declared`` maps each zone's path to its template's mark,
    ``params`` each Leaf's parameters as its world gives them; the timeline's values at t = 0
    are taken over them, and its later changes to a zone's ground go in its label.

    Matplotlib-free, so a run's process can hand the zones to its plotting child with the
    job instead of the child reading ``scenario.yaml`` (which is then still being written).
    """
    values = {path: dict(params.get(path) or {}) for path in declared}
    for change in timeline.initial:
        if change.leaf in values:
            values[change.leaf][change.param] = change.value
    changes: dict[str, list[str]] = {}
    for point in timeline.points():
        said: dict[str, list[str]] = {}
        for change in point.changes:
            mark = declared.get(change.leaf)
            if mark is not None and change.param in (mark.friction, mark.rolling_resistance):
                word = "μ" if change.param == mark.friction else "Crr"
                said.setdefault(change.leaf, []).append(f"{word} {change.value}")
        for path, words in said.items():
            text = f"from {_at(point.at)} s " + ", ".join(words)
            changes.setdefault(path, []).append(text)
    out = []
    for path, mark in declared.items():
        given = values[path]
        mu = float(given.get(mark.friction, 0.3))
        crr = float(given.get(mark.rolling_resistance, 0.1))
        label = "; ".join([f"{path}: μ {mu:g}, Crr {crr:g}", *changes.get(path, [])])
        pts = tuple((float(x), float(y)) for x, y in given.get(mark.polygon) or ())
        if len(pts) >= 3:
            out.append(ZoneShape(path, pts, mu, crr, label))
    return out


def _at(at: Any) -> str:
    """An instant as the label says it: ``60``, ``15.25``; an exact fraction that no short
    decimal writes (``7/3``) as the fraction."""
    text = f"{float(at):g}"
    return text if Fraction(text) == at else str(at)


def draw_zones(
    ax: Axes,
    zones: list[ZoneShape],
    view: Callable[[np.ndarray], np.ndarray] | None = None,
) -> None:
    """Fill each zone (blue if slippery, else brown) and name it, under everything else.

    ``view`` maps world metres to plot coordinates (the trajectory plot's lateral-offset
    frame), so a zone stays under the paths that cross it in any view.
    """
    from matplotlib.patches import Polygon  # here: zones_of runs without matplotlib

    for z in zones:
        pts = np.asarray(z.polygon, dtype=float)
        if view is not None:
            pts = view(pts)
        fill, edge = zone_colours(z.friction, z.rolling_resistance, (255, 255, 255))
        ax.add_patch(
            Polygon(
                pts,
                closed=True,
                fc=tuple(c / 255 for c in fill),
                ec=tuple(c / 255 for c in edge),
                lw=0.8,
                zorder=0.5,
                label=z.label,
            )
        )
