"""The static world as shapes: obstacles and walls from a world's ``physics:`` settings.

The window, the video and the trajectory plot all draw the arena from here, so they agree
with each other and with what pymunk was given (``physics/space.py`` reads the same dict).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Obstacle:
    """Static geometry in world metres: ``poly`` (closed), ``circle`` or ``line`` (open).

    A ``line``'s ``radius`` is half its thickness; a ``circle``'s is its radius.
    """

    kind: str
    points: tuple[tuple[float, float], ...]
    radius: float = 0.0


def static_obstacles(physics: dict[str, Any]) -> list[Obstacle]:
    """Obstacles and walls from the world's ``physics:`` settings (the same data pymunk got)."""
    out: list[Obstacle] = []
    for ob in physics.get("obstacles") or []:
        if ob["type"] == "box":
            w, h = ob["width"] / 2, ob["height"] / 2
            a = float(ob.get("angle", 0.0))
            c, s = math.cos(a), math.sin(a)
            pts = tuple(
                (ob["x"] + c * dx - s * dy, ob["y"] + s * dx + c * dy)
                for dx, dy in ((-w, -h), (w, -h), (w, h), (-w, h))
            )
            out.append(Obstacle("poly", pts))
        elif ob["type"] == "circle":
            out.append(Obstacle("circle", ((ob["x"], ob["y"]),), ob["radius"]))
        else:
            pts = tuple((float(p[0]), float(p[1])) for p in ob["points"])
            out.append(Obstacle("line", pts, float(ob.get("thickness", 0.1)) / 2))
    walls = physics.get("walls")
    if walls:
        x0, x1, y0, y1 = walls["xmin"], walls["xmax"], walls["ymin"], walls["ymax"]
        out.append(Obstacle("line", ((x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)), 0.1))
    return out
