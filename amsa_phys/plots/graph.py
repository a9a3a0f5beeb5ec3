"""Architecture diagrams (paper Fig. 2/4): components coloured by kind, Data as labelled arrows.

Layout: a component's column is its depth in the dataflow, counting only edges that go forward
in the execution order (a loop's back edge is drawn but does not push columns); rows keep
declaration order. DOT output is for Graphviz users; PNG and SVG are drawn with matplotlib so
no Graphviz install is needed.

Labels are placed, not just drawn: each link's label (one line per Data buffer) goes at the
first point along its arrow where its measured extent overlaps no component and no label
placed before it; the gap after a column is as wide as the longest label leaving it. An
earlier version put every label just after its source box, where labels of one source sat on
top of each other and of the next column's names.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.figure import Figure
from matplotlib.patches import FancyBboxPatch
from matplotlib.transforms import Bbox

from ..engine.recorder import write_atomic
from ..model.world import WorldSpec
from .save import save_png

KIND_COLOURS = {
    "environment": "#8dd3c7",
    "process": "#fdb462",
    "sensor": "#80b1d3",
    "actuator": "#fb8072",
    "controller": "#bebada",
    "observer": "#d9d9d9",
}


def edges(world: WorldSpec) -> list[tuple[str, str, str]]:
    """(producer, consumer, label) for every link, label ``output -> port``."""
    out = []
    for path, leaf in world.leaves.items():
        for port, buffer in leaf.inputs.items():
            producer, _, output = buffer.rpartition(".")
            label = output if output == port else f"{output}→{port}"
            if buffer in world.arrays:  # an array link: say how many Data it carries
                label += f" [{len(world.arrays[buffer])}]"
            out.append((producer, path, label))
    return out


@dataclass(frozen=True)
class Node:
    """A box of the diagram: one component, or every copy of a repeated one (``count``)."""

    name: str
    template: str
    kind: str
    freq: float
    count: int = 1

    @property
    def subtitle(self) -> str:
        """``controlledRobot · 4 Hz``, with ``· ×10`` for copies."""
        copies = f" · ×{self.count}" if self.count > 1 else ""
        return f"{self.template} · {self.freq:g} Hz{copies}"


@dataclass
class Structure:
    """What the diagram shows: boxes and labelled links (``Node.name`` to ``Node.name``)."""

    nodes: dict[str, Node]
    links: list[tuple[str, str, str]]


_COPY = re.compile(r"^(.*?)(\d+)$")


def structure(world: WorldSpec, collapse: bool = True) -> Structure:
    """The world's components and links; with ``collapse``, copies drawn once.

    Copies are leaves of Composites whose names differ only in a trailing number (``count:``
    makes Car1 .. Car10) with the same template: ``Car{i}.Robot`` stands for all of them. A
    link between different copies says so (``posX (from i-1)``), and a link that only some
    copies have names them (``(i=1)``, ``(i=2..10)``).
    """
    copy_of: dict[str, tuple[str, int]] = {}  # leaf path -> (node name, copy number)
    if collapse:
        members: dict[tuple[str, str, str], list[tuple[int, str]]] = {}
        for path, leaf in world.leaves.items():
            parent, _, name = path.rpartition(".")
            m = _COPY.match(parent)
            if m:
                key = (m.group(1), name, leaf.template_ref)
                members.setdefault(key, []).append((int(m.group(2)), path))
        for (prefix, name, _), group in members.items():
            if len(group) > 1:
                for number, path in group:
                    copy_of[path] = (f"{prefix}{{i}}.{name}", number)
    nodes: dict[str, Node] = {}
    for path, leaf in world.leaves.items():
        name = copy_of[path][0] if path in copy_of else path
        if name in nodes:
            nodes[name] = replace(nodes[name], count=nodes[name].count + 1)
        else:
            kind = leaf.kind.value
            nodes[name] = Node(name, leaf.template.name(), kind, float(leaf.freq))
    numbers: dict[str, set[int]] = {}
    for name, number in copy_of.values():
        numbers.setdefault(name, set()).add(number)
    # (from, to, label, copy offset) -> the copy numbers it holds for (of the copy side)
    held: dict[tuple[str, str, str, int], set[int]] = {}
    for a, b, label in edges(world):
        na, ia = copy_of.get(a, (a, None))
        nb, ib = copy_of.get(b, (b, None))
        offset = ia - ib if ia is not None and ib is not None else 0
        side = ib if ib is not None else ia
        held.setdefault((na, nb, label, offset), set()).update(() if side is None else (side,))
    links = []
    for (na, nb, label, offset), which in held.items():
        notes = [f"from i{offset:+d}"] if offset else []
        copy_side = nb if nb in numbers else na
        if which and which != numbers.get(copy_side, which):
            notes.append(f"i={_numbers_text(which)}")
        links.append((na, nb, f"{label} ({', '.join(notes)})" if notes else label))
    return Structure(nodes, links)


def _numbers_text(which: set[int]) -> str:
    """``1``, ``2..10`` or ``1, 3, 5``."""
    low, high = min(which), max(which)
    if len(which) == 1:
        return str(low)
    if which == set(range(low, high + 1)):
        return f"{low}..{high}"
    return ", ".join(str(n) for n in sorted(which))


def to_dot(world: WorldSpec, collapse: bool = True) -> str:
    """The architecture as Graphviz DOT text."""
    st = structure(world, collapse)
    lines = [
        f'digraph "{world.name}" {{',
        "  rankdir=LR;",
        '  node [shape=box, style="rounded,filled", fontname="Helvetica"];',
    ]
    for name, node in st.nodes.items():
        copies = f", ×{node.count}" if node.count > 1 else ""
        label = f"{name}\\n{node.template} ({node.kind}, {node.freq:g} Hz{copies})"
        lines.append(f'  "{name}" [label="{label}", fillcolor="{KIND_COLOURS[node.kind]}"];')
    for a, b, label in st.links:
        lines.append(f'  "{a}" -> "{b}" [label="{label}", fontsize=9];')
    lines.append("}")
    return "\n".join(lines) + "\n"


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


BOX_W, BOX_H = 3.0, 0.9  # a component, in data units (0.9 inch each)
ROW_STEP = 1.6
LABEL_PT = 6
CHAR_W = 0.055  # data units per label character at LABEL_PT, for sizing column gaps
ARC_RISE = 1.4  # how far a feedback arc rises above the boxes it joins
MARGINS = (0.01, 0.01, 0.99, 0.92)  # fixed: labels are placed against the final transform
#: where along an arrow a label is tried, in order (0 = source end, 1 = target end)
ALONG = (0.5, 0.35, 0.65, 0.22, 0.78, 0.12, 0.88, 0.42, 0.58, 0.28, 0.72, 0.17, 0.83)


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

    Where some label finds no free place, the columns move apart and it is laid out again
    (a few times at most: a crowded gap has more arrows than room).
    """
    st = structure(world, collapse)
    for widen in (0.0, 1.5, 3.0):
        fig, boxes, labels = _layout(world, st, widen)
        if not any(a.overlaps(b) for i, a in enumerate(labels) for b in (*labels[:i], *boxes)):
            return fig, boxes, labels
        plt.close(fig)
    return _layout(world, st, 4.5)


def _layout(world: WorldSpec, st: Structure, widen: float) -> tuple[Figure, list[Bbox], list[Bbox]]:
    pos = _positions(st, widen)
    merged: dict[tuple[str, str], list[str]] = {}
    for a, b, label in st.links:
        merged.setdefault((a, b), []).append(label)
    curves = {ab: _curve(pos[ab[0]], pos[ab[1]]) for ab in merged}
    xs = [x for x, _ in pos.values()]
    ys = [y for _, y in pos.values()]
    top = max(ys) + BOX_H / 2 + 0.6
    for p0, c, p2 in curves.values():
        top = max(top, (p0[1] + 2 * c[1] + p2[1]) / 4 + 0.5)
    x_lo, x_hi = min(xs) - BOX_W / 2 - 0.3, max(xs) + BOX_W / 2 + 0.3
    y_lo = min(ys) - BOX_H / 2 - 1.0  # room for the legend
    fig = plt.figure(figsize=(max(6.0, (x_hi - x_lo) * 0.9), max(3.0, (top - y_lo) * 0.9)), dpi=100)
    ax = fig.add_subplot()
    fig.subplots_adjust(*MARGINS)
    ax.set_xlim(x_lo, x_hi)
    ax.set_ylim(y_lo, top)
    ax.set_aspect("equal")
    ax.axis("off")
    ax.set_title(f"{world.name}: {len(world.leaves)} components")
    ax.apply_aspect()
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    boxes = [_draw_box(ax, node, pos[name]) for name, node in st.nodes.items()]
    box_extents = [b.get_window_extent(renderer) for b in boxes]
    placed: list[Bbox] = []
    for ab, labels in merged.items():
        p0, c, p2 = curves[ab]
        ax.annotate(
            "",
            xy=p2,
            xytext=p0,
            arrowprops={
                "arrowstyle": "-|>",
                "color": "0.35",
                "lw": 0.9,
                "shrinkA": 0,
                "shrinkB": 0,
                "connectionstyle": f"arc3,rad={_rad(p0, c, p2):.6f}",
            },
        )
        placed.append(
            _place_label(ax, renderer, "\n".join(labels), (p0, c, p2), box_extents, placed)
        )
    handles = [
        FancyBboxPatch((0, 0), 1, 1, fc=c, ec="0.2", label=k) for k, c in KIND_COLOURS.items()
    ]
    ax.legend(handles=handles, loc="lower right", fontsize=7, ncol=3)
    return fig, box_extents, placed


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


Point = tuple[float, float]


def _curve(a: Point, b: Point) -> tuple[Point, Point, Point]:
    """Start, control point and end of the quadratic arrow from box ``a`` to box ``b``.

    Forward links are straight, right side to left side; a link back (into a process: the
    loop's feedback) arcs over the boxes from top to top.
    """
    (x0, y0), (x1, y1) = a, b
    if x1 > x0:
        p0, p2 = (x0 + BOX_W / 2, y0), (x1 - BOX_W / 2, y1)
        return p0, ((p0[0] + p2[0]) / 2, (p0[1] + p2[1]) / 2), p2
    p0, p2 = (x0, y0 + BOX_H / 2), (x1, y1 + BOX_H / 2)
    peak = max(p0[1], p2[1]) + ARC_RISE  # the curve's midpoint; the control point is twice as high
    mid = ((p0[0] + p2[0]) / 2, (p0[1] + p2[1]) / 2)
    return p0, (mid[0], 2 * peak - mid[1]), p2


def _rad(p0: Point, c: Point, p2: Point) -> float:
    """matplotlib's ``arc3`` rad that puts the control point at ``c`` (0 for a straight line)."""
    dx, dy = p2[0] - p0[0], p2[1] - p0[1]
    mid = ((p0[0] + p2[0]) / 2, (p0[1] + p2[1]) / 2)
    length2 = dx * dx + dy * dy
    if length2 == 0:
        return 0.0
    # arc3: c = mid + rad * (dy, -dx)
    return ((c[0] - mid[0]) * dy - (c[1] - mid[1]) * dx) / length2


def _place_label(
    ax: plt.Axes,
    renderer: object,
    text: str,
    curve: tuple[Point, Point, Point],
    boxes: list[Bbox],
    placed: list[Bbox],
) -> Bbox:
    """Put ``text`` at the first point of the curve where it overlaps nothing; its extent."""
    p0, c, p2 = curve
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
    best: tuple[int, Bbox] | None = None
    for t in ALONG:
        u = 1 - t
        label.set_position(
            (
                u * u * p0[0] + 2 * u * t * c[0] + t * t * p2[0],
                u * u * p0[1] + 2 * u * t * c[1] + t * t * p2[1],
            )
        )
        extent = label.get_window_extent(renderer).expanded(1.08, 1.15)
        hits = sum(extent.overlaps(o) for o in (*boxes, *placed))
        if best is None or hits < best[0]:
            best = (hits, extent)
            spot = label.get_position()
        if hits == 0:
            break
    assert best is not None
    label.set_position(spot)
    return best[1]


def _draw_box(ax: plt.Axes, node: Node, centre: Point) -> FancyBboxPatch:
    """One component (or its copies): name, template and frequency on its kind's colour."""
    x, y = centre
    box = FancyBboxPatch(
        (x - BOX_W / 2, y - BOX_H / 2),
        BOX_W,
        BOX_H,
        boxstyle="round,pad=0.05,rounding_size=0.15",
        fc=KIND_COLOURS[node.kind],
        ec="0.2",
        lw=1,
        zorder=2,
    )
    ax.add_patch(box)
    ax.text(x, y + 0.12, node.name, ha="center", va="center", fontsize=8.5, weight="bold", zorder=3)
    ax.text(x, y - 0.2, node.subtitle, ha="center", va="center", fontsize=7, zorder=3)
    return box
