"""How fast a rover may move in one Chipmunk step without tunnelling through a shape.

Chipmunk's collisions are discrete: it tests overlaps at a step's end positions. The
physics world cuts a step faster than :func:`resolvable_speed` into sub-steps
(``bodyio.substeps``); a batch's columns take no sub-steps and make such a run alone
(``columns.py``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import pymunk

if TYPE_CHECKING:
    from .rover import DiffDriveRover


def resolvable_speed(rovers: Sequence[DiffDriveRover], space: pymunk.Space, dt: float) -> float:
    """The speed (m/s) up to which one Chipmunk step of ``dt`` cannot let a rover tunnel.

    Chipmunk tests overlaps at the step's end positions: a rover that moves further in one
    step than half the thinnest pair of shapes it can meet (itself and a wall, or two rovers
    closing at twice the speed) may stop past the middle and be pushed out the far side.
    So a step resolves a speed ``v`` when ``v dt`` is at most half of ``t_r + t_s`` (the
    thinnest rover and the thinnest static shape) and a quarter of ``2 t_r`` (two rovers
    head-on); faster, the step is cut into sub-steps (``bodyio.substeps``).
    """
    if not rovers:
        return math.inf
    rover = min(min(r.length, r.width) for r in rovers)
    statics = [s for s in space.shapes if s.body.body_type == pymunk.Body.STATIC]
    thin = min((_thickness(s) for s in statics), default=math.inf)
    return min(0.5 * rover, 0.5 * (rover + thin)) / dt


def _thickness(shape: pymunk.Shape) -> float:
    """The thinnest width of a static shape (m): a segment's or circle's diameter, a
    polygon's narrowest projection on its edges' normals (plus its rounding)."""
    if isinstance(shape, pymunk.Segment | pymunk.Circle):
        return 2.0 * shape.radius
    if isinstance(shape, pymunk.Poly):
        pts = shape.get_vertices()
        widths = []
        for a, b in zip(pts, [*pts[1:], pts[0]], strict=True):
            n = (b - a).perpendicular_normal()
            proj = [p.dot(n) for p in pts]
            widths.append(max(proj) - min(proj))
        return min(widths) + 2.0 * shape.radius
    return math.inf
