"""Architecture diagrams (paper Fig. 2/4): components coloured by kind, Data as labelled arrows.

Layout: a component's column is its depth in the dataflow, counting only edges that go forward
in the execution order (a loop's back edge is drawn but does not push columns); rows keep
declaration order. DOT output is for Graphviz users; PNG and SVG are drawn with matplotlib so
no Graphviz install is needed.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.patches import FancyBboxPatch

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
            out.append((producer, path, output if output == port else f"{output}→{port}"))
    return out


def to_dot(world: WorldSpec) -> str:
    """The architecture as Graphviz DOT text."""
    lines = [
        f'digraph "{world.name}" {{',
        "  rankdir=LR;",
        '  node [shape=box, style="rounded,filled", fontname="Helvetica"];',
    ]
    for path, leaf in world.leaves.items():
        kind = leaf.kind.value
        label = f"{path}\\n{leaf.template.name()} ({kind}, {float(leaf.freq):g} Hz)"
        lines.append(f'  "{path}" [label="{label}", fillcolor="{KIND_COLOURS[kind]}"];')
    for a, b, label in edges(world):
        lines.append(f'  "{a}" -> "{b}" [label="{label}", fontsize=9];')
    lines.append("}")
    return "\n".join(lines) + "\n"


def _columns(world: WorldSpec) -> dict[str, int]:
    """Dataflow depth, with edges into a process or environment treated as the feedback that
    closes a control loop (drawn, but not pushing columns), and any remaining back edge of a
    depth-first walk ignored."""
    succ: dict[str, list[str]] = {p: [] for p in world.leaves}
    for a, b, _ in edges(world):
        if a != b and world.leaves[b].kind.value not in ("process", "environment"):
            succ[a].append(b)
    col = dict.fromkeys(world.leaves, 0)
    state: dict[str, int] = {}

    def visit(node: str) -> None:
        state[node] = 1
        for nxt in succ[node]:
            if state.get(nxt) == 1:
                continue  # a back edge inside a loop the schedule resolves
            col[nxt] = max(col[nxt], col[node] + 1)
            visit(nxt)
        state[node] = 2

    for _ in range(len(world.leaves)):  # relax until stable (small graphs)
        state.clear()
        before = dict(col)
        for node in world.leaves:
            if node not in state:
                visit(node)
        if col == before:
            break
    return col


def draw(world: WorldSpec, out: Path) -> Path:
    """Write the diagram to ``out`` (.png, .svg or .dot)."""
    suffix = out.suffix.lower()
    if suffix == ".dot":
        write_atomic(out, to_dot(world))
        return out
    col = _columns(world)
    rows: dict[int, int] = {}
    pos = {}
    for path in world.leaves:
        c = col[path]
        pos[path] = (c * 4.2, -rows.get(c, 0) * 1.6)
        rows[c] = rows.get(c, 0) + 1
    width = max(x for x, _ in pos.values()) + 4
    height = max(-y for _, y in pos.values()) + 2
    fig, ax = plt.subplots(figsize=(max(6, width * 0.9), max(3, height * 0.9)), dpi=100)
    w, h = 3.0, 0.9
    merged: dict[tuple[str, str], list[str]] = {}
    for a, b, label in edges(world):
        merged.setdefault((a, b), []).append(label)
    for (a, b), labels in merged.items():
        label = ", ".join(labels)
        (x0, y0), (x1, y1) = pos[a], pos[b]
        back = x1 <= x0
        ax.annotate(
            "",
            xy=(x1 - w / 2 if not back else x1, y1 + (0 if not back else h / 2)),
            xytext=(x0 + w / 2 if not back else x0, y0 + (0 if not back else h / 2)),
            arrowprops={
                "arrowstyle": "-|>",
                "color": "0.35",
                "lw": 0.9,
                "connectionstyle": "arc3,rad=0.35" if back else "arc3,rad=0.05",
            },
        )
        lx = x0 + w / 2 + 0.15 if not back else (x0 + x1) / 2
        ly = (
            y0 + 0.08 + 0.28 * (y1 - y0) / max(abs(x1 - x0), 1.0)
            if not back
            else (max(y0, y1) + 1.0)
        )
        ax.text(lx, ly, label, fontsize=6, ha="left" if not back else "center", color="0.25")
    for path, leaf in world.leaves.items():
        x, y = pos[path]
        kind = leaf.kind.value
        ax.add_patch(
            FancyBboxPatch(
                (x - w / 2, y - h / 2),
                w,
                h,
                boxstyle="round,pad=0.05,rounding_size=0.15",
                fc=KIND_COLOURS[kind],
                ec="0.2",
                lw=1,
            )
        )
        ax.text(x, y + 0.12, path, ha="center", va="center", fontsize=8.5, weight="bold")
        ax.text(
            x,
            y - 0.2,
            f"{leaf.template.name()} · {float(leaf.freq):g} Hz",
            ha="center",
            va="center",
            fontsize=7,
        )
    handles = [
        FancyBboxPatch((0, 0), 1, 1, fc=c, ec="0.2", label=k) for k, c in KIND_COLOURS.items()
    ]
    ax.legend(handles=handles, loc="lower right", fontsize=7, ncol=3)
    ax.set_xlim(-2.5, width)
    ax.set_ylim(-height, 2.8)
    ax.set_aspect("equal")
    ax.axis("off")
    ax.set_title(f"{world.name}: {len(world.leaves)} components")
    if suffix == ".png":
        return save_png(fig, out)
    import io

    buf = io.StringIO()
    fig.tight_layout()
    fig.savefig(buf, format="svg")
    plt.close(fig)
    write_atomic(out, buf.getvalue())
    return out
