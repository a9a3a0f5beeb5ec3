"""Execution order of the Leaves from their dataflow (the paper's "logical order").

Components due at the same instant run producer-before-consumer. A loop in the dataflow has
no such order; as in the paper, the user then gives one with ``schedule:``. The listed
components run in the listed order among themselves (dataflow edges between two listed
components are replaced by that order); every other edge still constrains the order. If a
loop remains, the error names it. A component reading its own output is not a loop: it
simply sees its previous value.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from ..errors import ConfigError


def execution_order(
    leaves: Mapping[str, Any],
    schedule: Sequence[str],
    err: Callable[[tuple[Any, ...], str], ConfigError],
) -> list[str]:
    """Topological order of ``leaves`` (ties broken by declaration order)."""
    index = {path: i for i, path in enumerate(leaves)}
    listed = set(schedule)
    edges: dict[str, set[str]] = {p: set() for p in leaves}
    for path, leaf in leaves.items():
        for buffer in leaf.inputs.values():
            producer = buffer.rpartition(".")[0]
            if producer == path or (producer in listed and path in listed):
                continue
            edges[producer].add(path)
    for a, b in itertools.pairwise(schedule):
        edges[a].add(b)
    indegree = {p: 0 for p in leaves}
    for targets in edges.values():
        for t in targets:
            indegree[t] += 1
    ready = sorted((p for p, d in indegree.items() if d == 0), key=index.__getitem__)
    order: list[str] = []
    while ready:
        node = ready.pop(0)
        order.append(node)
        for t in sorted(edges[node], key=index.__getitem__):
            indegree[t] -= 1
            if indegree[t] == 0:
                ready.append(t)
                ready.sort(key=index.__getitem__)
    if len(order) < len(leaves):
        cycle = find_cycle({p: edges[p] for p in leaves if indegree[p] > 0}, index)
        text = " -> ".join([*cycle, cycle[0]])
        hint = f"schedule: [{', '.join(cycle)}]"
        where = ("schedule",) if schedule else ("components",)
        raise err(where, f"dataflow loop {text}; give the order explicitly, e.g. {hint}")
    return order


def find_cycle(edges: Mapping[str, set[str]], index: Mapping[str, int]) -> list[str]:
    """One cycle among the nodes a topological sort could not place.

    Every such node has a predecessor that is also unplaced (that is why its in-degree never
    reached zero), so walking predecessors must revisit a node; the walk reversed is a cycle.
    """
    preds: dict[str, list[str]] = {n: [] for n in edges}
    for src, targets in edges.items():
        for t in targets:
            if t in preds:
                preds[t].append(src)
    node = min(edges, key=index.__getitem__)
    walk = [node]
    seen = {node: 0}
    while True:
        node = min(preds[node], key=index.__getitem__)
        if node in seen:
            cycle = walk[seen[node] :]
            cycle.reverse()
            first = min(range(len(cycle)), key=lambda i: index[cycle[i]])
            return cycle[first:] + cycle[:first]
        seen[node] = len(walk)
        walk.append(node)
