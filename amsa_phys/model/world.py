"""A world file (the architecture model) -> a checked, immutable component tree.

Every reference is resolved and judged here, at load time: templates, parameter names and
values, input links (producer path and output), the kinds allowed to talk (``links.py``)
and the execution order (``dataflow.py``). A world that loads will run.
"""

from __future__ import annotations

from dataclasses import replace
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from . import schema
from .dataflow import execution_order
from .leafbuild import Copy, array_size, build_leaf, data_buffer, link_inputs
from .rates import cycle_problem
from .suggest import did_you_mean
from .worldspec import (
    DEFAULT_FREQ_HZ,
    MAX_COMPONENTS,
    PHYSICS_DEFAULTS,
    BufferSpec,
    CompositeSpec,
    LeafSpec,
    WorldSpec,
)
from .yamlio import KeyPath, YamlDoc, load_yaml

__all__ = [
    "DEFAULT_FREQ_HZ",
    "MAX_COMPONENTS",
    "PHYSICS_DEFAULTS",
    "BufferSpec",
    "CompositeSpec",
    "LeafSpec",
    "WorldSpec",
    "array_size",
    "build_world",
    "load_world",
    "resolved_values",
    "with_leaf",
]


def with_leaf(world: WorldSpec, leaf: LeafSpec) -> WorldSpec:
    """``world`` with its Leaf at ``leaf.path`` replaced by ``leaf`` (in ``leaves`` and in the
    component tree): a new WorldSpec, the given one untouched (cached scenarios share it)."""

    def swap(node: CompositeSpec) -> CompositeSpec:
        children: list[LeafSpec | CompositeSpec] = []
        for child in node.children:
            if isinstance(child, CompositeSpec):
                children.append(swap(child))
            else:
                children.append(leaf if child.path == leaf.path else child)
        return replace(node, children=children)

    return replace(world, leaves={**world.leaves, leaf.path: leaf}, root=swap(world.root))


def load_world(path: str | Path, quote: bool = True) -> WorldSpec:
    """Load and check a world file (``quote=False``: one another file names, whose values
    its shape errors never show, ``schema.validate``)."""
    doc = load_yaml(path)
    return build_world(doc.data, doc, (), quote)


def build_world(data: Any, doc: YamlDoc, prefix: KeyPath, quote: bool = True) -> WorldSpec:
    """Check ``data`` (found at ``prefix`` in ``doc``) and build the WorldSpec."""

    def err(keypath: KeyPath, message: str) -> ConfigError:
        return doc.error((*prefix, *keypath), message)

    if isinstance(data, dict) and isinstance(data.get("components"), dict):
        _check_size(data["components"], err)  # before the (slow) shape check, too
    schema.validate(data, schema.WORLD, doc, prefix, quote)
    _check_walls(data.get("physics", {}).get("walls"), err)

    leaves: dict[str, LeafSpec] = {}
    copy_schedule: list[str] = []  # the counted Composites' own schedules, per copy
    raw_inputs: dict[str, tuple[dict[str, str], KeyPath]] = {}
    root = CompositeSpec(path="")

    def walk(
        comps: dict[str, Any],
        parent: CompositeSpec,
        keypath: KeyPath,
        copy: Copy | None = None,
    ) -> None:
        for name, body in comps.items():
            path = f"{parent.path}.{name}" if parent.path else name
            kp = (*keypath, name)
            if "components" in body:
                if "count" in body:
                    for leaf_name in body.get("first", {}):
                        if leaf_name not in body["components"]:
                            raise err(
                                (*kp, "first", leaf_name),
                                f"no component {leaf_name!r} in this Composite"
                                + did_you_mean(str(leaf_name), body["components"]),
                            )
                    for inner, inner_body in body["components"].items():
                        if "components" in inner_body:
                            raise err(
                                (*kp, "components", inner),
                                "a Composite with count: holds Leaves only",
                            )
                    for j, item in enumerate(body.get("schedule", [])):
                        if item not in body["components"]:
                            raise err(
                                (*kp, "schedule", j),
                                f"no component {item!r} in this Composite"
                                + did_you_mean(str(item), body["components"]),
                            )
                    for i in range(1, body["count"] + 1):
                        copy_schedule.extend(f"{path}{i}.{x}" for x in body.get("schedule", []))
                        node = CompositeSpec(path=f"{path}{i}")
                        parent.children.append(node)
                        walk(body["components"], node, (*kp, "components"), Copy(i, body, kp))
                    continue
                for key in ("first", "schedule"):
                    if key in body:
                        raise err((*kp, key), f"only a Composite with count: has {key}:")
                node = CompositeSpec(path=path)
                parent.children.append(node)
                walk(body["components"], node, (*kp, "components"), copy)
                continue
            leaf = build_leaf(path, body, kp, err, copy)
            if path in leaves:
                raise err(kp, f"component {path} is defined twice (a counted copy's name?)")
            leaves[path] = leaf
            parent.children.append(leaf)
            raw_inputs[path] = (copy.inputs(name, body) if copy else body.get("inputs", {}), kp)

    walk(data["components"], root, ("components",))

    buffers: dict[str, BufferSpec] = {}
    arrays: dict[str, list[str]] = {}
    for leaf in leaves.values():
        for port in leaf.template.outputs:
            name = f"{leaf.path}.{port.name}"
            if port.array:
                arrays[name] = [f"{name}[{i}]" for i in range(array_size(leaf, port))]
                for element in arrays[name]:
                    buffers[element] = BufferSpec(element, leaf.path, port.name, port.initial)
            else:
                buffers[name] = BufferSpec(name, leaf.path, port.name, port.initial)

    for path, (inputs, kp) in raw_inputs.items():
        leaf = leaves[path]
        link_inputs(leaf, inputs, kp, leaves, err, arrays)

    schedule = list(data.get("schedule", []))
    for i, item in enumerate(schedule):
        if item not in leaves:
            raise err(("schedule", i), f"unknown component {item!r}" + did_you_mean(item, leaves))
    schedule += [x for x in copy_schedule if x not in schedule]
    physics = _merge(PHYSICS_DEFAULTS, data.get("physics", {}))
    why = cycle_problem([*(leaf.freq for leaf in leaves.values()), Fraction(str(physics["rate"]))])
    if why is not None:
        raise err(("components",), why)
    order = execution_order(leaves, schedule, err)
    composites = {c.path for c in _composites(root)}
    names = {
        name: data_buffer(name, ref, leaves, buffers, composites, err)
        for name, ref in data.get("data", {}).items()
    }
    return WorldSpec(
        name=str(data.get("name", doc.path.stem)),
        source=doc,
        keypath=prefix,
        data=data,
        physics=physics,
        root=root,
        leaves=leaves,
        buffers=buffers,
        order=order,
        schedule=schedule,
        data_names=names,
        arrays=arrays,
        timing=dict(data.get("timing", {})),
    )


def _check_size(comps: dict[str, Any], err: Any) -> None:
    """Refuse a world of more than :data:`MAX_COMPONENTS` Leaves before building copies."""

    def leaves(body: Any) -> int:  # any shape: the schema is checked after this
        if not isinstance(body, dict) or not isinstance(body.get("components"), dict):
            return 1
        count = body.get("count", 1)
        count = count if isinstance(count, int) and not isinstance(count, bool) else 1
        inner = sum(leaves(child) for child in body["components"].values())
        return inner * max(1, min(count, MAX_COMPONENTS + 1))

    total = 0
    for name, body in comps.items():
        total += leaves(body)
        if total > MAX_COMPONENTS:
            raise err(
                ("components", name),
                f"the world has over {MAX_COMPONENTS:,} components (count: copies "
                f"included), the limit",
            )


def _check_walls(walls: dict[str, Any] | None, err: Any) -> None:
    """A walled arena must have an inside."""
    if walls is None:
        return
    for lo, hi in (("xmin", "xmax"), ("ymin", "ymax")):
        if not walls[lo] < walls[hi]:
            raise err(
                ("physics", "walls", hi),
                f"{hi} ({walls[hi]:g}) must be greater than {lo} ({walls[lo]:g})",
            )


def resolved_values(world: WorldSpec) -> int:
    """How many values the world has written out in full (every copy, every parameter).

    An upper bound on what the YAML loader builds when it reads a resolved scenario's
    world back: a scenario is refused if this and its own values pass the loader's limit,
    so a run's ``scenario.yaml`` always loads again.
    """
    total = 16 + len(world.schedule) + sum(_values(ob) for ob in world.physics["obstacles"])
    composites = [world.root]
    while composites:
        node = composites.pop()
        for child in node.children:
            if isinstance(child, CompositeSpec):
                total += 2
                composites.append(child)
            else:
                params = sum(_values(v) for v in child.params.values())
                total += 6 + len(child.inputs) + params
    return total


def _values(value: Any) -> int:
    if isinstance(value, list | tuple):
        return 1 + sum(_values(v) for v in value)
    if isinstance(value, dict):
        return 1 + sum(_values(v) for v in value.values())
    return 1


def _composites(node: CompositeSpec) -> list[CompositeSpec]:
    out = [node]
    for child in node.children:
        if isinstance(child, CompositeSpec):
            out += _composites(child)
    return out


def _merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    out = dict(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = value
    return out
