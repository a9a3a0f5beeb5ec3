"""A world file (the architecture model) -> a checked, immutable component tree.

Every reference is resolved and judged here, at load time: templates, parameter names and
values, input links (producer path and output), the kinds allowed to talk (``links.py``)
and the execution order (``dataflow.py``). A world that loads will run.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from . import schema
from .dataflow import execution_order
from .links import allowed_text, link_allowed
from .rates import cycle_problem
from .suggest import did_you_mean
from .template import BUILTINS, Template, TemplateNotFound, resolve_template
from .timing import TIMING_KEYS, LeafTiming, timed
from .yamlio import KeyPath, YamlDoc, load_yaml

#: The AMSA metamodel's default frequency (``TimeableObject.freq`` in amsaCore.ecore).
DEFAULT_FREQ_HZ = 10
#: Most Leaf components in a world, ``count:`` copies included (checked before any copy is
#: built: 30 aliases of a ``count: 10000`` Composite would be 300,000 from a 1 KB file).
MAX_COMPONENTS = 10_000

PHYSICS_DEFAULTS: dict[str, Any] = {
    "rate": 100,
    "gravity": 9.81,
    "ground": {"friction": 0.8, "rolling_resistance": 0.02},
    "obstacles": [],
    "walls": None,
    "max_speed": 100.0,
    "extent": 100000.0,
}


@dataclass(frozen=True)
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
    #: transport latency, jitter and timer phase (``model/timing.py``)
    timing: LeafTiming = field(default_factory=LeafTiming)

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


@dataclass(frozen=True)
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
    #: Named Data (``data:``, the AMSA model's Data names): name -> buffer ``Component.output``
    data_names: dict[str, str] = field(default_factory=dict)
    #: array outputs: ``Lidar.ranges`` -> its element buffers ``Lidar.ranges[0]``, ...
    arrays: dict[str, list[str]] = field(default_factory=dict)
    #: the world's ``timing:`` section (``free_running``, ``resolution``)
    timing: dict[str, Any] = field(default_factory=dict)

    @property
    def free_running(self) -> bool:
        """Whether Leaves without their own ``phase`` get a random one."""
        return bool(self.timing.get("free_running", False))

    def error(self, keypath: KeyPath, message: str) -> ConfigError:
        """A ConfigError at ``keypath`` (relative to this world) in its source file."""
        return self.source.error((*self.keypath, *keypath), message)


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


def load_world(path: str | Path) -> WorldSpec:
    """Load and check a world file."""
    doc = load_yaml(path)
    return build_world(doc.data, doc, ())


def build_world(data: Any, doc: YamlDoc, prefix: KeyPath) -> WorldSpec:
    """Check ``data`` (found at ``prefix`` in ``doc``) and build the WorldSpec."""

    def err(keypath: KeyPath, message: str) -> ConfigError:
        return doc.error((*prefix, *keypath), message)

    if isinstance(data, dict) and isinstance(data.get("components"), dict):
        _check_size(data["components"], err)  # before the (slow) shape check, too
    schema.validate(data, schema.WORLD, doc, prefix)
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
            leaf = _build_leaf(path, body, kp, err, copy)
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
        _link_inputs(leaf, inputs, kp, leaves, err, arrays)

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
        name: _data_buffer(name, ref, leaves, buffers, composites, err)
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


def _data_buffer(
    name: str,
    ref: str,
    leaves: dict[str, LeafSpec],
    buffers: dict[str, BufferSpec],
    composites: set[str],
    err: Any,
) -> str:
    """The buffer a ``data:`` name stands for, looked up from the name's Composite outwards.

    ``Team.posX: Leader.posX`` names a Data of Composite ``Team``, so ``Leader`` is found in
    ``Team`` first, then at the root, as an input's producer would be.
    """
    scope = name.rpartition(".")[0]
    if scope not in composites:
        raise err(
            ("data", name), f"{scope!r} is not a Composite (a Data is named NAME or Composite.NAME)"
        )
    comp, _, output = ref.rpartition(".")
    producer = _resolve_scope(name, comp, leaves) if comp else None
    if producer is None:
        raise err(("data", name), f"unknown component {comp or ref!r}" + did_you_mean(comp, leaves))
    buffer = f"{producer.path}.{output}"
    if buffer not in buffers:
        outs = [p.name for p in producer.template.outputs]
        raise err(
            ("data", name),
            f"component {producer.path} ({producer.template.name()}) has no output "
            f"{output!r}" + did_you_mean(output, outs),
        )
    return buffer


def array_size(leaf: LeafSpec, port: Any) -> int:
    """The length of array output ``port`` of ``leaf`` (its size parameter's value)."""
    return int(leaf.params[port.size]) if port.size else 1


@dataclass(frozen=True)
class Copy:
    """Copy ``i`` (from 1) of a Composite with ``count: N`` — the platoon's cars.

    Copies are named ``<name>1`` .. ``<name>N``. In their Leaves' ``inputs``, ``{i}`` is the
    copy's number and ``{i-1}`` the previous one's, so ``Car{i-1}.Robot.posX`` is the car
    ahead; ``first:`` gives copy 1 other inputs (the car ahead of the first is the leader).
    A numeric parameter may be ``{from: A, step: B}``: A + B (i - 1) in copy i.
    """

    i: int
    body: dict[str, Any]
    keypath: KeyPath

    def inputs(self, leaf_name: str, leaf_body: dict[str, Any]) -> dict[str, str]:
        """The leaf's inputs in this copy, placeholders filled in."""
        inputs = dict(leaf_body.get("inputs", {}))
        if self.i == 1:
            inputs.update(self.body.get("first", {}).get(leaf_name, {}).get("inputs", {}))
        return {port: self.fill(ref) for port, ref in inputs.items()}

    def fill(self, text: str) -> str:
        """``{i}`` and ``{i-1}`` replaced by this copy's numbers."""
        return text.replace("{i-1}", str(self.i - 1)).replace("{i}", str(self.i))

    def value(self, value: Any) -> Any:
        """A ``{from, step}`` parameter's value in this copy; anything else unchanged."""
        if isinstance(value, dict) and set(value) == {"from", "step"}:
            a, b = value["from"], value["step"]
            if all(isinstance(v, int | float) and not isinstance(v, bool) for v in (a, b)):
                return a + b * (self.i - 1)
        return value


def _build_leaf(
    path: str, body: dict[str, Any], kp: KeyPath, err: Any, copy: Copy | None = None
) -> LeafSpec:
    ref = body["template"]
    try:
        template = resolve_template(ref)
    except TemplateNotFound as exc:
        hint = did_you_mean(ref, BUILTINS) if ":" not in ref else ""
        raise err((*kp, "template"), f"{exc}{hint}") from None
    freq = Fraction(str(body.get("freq", DEFAULT_FREQ_HZ)))
    declared = {p.name: p for p in template.params}
    params = {name: p.default for name, p in declared.items()}
    given: dict[str, str] = {}
    for written, value in body.get("params", {}).items():
        name = template.canonical(written)
        if name not in declared:
            raise err(
                (*kp, "params", written),
                f"unknown parameter of template {template.name()}"
                + did_you_mean(str(written), [*declared, *template.param_aliases]),
            )
        if name in given:
            raise err(
                (*kp, "params", written),
                f"{written} and {given[name]} name the same parameter ({name})",
            )
        given[name] = written
        if copy is not None:
            value = copy.value(value)
        try:
            params[name] = declared[name].coerce(value)
        except ValueError as exc:
            raise err((*kp, "params", written), str(exc)) from None
    try:
        template.check_params(params)
    except ValueError as exc:
        raise err((*kp, "params"), str(exc)) from None
    timing = LeafTiming()
    for key in TIMING_KEYS:
        if key in body:
            try:
                timing = timed(timing, key, body[key], freq)
            except ValueError as exc:
                raise err((*kp, key), str(exc)) from None
    return LeafSpec(
        path=path,
        template=template,
        template_ref=ref,
        freq=freq,
        params=params,
        inputs={},
        keypath=kp,
        timing=timing,
    )


def _link_inputs(
    leaf: LeafSpec,
    inputs: dict[str, str],
    kp: KeyPath,
    leaves: dict[str, LeafSpec],
    err: Any,
    arrays: dict[str, list[str]],
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
        outs = {p.name: p for p in producer.template.outputs}
        base, bracket, _ = output.partition("[")
        if base not in outs or (bracket and not outs[base].array):
            raise err(
                where,
                f"component {producer.path} ({producer.template.name()}) has no "
                f"output {output!r}" + did_you_mean(output, outs),
            )
        source = f"{producer.path}.{output}"
        if outs[base].array and bracket:  # one element of an array: a scalar
            n = len(arrays[f"{producer.path}.{base}"])
            if source not in arrays[f"{producer.path}.{base}"]:
                raise err(where, f"{output!r} is not an element of {base} (0..{n - 1})")
        is_array = outs[base].array and not bracket
        if is_array != ports[port_name].array:
            want = "an array" if ports[port_name].array else "one number"
            got = f"the array {base}" if is_array else f"the number {output}"
            raise err(
                where,
                f"input {port_name} of {leaf.template.name()} takes {want}, "
                f"{producer.path}.{output} is {got}",
            )
        if not link_allowed(producer.kind, leaf.kind):
            raise err(
                where,
                f"link {producer.path} ({producer.kind.value}) -> {leaf.path} "
                f"({leaf.kind.value}) is not allowed: a {producer.kind.value} may feed "
                f"only {allowed_text(producer.kind)}",
            )
        leaf.inputs[port_name] = source
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
