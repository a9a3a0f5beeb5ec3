"""Trajectories: the arena, every true path, GPS track and dead-reckoning (odometry) track,
and where collisions happened.

Colours match the window and the video (``amsa_phys/palette.py``: the leader orange, the
follower blue). The static world — walls, obstacles — is drawn by one function,
:func:`draw_static_world`, from the world's ``physics:`` settings, so another kind of
static layer is a few more lines there. Terrain (friction zones) comes from the run's own
``scenario.yaml`` (``plots/zones.py``) and goes through the same view.

A long, nearly straight run (scenario 1: a 124 m straight line) drawn to scale is a
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
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.patches import Polygon

from ..model.geometry import static_obstacles
from ..palette import (
    COLLISION,
    LOST_FIX,
    ROVER_COLOURS,
    hex_colour,
    rover_colour,
    rover_names,
    rover_ranks,
)
from ..tracemarks import lossy_in_run, lost_fix_rows
from .distance import cut_note, read_trace
from .save import save_png
from .zones import draw_zones

#: a run is drawn in the lateral-offset view when its paths stay this close to one line
STRAIGHT_RATIO = 0.05
STRAIGHT_MIN_LENGTH_M = 20.0
MIN_OFFSET_HALF_RANGE_M = 2.0  # the offset axis shows at least +-2 m (a rover is 0.6 m wide)
OBSTACLE_FILL = "#78746c"
GOAL_COLOUR = "#ffd700"
#: more rovers than this: one colour and one legend entry per role (``role_of``)
GROUP_ABOVE = 12
#: in a grouped plot: points drawn per path, and GPS crosses drawn in all
MAX_PATH_POINTS = 2000
MAX_FIXES = 30_000
MAX_GPS_TRACKS = 40
#: past the palette's end the colours come again with these dashes
LINE_STYLES = ("-", "--", "-.", ":")


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
    pts = pts[np.isfinite(pts).all(axis=1)]  # a damaged trace's gaps (NaN) carry no route
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


def draw_static_world(ax: Axes, physics: dict[str, Any] | None, view: View) -> bool:
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


def plotted_columns(
    header: list[str], links: Sequence[Mapping[str, Any]] | None = None
) -> frozenset[str]:
    """The trace columns the trajectory plot reads: positions, odometry and the GPS fixes
    it draws (a wide run's sample of its GPS: most of a 200-rover trace's columns are GPS
    fixes, and parsing them was most of the plots' cost). ``links``: the world's fixes
    (``plot_context``'s ``gps``)."""
    ends = (".posX", ".posY", ".odomX", ".odomY")
    keep = {c for c in header if c.endswith(ends)}
    for _, x, y in shown_gps(header, len(rover_names(header)) > GROUP_ABOVE, links):
        keep |= {x, y}
    return frozenset(keep)


def shown_gps(
    header: list[str], grouped: bool, links: Sequence[Mapping[str, Any]] | None = None
) -> list[tuple[str, str, str]]:
    """The fixes drawn, as ``(component, x column, y column)``: all, or in a wide run an
    evenly spaced sample of at most :data:`MAX_GPS_TRACKS` (crosses along every path are a
    smear). ``links``: the fixes the world's templates declare (``plot_context``'s ``gps``);
    without the world (its ``scenario.yaml`` missing) the built-in GPS's columns."""
    if links is None:
        found = [c[: -len(".gpsPosX")] for c in header if c.endswith(".gpsPosX")]
        tracks = [(c, f"{c}.gpsPosX", f"{c}.gpsPosY") for c in found]
    else:
        tracks = [(str(k["path"]), str(k["x"]), str(k["y"])) for k in links]
    columns = set(header)
    tracks = [t for t in tracks if t[1] in columns and t[2] in columns]
    if grouped and len(tracks) > MAX_GPS_TRACKS:
        tracks = tracks[:: -(-len(tracks) // MAX_GPS_TRACKS)]
    return tracks


def plot_trajectory(
    trace: Path,
    metrics: dict[str, Any],
    out: Path,
    world: dict[str, Any] | None = None,
    keep: frozenset[str] | None = None,
) -> Path:
    """Draw the paths in ``trace`` into ``out`` (start and end marked, collisions crossed).

    ``world`` (:func:`amsa_phys.runs.plotjob.plot_context`) brings the static world, which
    rover each GPS measures, the goals and (if it has them) the terrain zones; without it
    the paths are drawn alone, with the zones of the run's ``scenario.yaml``. ``keep``: the
    columns to read (:func:`plotted_columns` and more; all if None).
    """
    world = world or {}
    header, data = read_trace(trace, keep)
    rovers = rover_names(header) if len(data) else []  # a run that faulted at t = 0 has none
    paths = {r: data[:, [header.index(f"{r}.posX"), header.index(f"{r}.posY")]] for r in rovers}
    physics = world.get("physics")
    arena = bool(static_obstacles(physics or {}))  # obstacles or walls: show them to scale
    view = View() if arena else choose_view(list(paths.values()))
    fig = Figure(figsize=(10, 4.8) if view.lateral else (7, 6), dpi=100)  # no pyplot
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    draw_static_world(ax, physics, view)
    zones = world.get("zones") or []  # from the run's timeline (runs/plotjob.plot_context)
    draw_zones(ax, zones, view)  # terrain, from the run (its timeline changes the labels)
    grouped = len(rovers) > GROUP_ABOVE
    ranks = rover_ranks(world.get("rovers") or rovers, rovers)  # the world's order, not the trace's
    style = role_styles(rovers) if grouped else rover_styles(rovers, ranks)
    if grouped:
        _draw_roles(ax, paths, view, style)
    else:
        _draw_rovers(ax, paths, view, style)
    # a GPS of a rover the trace left out is still drawn in that rover's colour
    untraced = {r: _style(i, r) for i, r in enumerate(world.get("rovers") or [])}
    gps_style = style if grouped else {**untraced, **style}
    links = world.get("gps")
    _draw_gps(ax, header, data, view, gps_style, world.get("gps_of", {}), grouped, links)
    _draw_odometry(ax, header, data, view)
    _draw_goals(ax, world.get("goals", []), view)
    _draw_lost_fixes(ax, header, data, view, paths, links or [], metrics)
    hits = _collision_points(metrics, data, header, paths)
    if hits.size:
        p = view(hits)
        look = {"color": hex_colour(COLLISION.colour), "mec": "k", "mew": 0.8, "ls": ""}
        ax.plot(p[:, 0], p[:, 1], COLLISION.marker, ms=7, zorder=6, **look)
        ax.plot([], [], COLLISION.marker, ms=6, label=f"collision ({len(hits)})", **look)
    title = f"{metrics.get('scenario', '')}: trajectories (o start, ■ end){cut_note(metrics)}"
    if not rovers:
        why = (
            "no positions in the trace"
            if rover_names(header)  # a run that faulted at t = 0: no rows
            else "no positions in the trace (no X.posX, X.posY columns: see trace_columns)"
        )
        ax.text(0.5, 0.5, why, ha="center", transform=ax.transAxes)
    elif view.lateral:
        _lateral_axes(ax, np.concatenate([view(xy) for xy in paths.values()]))
        title += " — a straight run: offset across it stretched"
    else:
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    entries = len(ax.get_legend_handles_labels()[0])
    right = 0.98
    # a platoon: the legend beside the plot, not over its paths (and "best" would test
    # every one of a wide run's points against every place the legend could go)
    if entries > 6 or grouped:
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
        right = 0.8
    elif entries:
        ax.legend(fontsize=8, loc="best")
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=10)
    return save_png(fig, out, margins=(0.09, 0.1, right, 0.92))


@dataclass(frozen=True)
class Style:
    """How one rover (or, in a wide run, one role) is drawn, and its legend name."""

    colour: str
    linestyle: str
    name: str


def role_of(rover: str) -> str:
    """A rover's role: its path with the instance numbers of ``count:`` Composites starred
    (``Car17.Robot`` -> ``Car*.Robot``); ``Leader`` stays ``Leader``."""
    return re.sub(r"\d+(?=\.|$)", "*", rover)


def _style(index: int, name: str) -> Style:
    """The index-th colour of the window's palette; past its end the same colours again,
    dashed, then dash-dotted, then dotted, so no two of 36 rovers (or roles) look alike."""
    dash = LINE_STYLES[(index // len(ROVER_COLOURS)) % len(LINE_STYLES)]
    return Style(hex_colour(rover_colour(index)), dash, name)


def rover_styles(rovers: list[str], ranks: dict[str, int] | None = None) -> dict[str, Style]:
    """One style per rover: the window's colour of its rank among the world's rovers
    (``ranks``, :func:`~amsa_phys.palette.rover_ranks`; default: its place in ``rovers``)."""
    ranks = ranks or {r: i for i, r in enumerate(rovers)}
    return {r: _style(ranks[r], r) for r in rovers}


def role_styles(rovers: list[str]) -> dict[str, Style]:
    """Every rover styled by its role: one colour and one legend entry per role (a 200-car
    platoon is a leader and a column of cars, not 200 colours nobody can tell apart)."""
    roles: dict[str, list[str]] = {}
    for r in rovers:
        roles.setdefault(role_of(r), []).append(r)
    out = {}
    for k, (role, members) in enumerate(roles.items()):
        name = role if len(members) == 1 else f"{role} ×{len(members)}"
        for r in members:
            out[r] = _style(k, name)
    return out


def _draw_rovers(
    ax: Axes, paths: dict[str, np.ndarray], view: View, style: dict[str, Style]
) -> None:
    """Each rover's path, start and end as lines of its own (a few rovers: every point)."""
    first = next(iter(paths), None)
    for r, xy in paths.items():  # leader under follower: where the paths coincide both show
        p = view(xy)
        st = style[r]
        width = 3.2 if r == first and len(paths) > 1 else 1.6
        ax.plot(
            p[:, 0],
            p[:, 1],
            lw=width,
            color=st.colour,
            ls=st.linestyle,
            label=f"{r} (true)",
            zorder=3,
        )
        ax.plot(*p[0], "o", color=st.colour, ms=6, mec="k", mew=0.5, zorder=5)
        ax.plot(*p[-1], "s", color=st.colour, ms=6, mec="k", mew=0.5, zorder=5)


def _draw_roles(
    ax: Axes, paths: dict[str, np.ndarray], view: View, style: dict[str, Style]
) -> None:
    """A wide run: one LineCollection per role, its paths thinned to what a figure shows.

    Drawing cost is bounded by :data:`MAX_PATH_POINTS` per path, whatever the run's length,
    and the artists by the number of roles, whatever the number of rovers.
    """
    by_role: dict[Style, list[np.ndarray]] = {}
    for r, xy in paths.items():
        by_role.setdefault(style[r], []).append(view(_thin(xy, MAX_PATH_POINTS)))
    for k, (st, lines) in enumerate(by_role.items()):
        ax.add_collection(
            LineCollection(
                lines,
                colors=st.colour,
                linestyles=st.linestyle,
                linewidths=2.4 if k == 0 and len(lines) == 1 else 1.0,
                label=f"{st.name} (true)",
                zorder=3,
            )
        )
        for at, marker in ((0, "o"), (-1, "s")):
            ends = np.array([p[at] for p in lines])
            ax.plot(
                ends[:, 0],
                ends[:, 1],
                marker,
                ls="",
                color=st.colour,
                ms=4,
                mec="k",
                mew=0.4,
                zorder=5,
            )
    ax.autoscale_view()


def _thin(xy: np.ndarray, most: int) -> np.ndarray:
    """At most about ``most`` evenly spaced rows of ``xy``, always with its last."""
    if len(xy) <= most:
        return xy
    step = -(-len(xy) // most)
    return np.concatenate([xy[::step], xy[-1:]])


def _draw_gps(
    ax: Axes,
    header: list[str],
    data: np.ndarray,
    view: View,
    style: dict[str, Style],
    gps_of: dict[str, str],
    grouped: bool,
    links: Sequence[Mapping[str, Any]] | None,
) -> None:
    """GPS fixes as crosses in the measured rover's colour; in a wide run a sample of the
    GPS (:func:`shown_gps`), one artist per colour, at most :data:`MAX_FIXES` crosses."""
    shown = shown_gps(header, grouped, links)
    tracks = [c for c, _, _ in shown]
    cols = {c: (header.index(x), header.index(y)) for c, x, y in shown}

    def colour(comp: str) -> str:
        rover = gps_of.get(comp, "")
        return style[rover].colour if rover in style else "0.5"

    if grouped:
        per_track = max(2, MAX_FIXES // max(1, len(tracks)))
        by_colour: dict[str, list[np.ndarray]] = {}
        for comp in tracks:
            xy = _thin(data[:, list(cols[comp])], per_track)
            by_colour.setdefault(colour(comp), []).append(view(xy))
        for col, pts in by_colour.items():
            xy = np.concatenate(pts)
            ax.plot(xy[:, 0], xy[:, 1], "+", ls="", ms=3, mew=0.6, alpha=0.45, color=col, zorder=2)
    else:
        for comp in tracks:
            xy = view(data[:, list(cols[comp])])
            col = colour(comp)
            ax.plot(xy[:, 0], xy[:, 1], "+", ms=3, mew=0.6, alpha=0.45, color=col, zorder=2)
            if len(tracks) <= 3:
                ax.plot([], [], "+", color=col, label=f"{comp} (measured)")
    if grouped and tracks:
        ax.plot([], [], "+", color="0.4", label="GPS fixes (a sample)")
    elif len(tracks) > 3:
        ax.plot([], [], "+", color="0.4", label="GPS fixes (the rover's colour)")


def _draw_lost_fixes(
    ax: Axes,
    header: list[str],
    data: np.ndarray,
    view: View,
    paths: dict[str, np.ndarray],
    links: list[dict[str, Any]],
    metrics: dict[str, Any],
) -> None:
    """``palette.LOST_FIX`` (a red ×) where each GPS sample was lost, at the measured rover's
    true position then (``tracemarks``: the same losses the window and the video mark)."""
    lossy = lossy_in_run(metrics)
    points = []
    for link in links:
        path, rover = link["path"], link.get("rover")
        cols = (link["x"], link["y"])
        made = any((path, p) in lossy for p in link.get("loss_params") or ())
        if not (link["lossy"] or made) or rover not in paths or not set(cols) <= set(header):
            continue
        fx, fy = data[:, header.index(cols[0])], data[:, header.index(cols[1])]
        rows = lost_fix_rows(data[:, 0], fx, fy, float(link["period_s"]))
        points.append(paths[rover][rows])
    if not points or not sum(len(p) for p in points):
        return
    xy = view(np.concatenate(points))
    colour = hex_colour(LOST_FIX.colour)
    ax.plot(xy[:, 0], xy[:, 1], LOST_FIX.marker, ls="", color=colour, ms=6, mew=1.5, zorder=6)
    ax.plot(
        [], [], LOST_FIX.marker, ls="", color=colour, mew=1.5, label=f"lost GPS fix ({len(xy)})"
    )


def _draw_odometry(ax: Axes, header: list[str], data: np.ndarray, view: View) -> None:
    """Dead-reckoning tracks, dashed grey; more than three share one legend entry."""
    odometry = [c[: -len(".odomX")] for c in header if c.endswith(".odomX")]
    odometry = [c for c in odometry if f"{c}.odomY" in header]
    for comp in odometry:
        xy = data[:, [header.index(f"{comp}.odomX"), header.index(f"{comp}.odomY")]]
        if len(odometry) > 3:
            xy = _thin(xy, MAX_PATH_POINTS)
        xy = view(xy)
        label = f"{comp} (dead reckoning)" if len(odometry) <= 3 else None
        ax.plot(xy[:, 0], xy[:, 1], "--", lw=1.2, color="0.3", zorder=2, label=label)
    if len(odometry) > 3:
        ax.plot([], [], "--", lw=1.2, color="0.3", label="dead reckoning")


def _draw_goals(ax: Axes, goals: list[dict[str, float]], view: View) -> None:
    """Each goal a rover steers to (``plot_context``): a star, and its radius if it has one."""
    for i, goal in enumerate(goals):
        x, y = float(goal["x"]), float(goal["y"])
        radius = float(goal.get("radius") or 0.0)
        if radius > 0:
            a = np.linspace(0, 2 * math.pi, 49)
            ring = view(np.column_stack((x + radius * np.cos(a), y + radius * np.sin(a))))
            ax.plot(ring[:, 0], ring[:, 1], color=GOAL_COLOUR, lw=1.0, zorder=4)
        p = view(np.array([[x, y]]))[0]
        ax.plot(
            p[0],
            p[1],
            "*",
            color=GOAL_COLOUR,
            ms=14,
            mec="k",
            mew=0.7,
            zorder=6,
            label=f"goal ({x:g}, {y:g})" if i < 3 else None,
        )


def _lateral_axes(ax: Axes, pts: np.ndarray) -> None:
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
