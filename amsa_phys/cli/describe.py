"""Components, kinds, parameters with ranges, links and execution order of a file."""

from __future__ import annotations

import argparse
from typing import Any, NamedTuple

from ..errors import ConfigError, one_line
from ..model import timing
from ..model.adaptrules import describe_rules
from ..model.changes import parse_setting
from ..model.configure import with_ros2
from ..model.scenario import PHYSICS_PREFIX, Scenario, load_scenario
from ..model.wording import plural
from ..model.world import LeafSpec, WorldSpec
from ..ros import external as ros_external
from ..runs.expect import describe_bound, describe_what
from ..valuetext import value_text
from .loading import load_any


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys describe``."""
    p.add_argument("file", help="world or scenario YAML file")
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="Comp.param=V",
        help="scenario only: show the values as `run --set` would start them",
    )
    p.add_argument(
        "--ros2",
        metavar="COMP[,COMP]",
        help="scenario only: the topics, message types, QoS and parameters of these Leaves "
        "as your ROS 2 nodes (run --ros2); the scenario's ros2: without it",
    )


#: where a value in force at t = 0 comes from
Source = str


class Start(NamedTuple):
    """A parameter's value at t = 0 that a scenario gives, where it comes from, and the
    scenario's own value when a ``--set`` replaced it with another (None otherwise)."""

    value: Any
    source: Source
    replaced: Any = None


def raw_params(world: WorldSpec, leaf: LeafSpec) -> dict[str, Any]:
    """The parameters a world file writes for ``leaf`` (not the template's defaults)."""
    body: Any = world.data
    for part in leaf.keypath:
        body = body.get(part, {}) if isinstance(body, dict) else {}
    params = body.get("params", {}) if isinstance(body, dict) else {}
    return params if isinstance(params, dict) else {}


def describe_world(
    world: WorldSpec,
    start: dict[str, dict[str, Start]] | None = None,
    physics_from: dict[str, Source] | None = None,
    seed: int | None = None,
) -> list[str]:
    """Human-readable lines describing a world.

    Every parameter is shown with the value it starts with and where that comes from: the
    template's default, the world file, or (``start``, for a scenario) the scenario's
    ``set:`` or a ``--set``, with each value it replaced (``--set; scenario 0.35, world
    0.05``: the scenario's ``set:`` replaced the world's 0.05, the ``--set`` the scenario's
    0.35); a value equal to the one it replaced does not repeat it. A Leaf's loop timing
    (latency, jitter, phase) follows its frequency; for a scenario (``seed`` given) a random
    phase is shown as drawn.
    """
    start = start or {}
    lines = [
        f"world {one_line(world.name)}: {plural(len(world.leaves), 'component')}, physics "
        f"{float(world.physics['rate']):g} Hz"
    ]
    lines += _physics_lines(world, physics_from or {})
    for path in world.leaves:
        leaf = world.leaves[path]
        t = leaf.template
        written = raw_params(world, leaf)
        timing = _timing_text(world, leaf, seed)
        lines.append(
            f"  {path}: {t.name()} ({t.kind.value}) at {float(leaf.freq):g} Hz"
            + (f", {timing}" if timing else "")
        )
        for p in t.params:
            world_value = leaf.params[p.name]
            source = "world" if p.name in written else "default"
            value = world_value
            if p.name in start.get(path, {}):
                value, source, replaced = start[path][p.name]
                before = [] if replaced is None else [f"scenario {_short(replaced)}"]
                before += [f"world {_short(world_value)}"] * (value != world_value)
                source += "; " + ", ".join(before) if before else ""
            rng = p.range_text()
            unit = f" {p.unit}" if p.unit else ""
            text = f"      {p.name} = {_short(value)}{unit}" + (f"  {rng}" if rng else "")
            lines.append(f"{text}  ({source})")
        for port, buf in leaf.inputs.items():
            size = f" ({len(world.arrays[buf])} values)" if buf in world.arrays else ""
            lines.append(f"      <- {port}: {buf}{size}")
        if t.outputs:  # a terrain zone publishes nothing
            outs = ", ".join(
                f"{p.name}[{len(world.arrays[f'{path}.{p.name}'])}]" if p.array else p.name
                for p in t.outputs
            )
            lines.append(f"      -> {outs}")
    lines.append("execution order at a shared instant: " + " -> ".join(world.order))
    lines.append(_loop_timing_line(world))
    if world.schedule:
        lines.append("explicit schedule: " + ", ".join(world.schedule))
    return lines


def _timing_text(world: WorldSpec, leaf: LeafSpec, seed: int | None) -> str:
    """``latency 0.75 s, phase 0.137 s (random)``: what ``model/timing.py`` describes, with
    a random phase drawn for this seed when there is one."""
    text = timing.describe(leaf.timing, world.free_running)
    random = leaf.timing.phase == timing.RANDOM or (
        leaf.timing.phase is None and world.free_running
    )
    if random and seed is not None:
        from ..engine.timing import leaf_phase  # numpy: only when there is one to draw

        drawn = leaf_phase(leaf, world, seed)
        text = text.replace("phase random", f"phase {float(drawn):g} s (random, seed {seed})")
    return text


def _loop_timing_line(world: WorldSpec) -> str:
    """One line on how the world's Leaves are timed, so the default is visible too."""
    delayed = [p for p, leaf in world.leaves.items() if leaf.timing.delayed]
    free = "free-running: every Leaf without a phase ticks at a random one; " * world.free_running
    if not delayed:
        return f"loop timing: {free}outputs reach their readers in the instant they are published"
    return (
        f"loop timing: {free}outputs of {', '.join(delayed)} reach their readers after their "
        "latency (and jitter); every other output in the instant it is published"
    )


def _physics_lines(world: WorldSpec, physics_from: dict[str, Source]) -> list[str]:
    """The physics settings in force, each with its source (default, world, scenario)."""
    written = world.data.get("physics", {}) if isinstance(world.data, dict) else {}
    parts = []
    for key, value in world.physics.items():
        if key in ("obstacles", "walls"):
            continue
        items = value.items() if isinstance(value, dict) else [(None, value)]
        for sub, v in items:
            name = f"{key}.{sub}" if sub else key
            in_world = (key in written) if sub is None else sub in written.get(key, {})
            source = physics_from.get(name, "world" if in_world else "default")
            parts.append(f"{name} {_short(v)} ({source})")
    obstacles = len(world.physics.get("obstacles") or [])
    walls = "walls" if world.physics.get("walls") else "no walls"
    from ..physics.step_path import describe as step_path  # no numpy, no pymunk

    return [f"  physics: {', '.join(parts)}; {obstacles} obstacles, {walls}; step {step_path()[1]}"]


def _short(value: Any) -> str:
    return value_text(value)  # as the run's table and the window print it


def scenario_start(
    file: Scenario, final: Scenario, set_keys: set[str]
) -> dict[str, dict[str, Start]]:
    """Each parameter phase 0 of ``final`` sets, with its source: ``--set`` for a key in
    ``set_keys`` (the ``Leaf.param`` keys the command line gave), else the scenario's
    ``set:``.

    Sources go by key, not by position in phase 0: a ``--set`` of a key the file's ``set:``
    already gives replaces the file's entry, so counting the file's entries first would name
    the wrong ones.
    """
    in_file = {c.key: c.value for c in file.timeline.initial}
    start: dict[str, dict[str, Start]] = {}
    for change in final.timeline.initial:
        if change.key in set_keys:
            scenario = in_file.get(change.key)
            replaced = scenario if change.key in in_file and scenario != change.value else None
            entry = Start(change.value, "--set", replaced)
        else:
            entry = Start(change.value, "scenario set")
        start.setdefault(change.leaf, {})[change.param] = entry
    return start


def set_keys(overrides: list[str], scenario: Scenario) -> set[str]:
    """The ``Leaf.param`` keys of parameters ``--set`` gives (an alias resolved to the
    declared name; physics settings and frequencies are not parameters of phase 0)."""
    keys = set()
    for text in overrides:
        if text.strip().startswith(PHYSICS_PREFIX):
            continue
        change, _ = parse_setting(text, scenario.world)
        if change is not None:
            keys.add(change.key)
    return keys


def run(args: argparse.Namespace) -> int:
    """Print the description."""
    kind, obj = load_any(args.file)
    if kind == "world" and args.overrides:
        raise ConfigError("only for a scenario: a world has no t = 0 to set", key="--set")
    if kind == "world" and args.ros2:
        raise ConfigError("only for a scenario: run a scenario with --ros2", key="--ros2")
    if kind == "scenario":
        file_scenario, given = obj, set()
        physics_from = {
            f"{k}.{sub}" if isinstance(v, dict) else k: "scenario physics"
            for k, v in (obj.data.get("physics") or {}).items()
            for sub in (v if isinstance(v, dict) else [None])
        }
        if args.overrides:
            obj = load_scenario(args.file, overrides=args.overrides)
            given = set_keys(args.overrides, file_scenario)
            for text in args.overrides:
                key = text.partition("=")[0].strip()
                if key.startswith(PHYSICS_PREFIX):
                    physics_from[key.removeprefix(PHYSICS_PREFIX)] = "--set"
        obj = with_ros2(obj, args.ros2)  # a refused Leaf before anything is printed
        print(
            f"scenario {one_line(obj.name)}: {float(obj.duration):g} s, seed {obj.seed}, "
            f"trace at {float(obj.log_rate):g} Hz"
        )
        if obj.quality:
            q = obj.quality
            print(f"quality: {q.signal} vs {q.reference:g} ± {q.tolerance:g}")
        # a --set of a key the file's set: already gives replaces it: show the value in force
        final = {c.key: c.value for c in obj.timeline.initial}
        print("phase 0 at 0 s: " + (", ".join(f"{k}={_short(v)}" for k, v in final.items()) or "-"))
        for point in obj.timeline.points():
            changes = ", ".join(f"{c.key}={_short(c.value)}" for c in point.changes)
            if point.starts_phase:
                print(f"phase {point.phase} at {float(point.at):g} s: {changes or '-'}")
            else:
                print(f"  change at {float(point.at):g} s (same phase): {changes}")
        for e in obj.expect:
            print(f"expect {describe_what(e)} {describe_bound(e)}")
        for line in describe_rules(obj.adapt):
            print(f"adapt {line}")
        if obj.ros2:
            for line in ros_external.table(
                ros_external.describe(obj.world, obj.ros2), obj.ros2_timeout
            ):
                print(line)
        print(
            "values in force at t = 0, each with where it comes from (default: the "
            "template's; world; scenario set; --set) and any value it replaced"
        )
        start = scenario_start(file_scenario, obj, given)
        lines = describe_world(obj.world, start, physics_from, seed=obj.seed)
    else:
        lines = describe_world(obj)
    print("\n".join(lines))
    return 0
