"""Terrain: friction zones (polygons with their own friction and rolling resistance).

A zone is an *environment* component (template ``frictionZone``, in ``zones.py``), so everything the
framework does with parameters works on terrain too: ``describe`` lists a zone's friction
with its range, ``templates`` documents it, a sweep varies it, the window's panel edits it,
and "mud from t = 60" is an ordinary timeline change ``Mud.friction: 0.3``. The zone
registers itself with the run's physics world at ``initialize`` and tells it about every
change; the physics reads the ground under each wheel's contact point every step.

Where zones overlap, the one declared last wins (it is drawn on top). Outside every zone the
world's ``physics.ground`` applies. A zone acts on wheels only: a rover's tyres, rolling
resistance and patch scrub use the zone's values under each wheel separately, so a rover
with one wheel in mud pulls towards it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model.params import Param


@dataclass
class Zone:
    """One friction zone: a simple polygon (world metres) and its ground values."""

    name: str
    polygon: tuple[tuple[float, float], ...]
    friction: float
    rolling_resistance: float

    def __post_init__(self) -> None:
        xs = [p[0] for p in self.polygon]
        ys = [p[1] for p in self.polygon]
        self.bbox = (min(xs), min(ys), max(xs), max(ys))
        self._xs = np.array(xs)
        self._ys = np.array(ys)

    def contains(self, x: float, y: float) -> bool:
        """Whether ``(x, y)`` is inside (even-odd rule; a point on an edge may go either way)."""
        x0, y0, x1, y1 = self.bbox
        if not (x0 <= x <= x1 and y0 <= y <= y1):
            return False
        inside = False
        pts = self.polygon
        xj, yj = pts[-1]
        for xi, yi in pts:
            if (yi > y) != (yj > y) and x < (xj - xi) * (y - yi) / (yj - yi) + xi:
                inside = not inside
            xj, yj = xi, yi
        return inside

    def contains_many(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """:meth:`contains` for arrays of points (the many-rover path)."""
        x0, y0, x1, y1 = self.bbox
        inside = np.zeros(x.shape, dtype=bool)
        near = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
        if not near.any():
            return inside
        px, py = x[near], y[near]
        hit = np.zeros(px.shape, dtype=bool)
        xj, yj = self._xs[-1], self._ys[-1]
        for xi, yi in zip(self._xs, self._ys, strict=True):
            if yj != yi:
                crosses = ((yi > py) != (yj > py)) & (px < (xj - xi) * (py - yi) / (yj - yi) + xi)
                hit ^= crosses
            xj, yj = xi, yi
        inside[near] = hit
        return inside


@dataclass
class Grade:
    """One grade zone (a slope): a polygon, its angle (rad) and its uphill direction (rad)."""

    name: str
    polygon: tuple[tuple[float, float], ...]
    angle: float
    direction: float

    def __post_init__(self) -> None:
        self.area = Zone(self.name, self.polygon, 0.0, 0.0)  # the geometry and its tests


class Terrain:
    """The world's ground, its friction zones and its grade zones; ``version`` changes
    whenever any value does."""

    def __init__(self, friction: float, rolling_resistance: float, gravity: float = 0.0) -> None:
        self.friction = friction
        self.rolling_resistance = rolling_resistance
        self.gravity = gravity
        self.zones: list[Zone] = []
        self.grades: list[Grade] = []
        self.version = 0

    def add_grade(self, grade: Grade) -> None:
        """Add a grade zone on top of the others."""
        self.grades.append(grade)
        self.version += 1

    def update_grade(self, name: str, **values: Any) -> None:
        """Change a grade zone's angle, direction or polygon (a timeline change)."""
        for i, g in enumerate(self.grades):
            if g.name == name:
                fields = {"polygon": g.polygon, "angle": g.angle, "direction": g.direction}
                fields.update(values)
                self.grades[i] = Grade(name, **fields)
                self.version += 1
                return
        raise KeyError(name)

    def locate_grade(self, x: float, y: float) -> int:
        """Index of the grade zone at ``(x, y)`` (the last declared containing it), or -1."""
        for k in range(len(self.grades) - 1, -1, -1):
            if self.grades[k].area.contains(x, y):
                return k
        return -1

    def locate_grades(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """:meth:`locate_grade` for arrays of points."""
        out = np.full(x.shape, -1, dtype=np.intp)
        for k, grade in enumerate(self.grades):
            out[grade.area.contains_many(x, y)] = k
        return out

    def slope(self, index: int) -> tuple[float, float, float]:
        """``(cos(angle), g_x, g_y)`` of grade zone ``index`` (-1: flat): the share of the
        weight the ground carries and gravity's pull along the slope (m/s², world frame,
        downhill)."""
        if index < 0:
            return 1.0, 0.0, 0.0
        g = self.grades[index]
        pull = -self.gravity * math.sin(g.angle)
        return math.cos(g.angle), pull * math.cos(g.direction), pull * math.sin(g.direction)

    def add(self, zone: Zone) -> None:
        """Add a zone on top of the others."""
        self.zones.append(zone)
        self.version += 1

    def update(self, name: str, **values: Any) -> None:
        """Change a zone's friction, rolling resistance or polygon (a timeline change)."""
        for i, z in enumerate(self.zones):
            if z.name == name:
                fields = {
                    "friction": z.friction,
                    "rolling_resistance": z.rolling_resistance,
                    "polygon": z.polygon,
                }
                fields.update(values)
                self.zones[i] = Zone(name, **fields)
                self.version += 1
                return
        raise KeyError(name)

    def locate(self, x: float, y: float) -> int:
        """Index of the zone at ``(x, y)`` (the last declared that contains it), or -1."""
        zones = self.zones
        for k in range(len(zones) - 1, -1, -1):
            if zones[k].contains(x, y):
                return k
        return -1

    def locate_many(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """:meth:`locate` for arrays of points."""
        out = np.full(x.shape, -1, dtype=np.intp)
        for k, zone in enumerate(self.zones):  # later zones overwrite earlier ones
            out[zone.contains_many(x, y)] = k
        return out

    def ground(self, index: int) -> tuple[float, float]:
        """``(friction, rolling resistance)`` of zone ``index`` (-1: the world's ground)."""
        if index < 0:
            return self.friction, self.rolling_resistance
        z = self.zones[index]
        return z.friction, z.rolling_resistance


#: Zone colours (RGB): soft ground and slippery ground.
MUD = (150, 110, 60)
ICE = (120, 175, 225)


def zone_colours(
    friction: float, rolling_resistance: float, background: tuple[int, int, int]
) -> tuple[tuple[int, int, int], tuple[int, int, int]]:
    """Fill and edge colour of a zone, one definition for the window, video and plots: blue
    if slippery (friction < 0.2), else brown, the fill (blended into ``background``) darker
    the more the ground resists rolling (Crr 0 .. 0.3)."""
    base = ICE if friction < 0.2 else MUD
    strength = 0.25 if friction < 0.2 else 0.2 + 0.4 * min(1.0, rolling_resistance / 0.3)
    fill = tuple(int(b + (c - b) * strength) for b, c in zip(background, base, strict=True))
    return fill, base  # type: ignore[return-value]


def polygon_area(points: Sequence[Sequence[float]]) -> float:
    """Signed area (shoelace): positive when counter-clockwise."""
    total = 0.0
    for (x0, y0), (x1, y1) in zip(points, [*points[1:], points[0]], strict=True):
        total += x0 * y1 - x1 * y0
    return total / 2


#: The corners of a zone on the ground, declared the same by every zone template (friction,
#: grade, GPS-denied): one parameter, so the three read, check and document it alike.
POLYGON = Param(
    "polygon",
    "points",
    "the zone's corners [[x, y], ...] in order (at least 3, not crossing)",
    (),
    unit="m",
)


def check_polygon(values: Any) -> None:
    """A zone needs a polygon with an area (``ValueError`` naming what is wrong)."""
    pts = values.get("polygon", ())
    if len(pts) < 3:
        raise ValueError(f"polygon needs at least 3 corners, got {len(pts)}")
    if abs(polygon_area(pts)) < 1e-9:
        raise ValueError("polygon has no area (its corners are on one line)")
