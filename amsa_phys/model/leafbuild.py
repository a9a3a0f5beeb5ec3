"""Building one Leaf of a world and linking its inputs: templates resolved, parameters
judged, ``count:`` copies filled in, each input bound to the buffer it names (with the
Composite scopes searched outward), named Data resolved.

Split from ``world.py``, which walks the component tree and calls these.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from .links import allowed_text, link_allowed
from .suggest import did_you_mean
from .template import TemplateNotFound, known_names, resolve_template
from .timing import TIMING_KEYS, LeafTiming, timed
from .worldspec import DEFAULT_FREQ_HZ, BufferSpec, LeafSpec
from .yamlio import KeyPath


def data_buffer(
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


def build_leaf(
    path: str, body: dict[str, Any], kp: KeyPath, err: Any, copy: Copy | None = None
) -> LeafSpec:
    ref = body["template"]
    try:
        template = resolve_template(ref)
    except TemplateNotFound as exc:
        known = known_names()
        # a registered name that failed to load needs no "did you mean" (it is the name)
        hint = did_you_mean(ref, known) if ":" not in ref and ref not in known else ""
        if ":" not in ref and not hint and ref not in known:
            hint = " (no built-in template and no installed plugin has that name)"
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


def link_inputs(
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
