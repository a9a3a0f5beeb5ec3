"""Architecture diagrams (paper Fig. 2/4): components coloured by kind, Data as labelled arrows.

Layout: a component's column is its depth in the dataflow, counting only edges that go forward
in the execution order (a loop's back edge is drawn but does not push columns); rows keep
declaration order. DOT output is for Graphviz users; PNG and SVG are drawn with matplotlib so
no Graphviz install is needed. What the diagram shows (boxes, links, DOT) is
``graphmodel.py``; the plane geometry the layout uses is ``graphgeom.py``.

Labels are placed, not just drawn: each link's label (one line per Data buffer) goes at the
first point along its arrow where its measured extent overlaps no component and no label
placed before it; the gap after a column is as wide as the longest label leaving it. An
earlier version put every label just after its source box, where labels of one source sat on
top of each other and of the next column's names.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch
from matplotlib.path import Path as MplPath
from matplotlib.transforms import Bbox

from ..atomic import write_atomic
from ..errors import one_line
from ..model.wording import plural
from ..model.world import WorldSpec
from .graphgeom import (
    BOX_H,
    BOX_W,
    Point,
    Segments,
    detour,
    hits_box,
    line_crosses,
    overlapping,
    passes_through,
    point_along,
    quadratic_curve,
    rounded_path,
)
from .graphmodel import (
    KIND_COLOURS,
    Node,
    Structure,
    delay_text,
    edges,
    phase_text,
    structure,
    to_dot,
)
from .save import save_png

#: the structure (``graphmodel.py``) is re-exported: callers import it from here
__all__ = [
    "KIND_COLOURS",
    "MAX_BOXES",
    "SLOW_BOXES",
    "Node",
    "Structure",
    "delay_text",
    "diagram",
    "draw",
    "edges",
    "phase_text",
    "structure",
    "to_dot",
]


def _columns(st: Structure) -> dict[str, int]:
    """Dataflow depth, with edges into a process or environment treated as the feedback that
    closes a control loop (drawn, but not pushing columns), and any remaining back edge of a
    depth-first walk ignored."""
    succ: dict[str, list[str]] = {p: [] for p in st.nodes}
    for a, b, _ in st.links:
        if a != b and st.nodes[b].kind not in ("process", "environment"):
            succ[a].append(b)
    col = dict.fromkeys(st.nodes, 0)
    state: dict[str, int] = {}

    def visit(node: str) -> None:
        state[node] = 1
        for nxt in succ[node]:
            if state.get(nxt) == 1:
                continue  # a back edge inside a loop the schedule resolves
            col[nxt] = max(col[nxt], col[node] + 1)
            visit(nxt)
        state[node] = 2

    for _ in range(len(st.nodes)):  # relax until stable (small graphs)
        state.clear()
        before = dict(col)
        for node in st.nodes:
            if node not in state:
                visit(node)
        if col == before:
            break
    return col


ROW_STEP = 1.6
LABEL_PT = 7.5  # 6 pt was too small to read at the README's width
CHAR_W = 0.069  # data units per label character at LABEL_PT, for sizing column gaps
ROVER_EDGE_W = 3.5
ARC_RISE = 1.4  # how far a feedback arc rises above the boxes it joins
LANE_STEP = 0.35  # between two feedback links routed around the boxes
CORNER = 0.3  # radius of a routed link's corners
DETOUR_GAP = 0.6  # how far into a column gap a link routed around a box turns
MARGINS = (0.01, 0.01, 0.99, 0.92)  # fixed: labels are placed against the final transform
#: where along an arrow a label is tried (0 = source end, 1 = target end): middle first
ALONG = tuple(sorted((k / 40 for k in range(4, 37)), key=lambda t: (abs(t - 0.5), t)))
#: a diagram of more boxes is refused (PNG/SVG): its layout takes minutes and its picture
#: outgrows what Agg renders (65536 px a side); DOT has no limit
MAX_BOXES = 300
#: from this many boxes on, ``amsa-phys graph`` says it is working before it starts
SLOW_BOXES = 100
#: how far the columns move apart, layout after layout, while labels find no free place
WIDEN = (0.0, 1.5, 3.0, 4.5)
#: a label on a component or on another label costs this many line crossings
OVERLAP_COST = 100


def draw(world: WorldSpec, out: Path, collapse: bool = True) -> Path:
    """Write the diagram to ``out`` (.png, .svg or .dot); copies once unless not ``collapse``."""
    suffix = out.suffix.lower()
    if suffix == ".dot":
        write_atomic(out, to_dot(world, collapse))
        return out
    fig, _, _ = diagram(world, collapse)
    if suffix == ".png":
        return save_png(fig, out, MARGINS)
    import io

    buf = io.StringIO()
    fig.savefig(buf, format="svg")
    plt.close(fig)
    write_atomic(out, buf.getvalue())
    return out


def diagram(world: WorldSpec, collapse: bool = True) -> tuple[Figure, list[Bbox], list[Bbox]]:
    """The figure, and the display extents of its components and of its link labels.

    Where some label finds no free place (off every component, every other label and every
    other link's line), the columns move apart and it is laid out again: at most
    :data:`WIDEN` layouts, and no more once moving apart stops helping (by a fifth of the conflicts
    at least; a crowded gap has more arrows than room: the expanded 10-car platoon was
    laid out four times to go from 4906 conflicts to 4633).
    """
    st = structure(world, collapse)
    best: tuple[Figure, list[Bbox], list[Bbox], int] | None = None
    for widen in WIDEN:
        laid = _layout(world, st, widen)
        if best is not None and laid[3] > 0.8 * best[3]:  # wider barely helped: it will not
            if laid[3] < best[3]:
                best, laid = laid, best
            plt.close(laid[0])
            break
        if best is not None:
            plt.close(best[0])
        best = laid
        if not laid[3]:
            break
    assert best is not None
    return best[0], best[1], best[2]


def _layout(
    world: WorldSpec, st: Structure, widen: float
) -> tuple[Figure, list[Bbox], list[Bbox], int]:
    pos = _positions(st, widen)
    merged: dict[tuple[str, str], list[str]] = {}
    for a, b, label in st.links:
        merged.setdefault((a, b), []).append(label)
    routes = _routes(pos, list(merged))
    pts = [p for line in routes.values() for p in line]
    xs = [x for x, _ in pos.values()] + [x for x, _ in pts]
    ys = [y for _, y in pos.values()]
    top = max([max(ys) + BOX_H / 2 + 0.6, *(y + 0.5 for _, y in pts)])
    x_lo, x_hi = min(xs) - BOX_W / 2 - 0.3, max(xs) + BOX_W / 2 + 0.3
    y_lo = min(ys) - BOX_H / 2 - 1.0  # room for the legend
    fig = plt.figure(figsize=(max(6.0, (x_hi - x_lo) * 0.9), max(3.0, (top - y_lo) * 0.9)), dpi=100)
    ax = fig.add_subplot()
    fig.subplots_adjust(*MARGINS)
    ax.set_xlim(x_lo, x_hi)
    ax.set_ylim(y_lo, top)
    ax.set_aspect("equal")
    ax.axis("off")
    # the world's name is the user's text: shown escaped, and never read as mathtext (a name
    # with two ``$`` was a traceback, a control character a missing glyph)
    ax.set_title(
        one_line(f"{world.name}: {plural(len(world.leaves), 'component')}"), parse_math=False
    )
    ax.apply_aspect()
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    names = list(st.nodes)
    boxes = [_draw_box(ax, st.nodes[name], pos[name]) for name in names]
    box_extents = [b.get_window_extent(renderer) for b in boxes]
    shown = {ab: ax.transData.transform(routes[ab]) for ab in merged}
    for ab in merged:
        ax.add_patch(
            FancyArrowPatch(
                path=MplPath(routes[ab]),
                arrowstyle="-|>",
                color="0.35",
                lw=0.9,
                mutation_scale=10,
                shrinkA=0,
                shrinkB=0,
                zorder=1,
            )
        )
    placed: list[Bbox] = []
    conflicts = 0
    lines = Segments(list(shown.values()))
    for k, (ab, labels) in enumerate(merged.items()):
        ends = {names.index(ab[0]), names.index(ab[1])}
        extent, cost = _place_label(
            ax, renderer, "\n".join(labels), routes[ab], box_extents, placed, lines, k
        )
        placed.append(extent)
        conflicts += cost
        for i, box in enumerate(box_extents):  # a line through a component is a conflict too
            if i not in ends and line_crosses(shown[ab], box.expanded(0.98, 0.9)):
                conflicts += OVERLAP_COST
    handles = [
        FancyBboxPatch((0, 0), 1, 1, fc=c, ec="0.2", label=k) for k, c in KIND_COLOURS.items()
    ]
    rover_edges = [n.rover_colour for n in st.nodes.values() if n.rover_colour]
    if rover_edges:
        handles.append(
            FancyBboxPatch(
                (0, 0),
                1,
                1,
                fc="white",
                ec=rover_edges[-1],
                lw=ROVER_EDGE_W,
                label="rover: framed in its plot colour",
            )
        )
    ax.legend(handles=handles, loc="lower right", fontsize=7, ncol=3)
    return fig, box_extents, placed, conflicts


def _positions(st: Structure, widen: float = 0.0) -> dict[str, tuple[float, float]]:
    """Box centres: columns by dataflow depth, each gap as wide as its longest label
    (plus ``widen``)."""
    col = _columns(st)
    longest = dict.fromkeys(range(max(col.values()) + 1), 0)
    for a, b, label in st.links:
        if col[b] > col[a]:
            longest[col[a]] = max(longest[col[a]], len(label))
    x_of, x = {}, 0.0
    for c in sorted(longest):
        x_of[c] = x
        x += BOX_W + min(6.0, max(2.0, CHAR_W * longest[c] + 0.8)) + widen
    rows: dict[int, int] = {}
    pos = {}
    for path in st.nodes:
        c = col[path]
        pos[path] = (x_of[c], -rows.get(c, 0) * ROW_STEP)
        rows[c] = rows.get(c, 0) + 1
    return pos


def _routes(
    pos: dict[str, Point], links: list[tuple[str, str]]
) -> dict[tuple[str, str], list[Point]]:
    """Every link as a polyline in data units, from its source box to its target box.

    Forward links are straight, right side to left side, unless that line would cross a
    third box: then they go around it along a free lane (``graphgeom.detour``). The links
    leaving (entering) one box start (end) at points spread along its side in the order of
    the boxes they go to, so a fan of links does not meet in one point. A link back (into a
    process: the loop's feedback) arcs over the boxes from top to top where that arc
    crosses no other box; otherwise it is routed around them: up from the source, along a
    lane above every box, down beside the target and into its left side.
    """
    forward = [(a, b) for a, b in links if pos[b][0] > pos[a][0]]
    start: dict[tuple[str, str], float] = {}
    end: dict[tuple[str, str], float] = {}
    for name in pos:
        outs = sorted((ab for ab in forward if ab[0] == name), key=lambda ab: -pos[ab[1]][1])
        ins = sorted((ab for ab in forward if ab[1] == name), key=lambda ab: -pos[ab[0]][1])
        for group, side in ((outs, start), (ins, end)):
            for k, ab in enumerate(group):
                side[ab] = 0.3 * BOX_H * (1 - 2 * k / (len(group) - 1)) if len(group) > 1 else 0
    out: dict[tuple[str, str], list[Point]] = {}
    lanes = 0
    top = max(y for _, y in pos.values()) + BOX_H / 2
    for a, b in links:
        (x0, y0), (x1, y1) = pos[a], pos[b]
        if (a, b) in start:
            line = [(x0 + BOX_W / 2, y0 + start[(a, b)]), (x1 - BOX_W / 2, y1 + end[(a, b)])]
            others = [pos[n] for n in pos if n not in (a, b)]
            if any(passes_through(line, c) for c in others):  # past a third box: around it
                line = detour(line[0], line[1], others, DETOUR_GAP, CORNER) or line
            out[(a, b)] = line
            continue
        p0, p2 = (x0, y0 + BOX_H / 2), (x1, y1 + BOX_H / 2)
        peak = max(p0[1], p2[1]) + ARC_RISE  # the curve's midpoint; the control is twice as high
        mid = ((p0[0] + p2[0]) / 2, (p0[1] + p2[1]) / 2)
        arc = quadratic_curve(p0, (mid[0], 2 * peak - mid[1]), p2)
        if not any(hits_box(arc, pos[n]) for n in pos if n not in (a, b)):
            out[(a, b)] = arc
            continue
        lane = top + ARC_RISE + LANE_STEP * lanes
        lanes += 1
        side = x1 - BOX_W / 2 - 0.5 - LANE_STEP * (lanes - 1)
        corners = [p0, (x0, lane), (side, lane), (side, y1), (x1 - BOX_W / 2, y1)]
        out[(a, b)] = rounded_path(corners, CORNER)
    return out


def _place_label(
    ax: plt.Axes,
    renderer: object,
    text: str,
    line: list[Point],
    boxes: list[Bbox],
    placed: list[Bbox],
    lines: Segments,
    own: int,
) -> tuple[Bbox, int]:
    """Put ``text`` on its link (line ``own`` of ``lines``) where it covers nothing; its
    extent and what it still covers.

    A place is judged by what the label would cover: a component or a label placed before
    (:data:`OVERLAP_COST` each) and another link's line (1 each: a label on a crossing
    hides which line goes where). The first free place from the middle outwards wins. The
    label is measured once and moved (a centred text's extent moves with its centre).
    """
    label = ax.text(
        0,
        0,
        text,
        fontsize=LABEL_PT,
        ha="center",
        va="center",
        color="0.2",
        bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.85},
        zorder=4,
    )
    size = label.get_window_extent(renderer).expanded(1.08, 1.15)
    origin = ax.transData.transform((0.0, 0.0))
    covered = np.array([[b.x0, b.y0, b.x1, b.y1] for b in (*boxes, *placed)]).reshape(-1, 4)
    best: tuple[int, Bbox, Point] | None = None
    for t in ALONG:
        spot = point_along(line, t)
        dx, dy = ax.transData.transform(spot) - origin
        extent = size.translated(dx, dy)
        cost = OVERLAP_COST * overlapping(extent, covered)
        if cost < (best[0] if best is not None else 1 << 30):
            cost += lines.crossing(extent, own)
        if best is None or cost < best[0]:
            best = (cost, extent, spot)
        if cost == 0:
            break
    assert best is not None
    label.set_position(best[2])
    return label.get_window_extent(renderer).expanded(1.08, 1.15), best[0]


def _draw_box(ax: plt.Axes, node: Node, centre: Point) -> FancyBboxPatch:
    """One component (or its copies): name, template and frequency on its kind's colour."""
    x, y = centre
    box = FancyBboxPatch(
        (x - BOX_W / 2, y - BOX_H / 2),
        BOX_W,
        BOX_H,
        boxstyle="round,pad=0.05,rounding_size=0.15",
        fc=KIND_COLOURS[node.kind],
        # a rover framed in its colour in the trajectory plot, the window and the video
        ec=node.rover_colour or "0.2",
        lw=ROVER_EDGE_W if node.rover_colour else 1,
        zorder=2,
    )
    ax.add_patch(box)
    ax.text(x, y + 0.12, node.name, ha="center", va="center", fontsize=8.5, weight="bold", zorder=3)
    ax.text(x, y - 0.2, node.subtitle, ha="center", va="center", fontsize=7, zorder=3)
    return box
