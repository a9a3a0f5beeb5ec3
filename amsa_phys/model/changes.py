"""Parameter changes and settings: what ``set:``, ``--set``, a timeline entry or a grid axis
writes, judged against a world.

Every function here is pure: a setting that changes the world itself (a Leaf's frequency or
loop timing, a physics value) returns a new WorldSpec and leaves the given one as it was, so
a world cached and shared by a sweep's runs is never changed under them (``set_frequency``
once mutated a shared LeafSpec).
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass, field, replace
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from . import schema
from .params import short_repr
from .suggest import did_you_mean
from .timing import TIMING_KEYS, check_phase, timed
from .world import WorldSpec, with_leaf
from .yamlio import KeyPath, YamlDoc, parse_value


@dataclass(frozen=True)
class Change:
    """One parameter assignment: ``leaf.param = value``."""

    leaf: str
    param: str
    value: Any
    #: the parameter's name as the user wrote it, if an alias (``noise`` for ``stddev``)
    written: str = field(default="", compare=False)

    @property
    def key(self) -> str:
        """``Leaf.param`` with the parameter's declared name (as resolved files write it)."""
        return f"{self.leaf}.{self.param}"

    @property
    def written_key(self) -> str:
        """``Leaf.param`` as the user wrote it (where an error about it points)."""
        return f"{self.leaf}.{self.written or self.param}"


def set_changes(
    sets: dict[str, Any], kp: KeyPath, doc: YamlDoc, world: WorldSpec, frequencies: bool = False
) -> tuple[list[Change], WorldSpec]:
    """A ``set:`` mapping as parameter changes, and ``world`` with the frequencies and loop
    timings it sets for the whole run (``frequencies``: allowed here; a timeline entry may not
    set them). Errors name the file, line and key."""
    out = []
    for key, value in sets.items():
        try:
            if is_frequency(str(key), world):
                if not frequencies:
                    name = str(key).rpartition(".")[2]
                    what = "frequency" if name == "freq" else name
                    raise ValueError(
                        f"a Leaf's {what} holds for the whole run: set it in set:, "
                        "not in the timeline"
                    )
                world = set_frequency(str(key), value, world)
                continue
            out.append(resolve_change(str(key), value, world))
        except ValueError as exc:
            raise doc.error((*kp, key), str(exc)) from None
    return out, world


#: Leaf keys a scenario may set for the whole run (``set: {Leaf.freq: 4}``) besides
#: parameters: the frequency and the loop timing (``model/timing.py``).
WHOLE_RUN_KEYS = ("freq", *TIMING_KEYS)


def is_frequency(key: str, world: WorldSpec) -> bool:
    """Whether ``key`` is ``Leaf.freq`` or a timing key (``Leaf.latency``, ``.jitter``,
    ``.phase``) and the Leaf's template has no parameter of that name."""
    leaf_path, _, name = key.rpartition(".")
    leaf = world.leaves.get(leaf_path)
    return (
        name in WHOLE_RUN_KEYS
        and leaf is not None
        and name not in {p.name for p in leaf.template.params}
    )


def set_frequency(key: str, value: Any, world: WorldSpec) -> WorldSpec:
    """``world`` with a Leaf's frequency (``set: {Leaf.freq: 4}``) or timing set for the run.

    A value the world leaves to the scenario: an imported AMSA model whose Leaf has no
    frequency runs at the metamodel's 10 Hz unless a scenario says otherwise. The Leaf is
    replaced in a new WorldSpec (the given one may be shared by cached scenarios), so the
    resolved scenario writes the value into its world.
    """
    leaf_path, _, name = key.rpartition(".")
    leaf = world.leaves[leaf_path]
    if name != "freq":
        return with_leaf(world, replace(leaf, timing=timed(leaf.timing, name, value, leaf.freq)))
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise ValueError(f"expected a frequency in Hz, got {short_repr(value)}")
    try:
        freq = Fraction(str(value))
    except (ValueError, ZeroDivisionError):
        raise ValueError(f"expected a frequency in Hz, got {short_repr(value)}") from None
    if freq <= 0 or freq > 1_000_000:
        raise ValueError(f"a frequency must be in (0, 1e6] Hz, got {value}")
    why = check_phase(leaf.timing, freq)
    if why is not None:
        raise ValueError(why)
    return with_leaf(world, replace(leaf, freq=freq))


def resolve_change(key: str, value: Any, world: WorldSpec) -> Change:
    """``Leaf.param`` and a value -> a checked Change, or ValueError saying what is wrong."""
    leaf_path, _, param = key.rpartition(".")
    if not leaf_path:
        raise ValueError("expected Component.parameter")
    leaf = world.leaves.get(leaf_path)
    if leaf is None:
        raise ValueError(f"unknown component {leaf_path!r}" + did_you_mean(leaf_path, world.leaves))
    template = leaf.template
    names = [p.name for p in template.params]
    name = template.canonical(param)
    if name not in names:
        raise ValueError(
            f"unknown parameter of template {template.name()}"
            + did_you_mean(param, [*names, *template.param_aliases])
        )
    if name in template.size_params():
        raise ValueError(
            f"{param} sets how many Data buffers the component has; set it in the world"
        )
    written = param if param != name else ""
    return Change(leaf_path, name, template.param(name).coerce(value), written)


def parse_setting(text: str, world: WorldSpec) -> tuple[Change | None, WorldSpec]:
    """``Comp.param=V`` from the command line (V read as a YAML scalar): the change, and the
    world (a new one if ``Leaf.freq=V`` or a timing key set a Leaf for the whole run; the
    change is then None)."""
    key, sep, raw = text.partition("=")
    if not sep:
        raise ConfigError(f"expected Component.parameter=value, got {text!r}", key="--set")
    value = parse_value(raw, f"--set {key.strip()}")
    try:
        if is_frequency(key.strip(), world):
            return None, set_frequency(key.strip(), value, world)
        return resolve_change(key.strip(), value, world), world
    except ValueError as exc:
        raise ConfigError(str(exc), key=f"--set {key.strip()}") from None


PHYSICS_PREFIX = "physics."


def with_physics(world: WorldSpec, over: dict[str, Any]) -> WorldSpec:
    """``world`` with a scenario's ``physics:`` (or ``--set physics.…``) merged over its own.

    Mappings merge key by key (``ground: {friction: 0.5}`` keeps the world's rolling
    resistance); ``obstacles`` are *added* to the world's, so a scenario can put a box in
    the leader's way without restating the arena; any other value replaces the world's.
    The world itself is not changed: a WorldSpec may be shared.
    """
    merged = copy.deepcopy(world.physics)
    for key, value in over.items():
        if key == "obstacles":
            merged["obstacles"] = [*merged.get("obstacles", []), *copy.deepcopy(value)]
        elif isinstance(value, dict) and isinstance(merged.get(key), dict):
            merged[key] = {**merged[key], **copy.deepcopy(value)}
        else:
            merged[key] = copy.deepcopy(value)
    return dataclasses.replace(world, physics=merged)


def parse_physics_override(text: str) -> dict[str, Any]:
    """``physics.ground.friction=0.5`` -> ``{"ground": {"friction": 0.5}}``, shape-checked
    like a file's ``physics:`` (unknown keys named, with a suggestion)."""
    key, sep, raw = text.partition("=")
    key = key.strip()
    if not sep:
        raise ConfigError(f"expected physics.key=value, got {text!r}", key="--set")
    value = parse_value(raw, f"--set {key}")
    return physics_setting(key, value, option=f"--set {key}")


def physics_setting(key: str, value: Any, option: str) -> dict[str, Any]:
    """``physics.a.b`` and a value as the nested mapping ``{a: {b: value}}``, shape-checked;
    a ConfigError names ``option`` (a ``--set`` or ``--grid`` axis)."""
    parts = key.split(".")[1:]
    if not parts or not all(parts):
        raise ConfigError("expected physics.<setting>, e.g. physics.ground.friction", key=option)
    nested: dict[str, Any] = {}
    inner = nested
    for part in parts[:-1]:
        inner = inner.setdefault(part, {})
    inner[parts[-1]] = value
    doc = YamlDoc(Path(option), nested)
    try:
        schema.validate(nested, schema.PHYSICS, doc)
    except ConfigError as exc:
        where = f"physics.{exc.key}" if exc.key else key
        raise ConfigError(exc.message, key=f"{option.split(' ')[0]} {where}") from None
    return nested
