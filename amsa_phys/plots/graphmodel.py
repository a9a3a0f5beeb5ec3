"""What an architecture diagram shows, without drawing it: boxes, links, DOT text.

Split from ``plots/graph.py`` (which lays out and draws with matplotlib) so the structure
of a world — components collapsed by ``count``, links labelled by Data — and its DOT form
need no plotting library.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

from ..errors import one_line
from ..model.timing import RANDOM, LeafTiming
from ..model.world import WorldSpec
from ..palette import rover_names
from .trajectory import GROUP_ABOVE, role_styles, rover_styles

KIND_COLOURS = {
    "environment": "#8dd3c7",
    "process": "#fdb462",
    "sensor": "#80b1d3",
    "actuator": "#fb8072",
    "controller": "#bebada",
    "observer": "#d9d9d9",
}


def edges(world: WorldSpec) -> list[tuple[str, str, str]]:
    """(producer, consumer, label) for every link, label ``output -> port``; a link whose
    producer has latency or jitter says how late its Data arrive (``+0.75 s``)."""
    out = []
    for path, leaf in world.leaves.items():
        for port, buffer in leaf.inputs.items():
            producer, _, output = buffer.rpartition(".")
            label = output if output == port else f"{output}→{port}"
            if buffer in world.arrays:  # an array link: say how many Data it carries
                label += f" [{len(world.arrays[buffer])}]"
            source = world.leaves.get(producer)
            if source is not None and source.timing.delayed:
                label += f" {delay_text(source.timing)}"
            out.append((producer, path, label))
    return out


def delay_text(t: LeafTiming) -> str:
    """``+0.75 s``, or ``+0.75..0.85 s`` with jitter: how late a Leaf's outputs arrive."""
    lo = float(t.latency)
    if not t.jitter:
        return f"+{lo:g} s"
    return f"+{lo:g}..{lo + float(t.jitter):g} s"


def phase_text(world: WorldSpec, t: LeafTiming) -> str:
    """`` · phase 0.1 s`` or `` · phase random`` for a Leaf whose timer is shifted."""
    if t.phase == RANDOM or (t.phase is None and world.free_running):
        return " · phase random"
    if t.phase:
        return f" · phase {float(t.phase):g} s"
    return ""


@dataclass(frozen=True)
class Node:
    """A box of the diagram: one component, or every copy of a repeated one (``count``)."""

    name: str
    template: str
    kind: str
    freq: float
    count: int = 1
    #: `` · phase 0.1 s`` when the Leaf's timer is shifted (``phase_text``)
    phase: str = ""
    #: a rover's colour in the trajectory plot, the window and the video ("" if no rover)
    rover_colour: str = ""

    @property
    def subtitle(self) -> str:
        """``controlledRobot · 4 Hz``, with ``· ×10`` for copies and the timer's phase."""
        copies = f" · ×{self.count}" if self.count > 1 else ""
        return f"{self.template} · {self.freq:g} Hz{self.phase}{copies}"


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
    rovers = rover_names(list(world.buffers))
    looks = role_styles(rovers) if len(rovers) > GROUP_ABOVE else rover_styles(rovers)
    nodes: dict[str, Node] = {}
    for path, leaf in world.leaves.items():
        name = copy_of[path][0] if path in copy_of else path
        if name in nodes:
            nodes[name] = replace(nodes[name], count=nodes[name].count + 1)
        else:
            kind = leaf.kind.value
            nodes[name] = Node(
                name,
                leaf.template.name(),
                kind,
                float(leaf.freq),
                phase=phase_text(world, leaf.timing),
                rover_colour=looks[path].colour if path in looks else "",
            )
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


#: The DOT graph's comment that says amsa-phys wrote it (``graph -o`` replaces such a file)
DOT_MARK = "drawn by amsa-phys graph"


def to_dot(world: WorldSpec, collapse: bool = True) -> str:
    """The architecture as Graphviz DOT text; every name goes through :func:`_dot`."""
    st = structure(world, collapse)
    lines = [
        f'digraph "{_dot(world.name)}" {{',
        f'  comment="{DOT_MARK}";',
        "  rankdir=LR;",
        '  node [shape=box, style="rounded,filled", fontname="Helvetica"];',
    ]
    for name, node in st.nodes.items():
        copies = f", ×{node.count}" if node.count > 1 else ""
        label = f"{_dot(name)}\\n{_dot(f'{node.template} ({node.kind}, {node.freq:g} Hz{copies})')}"
        lines.append(f'  "{_dot(name)}" [label="{label}", fillcolor="{KIND_COLOURS[node.kind]}"];')
    for a, b, label in st.links:
        lines.append(f'  "{_dot(a)}" -> "{_dot(b)}" [label="{_dot(label)}", fontsize=9];')
    lines.append("}")
    return "\n".join(lines) + "\n"


def _dot(text: str) -> str:
    """``text`` for inside a DOT double-quoted string: one line, control characters shown
    escaped (:func:`~amsa_phys.errors.one_line`), then ``\\`` and ``"`` escaped. A world's
    ``name:`` may be any string: ``a"]; x [label="`` closed the quotes and wrote DOT of its
    own (attributes that make Graphviz read a file, ``image=``), and a newline split the
    header."""
    return one_line(text).replace("\\", "\\\\").replace('"', '\\"')
