"""A world file (the architecture model) -> a checked, immutable component tree.

Every reference is resolved and judged here, at load time: templates, parameter names and
values, input links (producer path and output), the kinds allowed to talk (``links.py``)
and the execution order (``dataflow.py``). A world that loads will run.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from . import schema
from .dataflow import execution_order
from .links import allowed_text, link_allowed
from .suggest import did_you_mean
from .template import BUILTINS, Template, TemplateNotFound, resolve_template
from .yamlio import KeyPath, YamlDoc, load_yaml

#: The AMSA metamodel's default frequency (``TimeableObject.freq`` in amsaCore.ecore).
DEFAULT_FREQ_HZ = 10

PHYSICS_DEFAULTS: dict[str, Any] = {
    "rate": 100,
    "gravity": 9.81,
    "ground": {"friction": 0.8, "rolling_resistance": 0.02},
    "obstacles": [],
    "walls": None,
    "max_speed": 100.0,
    "extent": 100000.0,
}


@dataclass
class LeafSpec:
    """One Leaf component: a template instance with its frequency, parameters and links."""

    path: str
    template: type[Template]
    template_ref: str
    freq: Fraction
    params: dict[str, Any]
    #: input port -> buffer name (``Producer.path.output``)
    inputs: dict[str, str]
    keypath: KeyPath

    @property
    def kind(self) -> Any:
        """The template's kind."""
        return self.template.kind


@dataclass
class CompositeSpec:
    """A Composite: a named group of components (the root is the system)."""

    path: str
    children: list[LeafSpec | CompositeSpec] = field(default_factory=list)


@dataclass
class BufferSpec:
    """A Data buffer: one producer's output, read by any number of consumers."""

    name: str
    producer: str
    port: str
    initial: Any


@dataclass
class WorldSpec:
    """A loaded, checked world."""

    name: str
    source: YamlDoc
    keypath: KeyPath
    data: dict[str, Any]
    physics: dict[str, Any]
    root: CompositeSpec
    leaves: dict[str, LeafSpec]
    buffers: dict[str, BufferSpec]
    order: list[str]
    schedule: list[str]

    def error(self, keypath: KeyPath, message: str) -> ConfigError:
        """A ConfigError at ``keypath`` (relative to this world) in its source file."""
        return self.source.error((*self.keypath, *keypath), message)


def load_world(path: str | Path) -> WorldSpec:
    """Load and check a world file."""
    doc = load_yaml(path)
    return build_world(doc.data, doc, ())


def build_world(data: Any, doc: YamlDoc, prefix: KeyPath) -> WorldSpec:
    """Check ``data`` (found at ``prefix`` in ``doc``) and build the WorldSpec."""
    schema.validate(data, schema.WORLD, doc, prefix)

    def err(keypath: KeyPath, message: str) -> ConfigError:
        return doc.error((*prefix, *keypath), message)

    leaves: dict[str, LeafSpec] = {}
    raw_inputs: dict[str, tuple[dict[str, str], KeyPath]] = {}
    root = CompositeSpec(path="")

    def walk(comps: dict[str, Any], parent: CompositeSpec, keypath: KeyPath) -> None:
        for name, body in comps.items():
            path = f"{parent.path}.{name}" if parent.path else name
            kp = (*keypath, name)
            if "components" in body:
                node = CompositeSpec(path=path)
                parent.children.append(node)
                walk(body["components"], node, (*kp, "components"))
                continue
            leaf = _build_leaf(path, body, kp, err)
            leaves[path] = leaf
            parent.children.append(leaf)
            raw_inputs[path] = (body.get("inputs", {}), kp)

    walk(data["components"], root, ("components",))

    buffers: dict[str, BufferSpec] = {}
    for leaf in leaves.values():
        for port in leaf.template.outputs:
            name = f"{leaf.path}.{port.name}"
            buffers[name] = BufferSpec(name, leaf.path, port.name, port.initial)

    for path, (inputs, kp) in raw_inputs.items():
        leaf = leaves[path]
        _link_inputs(leaf, inputs, kp, leaves, err)

    schedule = list(data.get("schedule", []))
    for i, item in enumerate(schedule):
        if item not in leaves:
            raise err(("schedule", i), f"unknown component {item!r}" + did_you_mean(item, leaves))
    physics = _merge(PHYSICS_DEFAULTS, data.get("physics", {}))
    order = execution_order(leaves, schedule, err)
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
    )


def _build_leaf(path: str, body: dict[str, Any], kp: KeyPath, err: Any) -> LeafSpec:
    ref = body["template"]
    try:
        template = resolve_template(ref)
    except TemplateNotFound as exc:
        hint = did_you_mean(ref, BUILTINS) if ":" not in ref else ""
        raise err((*kp, "template"), f"{exc}{hint}") from None
    freq = Fraction(str(body.get("freq", DEFAULT_FREQ_HZ)))
    declared = {p.name: p for p in template.params}
    params = {name: p.default for name, p in declared.items()}
    for name, value in body.get("params", {}).items():
        if name not in declared:
            raise err(
                (*kp, "params", name),
                f"unknown parameter of template {template.name()}"
                + did_you_mean(str(name), declared),
            )
        try:
            params[name] = declared[name].coerce(value)
        except ValueError as exc:
            raise err((*kp, "params", name), str(exc)) from None
    return LeafSpec(
        path=path,
        template=template,
        template_ref=ref,
        freq=freq,
        params=params,
        inputs={},
        keypath=kp,
    )


def _link_inputs(
    leaf: LeafSpec, inputs: dict[str, str], kp: KeyPath, leaves: dict[str, LeafSpec], err: Any
) -> None:
    ports = {p.name: p for p in leaf.template.inputs}
    for port_name, ref in inputs.items():
        where = (*kp, "inputs", port_name)
        if port_name not in ports:
            raise err(
                where,
                f"template {leaf.template.name()} has no input {port_name!r}"
                + did_you_mean(str(port_name), ports),
            )
        comp, _, output = ref.rpartition(".")
        if not comp:
            raise err(where, f"expected Component.output, got {ref!r}")
        producer = _resolve_scope(leaf.path, comp, leaves)
        if producer is None:
            raise err(where, f"unknown component {comp!r}" + did_you_mean(comp, leaves))
        outs = [p.name for p in producer.template.outputs]
        if output not in outs:
            raise err(
                where,
                f"component {producer.path} ({producer.template.name()}) has no "
                f"output {output!r}" + did_you_mean(output, outs),
            )
        if not link_allowed(producer.kind, leaf.kind):
            raise err(
                where,
                f"link {producer.path} ({producer.kind.value}) -> {leaf.path} "
                f"({leaf.kind.value}) is not allowed: a {producer.kind.value} may feed "
                f"only {allowed_text(producer.kind)}",
            )
        leaf.inputs[port_name] = f"{producer.path}.{output}"
    missing = [
        p for p in ports if p not in leaf.inputs and not getattr(ports[p], "optional", False)
    ]
    if missing:
        raise err(
            (*kp, "inputs"),
            f"input {missing[0]!r} of template {leaf.template.name()} is not connected",
        )


def _resolve_scope(consumer: str, ref: str, leaves: dict[str, LeafSpec]) -> LeafSpec | None:
    """Find ``ref`` from the consumer's enclosing Composite outwards (lexical scoping)."""
    scope = consumer.split(".")[:-1]
    while True:
        candidate = ".".join([*scope, ref])
        if candidate in leaves:
            return leaves[candidate]
        if not scope:
            return None
        scope.pop()


def _merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    out = dict(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = value
    return out
