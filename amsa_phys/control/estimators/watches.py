"""Which context parameter each estimator of a world watches (its ``estimates``).

An estimator template declares what it estimates (``control/estimators``: "``delivered`` is
about 0.01 x ``motorCoef`` of a NormalizePower"). In a world, the Leaf it watches is the
nearest Leaf of that template on the estimator's dataflow: a producer of its inputs, their
producers, or another reader of the same Data (the actuator fed the same commands), at
most ``MAX_HOPS`` links away. This keeps the mapping out of the user's hands and wrong
wiring visible: an estimator that watches nothing is reported.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

from ...model.template import Template, TemplateNotFound, resolve_template
from ...model.world import WorldSpec
from . import Estimates

MAX_HOPS = 3


@dataclass(frozen=True)
class Watch:
    """Estimator output ``signal`` (``Leaf.output``) estimates context parameter ``key``."""

    signal: str
    key: str
    estimates: Estimates


def _neighbours(world: WorldSpec) -> dict[str, set[str]]:
    """Leaves linked by a Data (producer to reader, and readers of the same Data)."""
    near: dict[str, set[str]] = {p: set() for p in world.leaves}
    readers: dict[str, set[str]] = {}
    for path, leaf in world.leaves.items():
        for buffer in leaf.inputs.values():
            producer = buffer.rpartition(".")[0]
            if producer in near:
                near[path].add(producer)
                near[producer].add(path)
            readers.setdefault(buffer, set()).add(path)
    for group in readers.values():
        for a in group:
            near[a] |= group - {a}
    return near


def watches(world: WorldSpec) -> list[Watch]:
    """Every (estimator output, context parameter) pair of ``world``, in world order."""
    near = _neighbours(world)
    out = []
    for path, leaf in world.leaves.items():
        for est in getattr(leaf.template, "estimates", ()):
            target = _nearest(path, near, world, est.templates)
            if target is not None:
                out.append(Watch(f"{path}.{est.output}", f"{target}.{est.param}", est))
    return out


def _classes(names: tuple[str, ...]) -> tuple[type[Template], ...]:
    """The templates an estimator names, as classes: a Leaf counts when its template is one
    of them or a subclass (which keeps the parameter and its meaning), never when it merely
    shares a name (a user's own ``GPS`` is another receiver)."""
    out = []
    for name in names:
        try:
            out.append(resolve_template(name))
        except TemplateNotFound:  # a plugin's template that is not installed: none to watch
            continue
    return tuple(out)


def _nearest(
    start: str, near: dict[str, set[str]], world: WorldSpec, names: tuple[str, ...]
) -> str | None:
    """The closest Leaf of one of the templates ``names`` (ties: world order)."""
    kinds = _classes(names)
    order = {p: i for i, p in enumerate(world.leaves)}
    seen = {start}
    frontier = deque([(start, 0)])
    found: list[tuple[int, int, str]] = []
    while frontier:
        path, hops = frontier.popleft()
        if hops and issubclass(world.leaves[path].template, kinds):
            found.append((hops, order[path], path))
        if hops == MAX_HOPS:
            continue
        for other in sorted(near[path], key=order.__getitem__):
            if other not in seen:
                seen.add(other)
                frontier.append((other, hops + 1))
    return min(found)[2] if found else None
