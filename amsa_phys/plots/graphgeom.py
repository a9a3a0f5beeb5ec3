"""Plane geometry of the architecture diagram: curves, corners, box hits, label overlaps.

Split from ``plots/graph.py``: pure functions on points and boxes (matplotlib's ``Bbox``
and ``Path`` as data only), which the layout calls to route links and place their labels.
"""

from __future__ import annotations

import itertools

import numpy as np
from matplotlib.transforms import Bbox

Point = tuple[float, float]

BOX_W, BOX_H = 3.0, 0.9  # a component, in data units (0.9 inch each)


def quadratic_curve(p0: Point, c: Point, p2: Point, n: int = 40) -> list[Point]:
    """The quadratic Bezier from ``p0`` to ``p2`` with control ``c`` as ``n + 1`` points."""
    pts = []
    for k in range(n + 1):
        t = k / n
        u = 1 - t
        pts.append(
            (
                u * u * p0[0] + 2 * u * t * c[0] + t * t * p2[0],
                u * u * p0[1] + 2 * u * t * c[1] + t * t * p2[1],
            )
        )
    return pts


def rounded_path(corners: list[Point], r: float) -> list[Point]:
    """A polyline through ``corners`` with each inner corner rounded (radius about ``r``)."""
    out = [corners[0]]
    for prev, here, nxt in zip(corners, corners[1:], corners[2:], strict=False):
        d_in = max(abs(here[0] - prev[0]), abs(here[1] - prev[1]))
        d_out = max(abs(nxt[0] - here[0]), abs(nxt[1] - here[1]))
        k = min(r, d_in / 2, d_out / 2)
        a = _toward(here, prev, k)
        b = _toward(here, nxt, k)
        out += quadratic_curve(a, here, b, 8)
    out.append(corners[-1])
    return out


def _toward(p: Point, q: Point, k: float) -> Point:
    """The point ``k`` from ``p`` toward ``q`` (axis-aligned segments)."""
    dx, dy = q[0] - p[0], q[1] - p[1]
    length = max(abs(dx), abs(dy)) or 1.0
    return (p[0] + dx * k / length, p[1] + dy * k / length)


def hits_box(line: list[Point], centre: Point) -> bool:
    """Whether the polyline passes through, or within 0.3 of, the box centred at ``centre``.

    The margin keeps an arc from threading the gap between two rows of boxes.
    """
    x, y = centre
    w, h = BOX_W / 2 + 0.3, BOX_H / 2 + 0.3
    box = Bbox.from_extents(x - w, y - h, x + w, y + h)
    return line_crosses(np.asarray(line), box)


def line_crosses(line: np.ndarray, box: Bbox) -> bool:
    """Whether any segment of the polyline ``line`` (N x 2) meets the rectangle ``box``."""
    a, b = line[:-1], line[1:]
    near = (  # segments whose own bounding box meets the rectangle: the only candidates
        (np.minimum(a[:, 0], b[:, 0]) <= box.x1)
        & (np.maximum(a[:, 0], b[:, 0]) >= box.x0)
        & (np.minimum(a[:, 1], b[:, 1]) <= box.y1)
        & (np.maximum(a[:, 1], b[:, 1]) >= box.y0)
    )
    return any(_segment_meets(*a[k], *b[k], box) for k in np.flatnonzero(near).tolist())


def _segment_meets(x0: float, y0: float, x1: float, y1: float, box: Bbox) -> bool:
    """Liang-Barsky: does the segment (x0, y0)-(x1, y1) meet ``box``?"""
    lo, hi = 0.0, 1.0
    dx, dy = x1 - x0, y1 - y0
    for p, q in (
        (-dx, x0 - box.x0),
        (dx, box.x1 - x0),
        (-dy, y0 - box.y0),
        (dy, box.y1 - y0),
    ):
        if p == 0:
            if q < 0:
                return False
            continue
        t = q / p
        if p < 0:
            lo = max(lo, t)
        else:
            hi = min(hi, t)
        if lo > hi:
            return False
    return True


def point_along(line: list[Point], t: float) -> Point:
    """The point a fraction ``t`` of the way along the polyline, by length."""
    arr = np.asarray(line)
    seg = np.hypot(*np.diff(arr, axis=0).T)
    goal = t * seg.sum()
    k = int(np.searchsorted(np.cumsum(seg), goal))
    k = min(k, len(seg) - 1)
    before = seg[:k].sum()
    f = (goal - before) / seg[k] if seg[k] > 0 else 0.0
    x, y = arr[k] + f * (arr[k + 1] - arr[k])
    return (float(x), float(y))


class Segments:
    """Every link's line as one array of segments (display pixels), so a label's place is
    tested against all of them at once: a per-line Python loop made the expanded 10-car
    platoon (71 components, 110 links) take 33 s."""

    def __init__(self, lines: list[np.ndarray]) -> None:
        a = [np.asarray(line, dtype=float)[:-1] for line in lines]
        b = [np.asarray(line, dtype=float)[1:] for line in lines]
        self.a = np.concatenate(a) if a else np.empty((0, 2))
        self.b = np.concatenate(b) if b else np.empty((0, 2))
        self.owner = np.concatenate([np.full(len(x), k) for k, x in enumerate(a)]) if a else []
        self.lo = np.minimum(self.a, self.b)
        self.hi = np.maximum(self.a, self.b)

    def crossing(self, box: Bbox, but: int) -> int:
        """How many lines other than line ``but`` meet ``box``."""
        near = (
            (self.lo[:, 0] <= box.x1)
            & (self.hi[:, 0] >= box.x0)
            & (self.lo[:, 1] <= box.y1)
            & (self.hi[:, 1] >= box.y0)
            & (self.owner != but)
        )
        hit = set()
        for k in np.flatnonzero(near).tolist():
            owner = int(self.owner[k])
            if owner not in hit and _segment_meets(*self.a[k], *self.b[k], box):
                hit.add(owner)
        return len(hit)


def overlapping(extent: Bbox, others: np.ndarray) -> int:
    """How many of ``others`` (N x 4: x0, y0, x1, y1) ``extent`` overlaps (as
    ``Bbox.overlaps``: touching edges do not count)."""
    if not len(others):
        return 0
    return int(
        np.count_nonzero(
            (extent.x0 < others[:, 2])
            & (others[:, 0] < extent.x1)
            & (extent.y0 < others[:, 3])
            & (others[:, 1] < extent.y1)
        )
    )


def passes_through(line: list[Point], centre: Point, margin: float = 0.05) -> bool:
    """Whether the polyline crosses the box centred at ``centre`` (grown by ``margin``)."""
    x, y = centre
    w, h = BOX_W / 2 + margin, BOX_H / 2 + margin
    return line_crosses(np.asarray(line), Bbox.from_extents(x - w, y - h, x + w, y + h))


def detour(
    p0: Point, p1: Point, others: list[Point], gap: float, corner: float
) -> list[Point] | None:
    """A forward link from ``p0`` (its source's right side) to ``p1`` (its target's left
    side) that a straight line would draw through another box: out into the gap beside the
    source, along a free horizontal lane (between two rows of boxes, or above or below them
    all), into the gap beside the target, and in. Read as a straight line, a link through a
    third box looks like that box's link. The lane nearest the straight line first; None
    when every lane is blocked (``others``: the centres of the boxes to keep clear of)."""
    if not others:
        return None
    ys = sorted({y for _, y in others} | {p0[1], p1[1]})
    lanes = [(a + b) / 2 for a, b in itertools.pairwise(ys) if b - a > BOX_H + 0.2]
    lanes += [ys[-1] + BOX_H, ys[0] - BOX_H]
    middle = (p0[1] + p1[1]) / 2
    for lane in sorted(lanes, key=lambda y: abs(y - middle)):
        corners = [
            p0,
            (p0[0] + gap, p0[1]),
            (p0[0] + gap, lane),
            (p1[0] - gap, lane),
            (p1[0] - gap, p1[1]),
            p1,
        ]
        if not any(passes_through(corners, c) for c in others):
            return rounded_path(corners, corner)
    return None
