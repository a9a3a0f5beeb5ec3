"""Terrain: friction zones (polygons with their own friction and rolling resistance).

A zone is an *environment* component (template ``frictionZone``), so everything the
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

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from ..model.params import Param
from ..model.template import Kind, Template


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


class Terrain:
    """The world's ground and its zones; ``version`` changes whenever any value does."""

    def __init__(self, friction: float, rolling_resistance: float) -> None:
        self.friction = friction
        self.rolling_resistance = rolling_resistance
        self.zones: list[Zone] = []
        self.version = 0

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


class FrictionZone(Template):
    """A patch of ground with its own friction and rolling resistance (mud, ice, sand, grass).

    The wheels of any rover over ``polygon`` use this friction (tyre grip, scrub) and
    rolling resistance instead of the world's ``physics.ground``. Change ``friction`` in a
    scenario's timeline to make the ground change mid-run ("mud from t = 60":
    ``{at: 60, set: {Mud.friction: 0.3}}``). Overlapping zones: the last declared wins.
    """

    template_name = "frictionZone"
    kind = Kind.ENVIRONMENT
    params = (
        Param(
            "friction",
            "float",
            "tyre-ground friction coefficient mu in the zone (dry asphalt 0.8, wet grass "
            "0.35, mud 0.3, snow 0.2, ice 0.05)",
            0.3,
            0.0,
            5.0,
        ),
        Param(
            "rollingResistance",
            "float",
            "rolling-resistance coefficient Crr in the zone (concrete 0.015, grass 0.05, "
            "sand 0.15, mud 0.1-0.3)",
            0.1,
            0.0,
            1.0,
        ),
        Param(
            "polygon",
            "points",
            "the zone's corners [[x, y], ...] in order (at least 3, not crossing)",
            (),
            unit="m",
        ),
    )

    @classmethod
    def check_params(cls, values: Mapping[str, Any]) -> None:
        """A zone needs a polygon with an area."""
        pts = values.get("polygon", ())
        if len(pts) < 3:
            raise ValueError(f"polygon needs at least 3 corners, got {len(pts)}")
        if abs(polygon_area(pts)) < 1e-9:
            raise ValueError("polygon has no area (its corners are on one line)")

    def initialize(self, ctx: Any) -> None:
        """Register the zone with the run's physics world."""
        from .space import physics_of  # the world module imports this one

        self.check_params(self.p.as_dict())
        self.terrain = physics_of(ctx).terrain
        self.terrain.add(
            Zone(self.path, tuple(self.p.polygon), self.p.friction, self.p.rollingResistance)
        )

    def on_param_change(self, name: str, value: Any) -> None:
        """Tell the physics: the next step's wheels see the new ground."""
        self.check_params(self.p.as_dict())
        key = {"friction": "friction", "rollingResistance": "rolling_resistance"}.get(
            name, "polygon"
        )
        self.terrain.update(self.path, **{key: tuple(value) if key == "polygon" else value})

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: nothing to publish (the ground acts through the physics)."""
        return {}
