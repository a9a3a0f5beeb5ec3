"""Trajectories: the arena, every true path, GPS track and dead-reckoning (odometry) track,
and where collisions happened.

Colours match the window and the video (``amsa_phys/palette.py``: the leader orange, the
follower blue). The static world — walls, obstacles — is drawn by one function,
:func:`draw_static_world`, from the world's ``physics:`` settings, so another kind of
static layer is a few more lines there. Terrain (friction zones) comes from the run's own
``scenario.yaml`` (``plots/zones.py``) and goes through the same view.

A long, nearly straight run (scenario 1: a 420 m straight line) drawn to scale is a
hairline in a square of empty metres. When every true path stays within 5 % of its length
of one straight line, and the world has no obstacles or walls (an arena is drawn to scale,
it is what the paths are read against), the plot turns into a *lateral-offset view*:
distance along that line against the offset across it, the offset axis stretched (and
labelled so). We chose this
over a to-scale plot with an auto-aspect inset because the inset would get a fraction of
the figure while the to-scale panel shows only a line; the rotated, stretched view gives
the whole figure to what varies, works for a straight run in any direction, and keeps
obstacles and collision marks in the same frame (they are rotated with the paths).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Polygon

from ..model.geometry import static_obstacles
from ..palette import ALERT, hex_colour, rover_colour, rover_names
from .distance import read_trace
from .save import save_png
from .zones import draw_zones, zones_of_run

#: a run is drawn in the lateral-offset view when its paths stay this close to one line
STRAIGHT_RATIO = 0.05
STRAIGHT_MIN_LENGTH_M = 20.0
MIN_OFFSET_HALF_RANGE_M = 2.0  # the offset axis shows at least +-2 m (a rover is 0.6 m wide)
OBSTACLE_FILL = "#78746c"


@dataclass(frozen=True)
class View:
    """World metres -> plot coordinates: identity (to scale) or the lateral-offset frame."""

    origin: tuple[float, float] = (0.0, 0.0)
    along: tuple[float, float] = (1.0, 0.0)  # unit vector of the route
    lateral: bool = False

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        """Points (N x 2) in plot coordinates."""
        if not self.lateral:
            return xy
        d = np.asarray(xy, dtype=float) - self.origin
        ux, uy = self.along
        return np.column_stack((d[:, 0] * ux + d[:, 1] * uy, -d[:, 0] * uy + d[:, 1] * ux))


def choose_view(paths: list[np.ndarray]) -> View:
    """The lateral-offset frame when every path hugs one straight line, else to scale."""
    pts = np.concatenate([p for p in paths if p.size]) if paths else np.empty((0, 2))
    if len(pts) < 3:
        return View()
    origin = pts.mean(axis=0)
    _, _, vt = np.linalg.svd(pts - origin, full_matrices=False)
    u = vt[0]
    first = paths[0]
    if first.size and np.dot(first[-1] - first[0], u) < 0:  # the route runs left to right
        u = -u
    along = (pts - origin) @ u
    across = (pts - origin) @ np.array([-u[1], u[0]])
    length = float(np.ptp(along))
    if length < STRAIGHT_MIN_LENGTH_M or float(np.ptp(across)) > STRAIGHT_RATIO * length:
        return View()
    # the origin moved to the route's start, so "along" reads as distance from the start
    start = origin + u * float(along.min())
    return View((float(start[0]), float(start[1])), (float(u[0]), float(u[1])), lateral=True)


def draw_static_world(ax: plt.Axes, physics: dict[str, Any] | None, view: View) -> bool:
    """Walls and obstacles (whatever the world's ``physics:`` holds), under everything else.

    Each shape is turned into plot coordinates through ``view`` as a polygon or a line, so a
    circle stays right in the stretched lateral view. Returns whether anything was drawn.
    """
    drawn = False
    for ob in static_obstacles(physics or {}):
        if ob.kind == "circle":
            (cx, cy), r = ob.points[0], ob.radius
            a = np.linspace(0, 2 * math.pi, 49)
            ring = view(np.column_stack((cx + r * np.cos(a), cy + r * np.sin(a))))
            ax.add_patch(Polygon(ring, closed=True, fc=OBSTACLE_FILL, ec="none", zorder=1))
        elif ob.kind == "poly":
            pts = view(np.asarray(ob.points))
            ax.add_patch(Polygon(pts, closed=True, fc=OBSTACLE_FILL, ec="none", zorder=1))
        else:  # walls and polylines: thickness in metres is not a line width; drawn at 2.5 pt
            pts = view(np.asarray(ob.points))
            ax.plot(pts[:, 0], pts[:, 1], color=OBSTACLE_FILL, lw=2.5, zorder=1)
        drawn = True
    return drawn


def plot_trajectory(
    trace: Path, metrics: dict[str, Any], out: Path, world: dict[str, Any] | None = None
) -> Path:
    """Draw the paths in ``trace`` into ``out`` (start and end marked, collisions crossed).

    ``world`` (:func:`amsa_phys.runs.plotjob.plot_context`) brings the static world and
    which rover each GPS measures; without it the paths are drawn alone.
    """
    world = world or {}
    header, data = read_trace(trace)
    rovers = rover_names(header) if len(data) else []  # a run that faulted at t = 0 has none
    paths = {r: data[:, [header.index(f"{r}.posX"), header.index(f"{r}.posY")]] for r in rovers}
    physics = world.get("physics")
    arena = bool(static_obstacles(physics or {}))  # obstacles or walls: show them to scale
    view = View() if arena else choose_view(list(paths.values()))
    fig, ax = plt.subplots(figsize=(10, 4.8) if view.lateral else (7, 6), dpi=100)
    draw_static_world(ax, physics, view)
    draw_zones(ax, zones_of_run(trace.parent / "scenario.yaml"), view)  # terrain, from the run
    colour = {r: hex_colour(rover_colour(i)) for i, r in enumerate(rovers)}
    for r, xy in paths.items():  # leader under follower: where the paths coincide both show
        p = view(xy)
        width = 3.2 if r == rovers[0] and len(rovers) > 1 else 1.6
        ax.plot(p[:, 0], p[:, 1], lw=width, color=colour[r], label=f"{r} (true)", zorder=3)
        ax.plot(*p[0], "o", color=colour[r], ms=6, mec="k", mew=0.5, zorder=5)
        ax.plot(*p[-1], "s", color=colour[r], ms=6, mec="k", mew=0.5, zorder=5)
    gps_of = world.get("gps_of", {})
    tracks = [c[: -len(".gpsPosX")] for c in header if c.endswith(".gpsPosX")]
    tracks = [c for c in tracks if f"{c}.gpsPosY" in header]
    for comp in tracks:
        xy = view(data[:, [header.index(f"{comp}.gpsPosX"), header.index(f"{comp}.gpsPosY")]])
        col = colour.get(gps_of.get(comp, ""), "0.5")
        ax.plot(xy[:, 0], xy[:, 1], "+", ms=3, mew=0.6, alpha=0.45, color=col, zorder=2)
        if len(tracks) <= 3:
            ax.plot([], [], "+", color=col, label=f"{comp} (measured)")
    if len(tracks) > 3:
        ax.plot([], [], "+", color="0.4", label="GPS fixes (the rover's colour)")
    odometry = [c[: -len(".odomX")] for c in header if c.endswith(".odomX")]
    for comp in [c for c in odometry if f"{c}.odomY" in header]:
        xy = view(data[:, [header.index(f"{comp}.odomX"), header.index(f"{comp}.odomY")]])
        ax.plot(
            xy[:, 0],
            xy[:, 1],
            "--",
            lw=1.2,
            color="0.3",
            zorder=2,
            label=f"{comp} (dead reckoning)",
        )
    hits = _collision_points(metrics, data, header, paths)
    if hits.size:
        p = view(hits)
        ax.plot(p[:, 0], p[:, 1], "x", color=hex_colour(ALERT), ms=9, mew=2, zorder=6)
        ax.plot([], [], "x", color=hex_colour(ALERT), mew=2, label=f"collision ({len(hits)})")
    title = f"{metrics.get('scenario', '')}: trajectories (o start, ■ end)"
    if not rovers:
        ax.text(0.5, 0.5, "no positions in the trace", ha="center", transform=ax.transAxes)
    elif view.lateral:
        _lateral_axes(ax, np.concatenate([view(xy) for xy in paths.values()]))
        title += " — a straight run: offset across it stretched"
    else:
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    entries = len(ax.get_legend_handles_labels()[0])
    right = 0.98
    if entries > 6:  # a platoon: the legend beside the plot, not over its paths
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
        right = 0.8
    elif entries:
        ax.legend(fontsize=8, loc="best")
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=10)
    return save_png(fig, out, margins=(0.09, 0.1, right, 0.92))


def _lateral_axes(ax: plt.Axes, pts: np.ndarray) -> None:
    """Limits and labels of the lateral-offset view (data, not the obstacles, set them)."""
    along, across = pts[:, 0], pts[:, 1]
    pad = 0.03 * float(np.ptp(along))
    ax.set_xlim(float(along.min()) - pad, float(along.max()) + pad)
    mid = (float(across.max()) + float(across.min())) / 2
    half = max(MIN_OFFSET_HALF_RANGE_M, 0.6 * float(np.ptp(across)))
    ax.set_ylim(mid - half, mid + half)
    ax.set_xlabel("distance along the route (m)")
    ax.set_ylabel("lateral offset (m, stretched)")


def _collision_points(
    metrics: dict[str, Any], data: np.ndarray, header: list[str], paths: dict[str, np.ndarray]
) -> np.ndarray:
    """Where each collision event happened: the rovers' positions at its time (interpolated
    from the trace; the midpoint of two rovers that touched)."""
    t = data[:, 0] if data.size else np.empty(0)
    out = []
    for event in metrics.get("events", []):
        if event.get("kind") != "collision" or not t.size:
            continue
        involved = [n for n in str(event.get("detail", "")).split("-") if n in paths]
        if not involved:
            continue
        at = float(event["t"])
        xy = [
            (np.interp(at, t, paths[n][:, 0]), np.interp(at, t, paths[n][:, 1])) for n in involved
        ]
        out.append(np.mean(xy, axis=0))
    return np.asarray(out).reshape(-1, 2)
