"""Building a Scenario from a checked document, one step per section of the file.

``build_scenario`` reads, in order: the world (loaded or inline, with the scenario's
``physics:``), the duration, the phases (``set:`` and ``timeline:``), the quality signal,
the expectations and the trace columns; then the whole is checked (rates, size, the
templates' rules along the phases). Each step is a small function that names the file, line
and key of what it refuses.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Collection, Sequence
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from . import schema, tracecols
from .adaptrules import load_rules
from .changes import Change, set_changes, with_physics
from .metrics import METRICS
from .rates import cycle_problem
from .scenariospec import (
    DEFAULT_LOG_RATE_HZ,
    DEFAULT_ROS2_TIMEOUT_S,
    DEFAULT_TOLERANCE,
    Expectation,
    Quality,
    Scenario,
)
from .suggest import did_you_mean
from .template import Kind
from .timeline import Phase, Step, Timeline
from .wording import plural
from .world import WorldSpec, build_world, load_world, resolved_values
from .yamlio import MAX_NODES, YamlDoc


def build_scenario(doc: YamlDoc, check_rules: bool = True) -> Scenario:
    """Check a scenario document and build it (the world loaded or inlined).

    ``check_rules`` runs :func:`check_phases`; a caller that still adds changes to phase 0
    runs it afterwards instead.
    """
    data = doc.data
    schema.validate(data, schema.SCENARIO, doc)
    world = _world(doc, data)
    duration = _duration(doc, data)
    phases, world = _phases(doc, data, world, duration)
    quality = _quality(doc, data, world)
    scenario = Scenario(
        path=doc.path,
        name=str(data.get("name", doc.path.stem)),
        world=world,
        timeline=Timeline.of(phases, duration),
        seed=int(data.get("seed", 0)),
        log_rate=Fraction(str(data.get("log_rate", DEFAULT_LOG_RATE_HZ))),
        quality=quality,
        expect=_expectations(doc, data, world, len(phases), quality, duration),
        data=data,
        trace_columns=_trace_patterns(doc, data, world),
        adapt=load_rules(doc, data.get("adapt", []), world),
        ros2=_ros2(doc, data, world),
        ros2_timeout=float(data.get("ros2_timeout", DEFAULT_ROS2_TIMEOUT_S)),
    )
    _check_whole(doc, data, scenario)
    if check_rules:
        check_phases(scenario, doc)
    return scenario


def _ros2(doc: YamlDoc, data: dict[str, Any], world: WorldSpec) -> tuple[str, ...]:
    """``ros2:``: the Leaves a user's ROS 2 nodes step, judged as ``--ros2`` is."""
    if "ros2" not in data:
        return ()
    from . import externals as external  # names only

    try:
        paths = external.parse_list(data["ros2"], "ros2")
    except ConfigError as exc:  # where in the file, as every other key's problem
        raise doc.error(("ros2",), exc.message) from None
    why = external.problem(world, paths)
    if why is not None:
        raise doc.error(("ros2",), why)
    return paths


def _world(doc: YamlDoc, data: dict[str, Any]) -> WorldSpec:
    """The scenario's world: the file it names or the mapping it inlines, with its physics."""
    world_ref = data["world"]
    if isinstance(world_ref, str):
        world_path = doc.path.parent / world_ref
        if world_path.is_dir():
            raise doc.error(("world",), f"{world_path} is a directory, expected a world file")
        if not world_path.exists():
            # shown without its ``..`` (``s/../worlds/w.yaml`` is ``worlds/w.yaml``); only
            # shown: with a symbolic link in the path, the lexical form may name elsewhere
            shown = Path(os.path.normpath(world_path))
            notes = [] if str(shown) == world_ref else [f"written {world_ref}"]
            notes += _nearby_file(world_path)
            said = f" ({'; '.join(notes)})" if notes else ""
            raise doc.error(("world",), f"world file not found: {shown}{said}")
        world = load_world(world_path, quote=False)  # any file: no value shown until a world
    else:
        world = build_world(world_ref, doc, ("world",))
    if "physics" in data:
        world = with_physics(world, data["physics"])
    return world


def _duration(doc: YamlDoc, data: dict[str, Any]) -> Fraction:
    """``duration:``, exact and positive."""
    duration = Fraction(str(data["duration"]))
    if duration <= 0:
        raise doc.error(("duration",), f"must be > 0, got {data['duration']}")
    why = schema.duration_problem(duration)
    if why is not None:
        raise doc.error(("duration",), why)
    return duration


def _phases(
    doc: YamlDoc, data: dict[str, Any], world: WorldSpec, duration: Fraction
) -> tuple[list[Phase], WorldSpec]:
    """Phase 0 from ``set:``, then one phase (or step, ``new_phase: false``) per timeline
    entry, in time order; and the world with the frequencies ``set:`` gives for the run."""
    initial, world = set_changes(data.get("set", {}), ("set",), doc, world, frequencies=True)
    phases = [Phase(Fraction(0), initial)]
    last = Fraction(0)
    for i, entry in enumerate(data.get("timeline", [])):
        at = Fraction(str(entry["at"]))
        if at <= last:
            raise doc.error(
                ("timeline", i, "at"),
                f"{float(at):g} s is not after the previous "
                f"phase start ({float(last):g} s); entries must be in time order",
            )
        if at >= duration:
            raise doc.error(
                ("timeline", i, "at"),
                f"{float(at):g} s is not before the end of "
                f"the scenario (duration {float(duration):g} s)",
            )
        last = at
        changes, _ = set_changes(entry["set"], ("timeline", i, "set"), doc, world)
        if entry.get("new_phase", True):
            phases.append(Phase(at, changes, entry.get("label", ""), entry=i))
        else:  # a step of the phase so far: a new Phase (they are frozen)
            step = Step(at, changes, entry.get("label", ""), entry=i)
            phases[-1] = dataclasses.replace(phases[-1], within=[*phases[-1].within, step])
    return phases, world


def _quality(doc: YamlDoc, data: dict[str, Any], world: WorldSpec) -> Quality | None:
    """``quality:``: a Data buffer of the world, with its reference and tolerance."""
    quality = None
    if "quality" in data:
        q = data["quality"]
        if q["signal"] not in world.buffers:
            raise doc.error(
                ("quality", "signal"),
                f"unknown Data {q['signal']!r}" + did_you_mean(q["signal"], world.buffers),
            )
        quality = Quality(
            q["signal"],
            float(q["reference"]),
            float(q.get("tolerance", DEFAULT_TOLERANCE)),
            None if q.get("dwell") is None else float(q["dwell"]),
        )
    return quality


def _expectations(
    doc: YamlDoc,
    data: dict[str, Any],
    world: WorldSpec,
    phases: int,
    quality: Quality | None,
    duration: Fraction,
) -> list[Expectation]:
    """``expect:``: bounds on metrics (overall or of a phase) or on a trace's samples."""
    expect = []
    names: set[str] = set()  # the requirements' names so far (a list search was quadratic)
    for i, e in enumerate(data.get("expect", [])):
        kp = ("expect", i)
        if "stl" in e:
            expect.append(_requirement(doc, data, e, kp, world, duration, names))
            continue
        if "name" in e:
            raise doc.error((*kp, "name"), "only an stl requirement takes a name")
        if ("metric" in e) == ("trace" in e):
            raise doc.error(kp, "give exactly one of 'metric', 'trace' or 'stl'")
        if "trace" in e:
            if e["trace"] not in world.buffers:
                raise doc.error(
                    (*kp, "trace"),
                    f"unknown Data {e['trace']!r}" + did_you_mean(e["trace"], world.buffers),
                )
            if "phase" in e:
                raise doc.error((*kp, "phase"), "a trace check takes after/before, not phase")
            if "after" in e and "before" in e and e["after"] > e["before"]:
                raise doc.error(
                    (*kp, "before"),
                    f"before ({e['before']:g} s) is earlier than after ({e['after']:g} s): "
                    "the window holds no instant",
                )
            if "after" in e and Fraction(str(e["after"])) > duration:
                raise doc.error(  # it would check nothing and pass
                    (*kp, "after"),
                    f"{e['after']:g} s is after the end of the scenario (duration "
                    f"{float(duration):g} s): the window would never hold a sample",
                )
            expect.append(
                Expectation(
                    None,
                    None,
                    e.get("below"),
                    e.get("above"),
                    doc.line(kp),
                    e["trace"],
                    e.get("after"),
                    e.get("before"),
                )
            )
            continue
        if e["metric"] not in METRICS:
            raise doc.error(
                (*kp, "metric"),
                f"unknown metric {e['metric']!r}"
                + did_you_mean(e["metric"], METRICS)
                + f"; known: {', '.join(METRICS)}",
            )
        if "phase" in e and e["phase"] >= phases:
            raise doc.error(
                (*kp, "phase"),
                f"phase {e['phase']} does not exist "
                f"(the scenario has {plural(phases, 'phase')}, "
                + (f"0..{phases - 1})" if phases > 1 else "only phase 0)"),
            )
        if quality is None:
            raise doc.error(kp, "metric expectations need a quality: section")
        expect.append(
            Expectation(e["metric"], e.get("phase"), e.get("below"), e.get("above"), doc.line(kp))
        )
    return expect


def _requirement(
    doc: YamlDoc,
    data: dict[str, Any],
    e: dict[str, Any],
    kp: tuple[Any, ...],
    world: WorldSpec,
    duration: Fraction,
    earlier: set[str],
) -> Expectation:
    """``{stl: FORMULA, name: NAME}``: an STL requirement, refused at load if a run could not
    judge it (``stl.requirement.check_formula``). The name is required: it is the
    ``robustness.NAME`` column of a sweep and the argument of ``falsify --requirement``, so
    it must not change when another entry is added above it."""
    from ..stl.requirement import NAME, check_formula

    extra = sorted(set(e) - {"stl", "name"})
    if extra:
        raise doc.error(
            (*kp, extra[0]), f"an stl requirement takes only stl and name, not {extra[0]}"
        )
    if "name" not in e:
        raise doc.error(
            kp,
            "an stl requirement needs a name (its robustness.NAME column and --requirement NAME)",
        )
    name = e["name"]
    if not NAME.fullmatch(name):
        raise doc.error(
            (*kp, "name"),
            f"{name!r} is not a requirement name: letters, digits, _ and -, "
            "starting with a letter or _, at most 64",
        )
    if name in earlier:
        raise doc.error((*kp, "name"), f"the requirement name {name!r} is used twice")
    earlier.add(name)
    log_rate = Fraction(str(data.get("log_rate", DEFAULT_LOG_RATE_HZ)))
    try:
        check_formula(e["stl"], world.buffers, log_rate, duration, did_you_mean)
    except ValueError as exc:
        raise doc.error((*kp, "stl"), str(exc)) from None
    return Expectation(None, None, None, None, doc.line(kp), stl=e["stl"], name=name)


def _check_whole(doc: YamlDoc, data: dict[str, Any], scenario: Scenario) -> None:
    """What only the whole scenario shows: rates that cannot be scheduled, a size that would
    not load again once written out in full."""
    why = scenario_cycle_problem(scenario)
    if why is not None:
        raise doc.error(("log_rate",) if "log_rate" in data else ("world",), why)
    size = written_values(scenario.world, data)
    if size > MAX_NODES:
        raise doc.error(
            (),
            f"too large: written out in full (every copy and parameter) the scenario holds "
            f"{size:,} values, over the limit of {MAX_NODES:,}",
        )


def trace_problem(patterns: list[str], buffers: list[str]) -> tuple[int, str] | None:
    """The first problem of ``trace_columns`` patterns: (index of the pattern, message), or
    (-1, message) if there are none. The one check for the file's key and the option."""
    if not patterns:
        return -1, "needs at least one pattern, like 'Car*.Gap.*'"
    for i, pattern in enumerate(patterns):
        if tracecols.unmatched([pattern], buffers):
            return i, tracecols.no_match_message(pattern, buffers)
    return None


def _trace_patterns(doc: YamlDoc, data: dict[str, Any], world: WorldSpec) -> list[str] | None:
    """``trace_columns:``, each pattern checked to keep at least one buffer."""
    if "trace_columns" not in data:
        return None
    raw = data["trace_columns"]
    written_as_text = isinstance(raw, str)  # "Car*.Gap.*, Leader.*", as --trace-columns
    patterns = tracecols.parse_patterns(raw) if written_as_text else [str(p) for p in raw]
    problem = trace_problem(patterns, list(world.buffers))
    if problem is not None:
        i, message = problem
        where = ("trace_columns",) if written_as_text or i < 0 else ("trace_columns", i)
        raise doc.error(where, message)
    return patterns


def effective_log_rate(rate: Fraction, world: WorldSpec) -> Fraction:
    """The trace is never sampled slower than the fastest sensor (design.md)."""
    sensors = [leaf.freq for leaf in world.leaves.values() if leaf.kind is Kind.SENSOR]
    return max([rate, *sensors])


def _nearby_file(path: Path) -> list[str]:
    """``did you mean x.yaml?`` for a YAML file beside ``path`` with a close name (``x.yml``
    for ``x.yaml``, a typo in the stem), or that its directory does not exist; none if
    neither."""
    if not path.parent.is_dir():
        return [f"there is no directory {os.path.normpath(path.parent)}"]
    try:
        names = [p.name for p in path.parent.iterdir() if p.suffix in (".yaml", ".yml")]
    except OSError:
        return []
    same_stem = [n for n in names if Path(n).stem == path.stem]
    if same_stem:
        return [f"did you mean {same_stem[0]}?"]
    hint = did_you_mean(path.name, names)  # " (did you mean x?)" or ""
    return [hint.strip()[1:-1]] if hint else []


def scenario_cycle_problem(scenario: Scenario) -> str | None:
    """Why the world's rates with the trace's cannot be scheduled (``model/rates.py``)."""
    world = scenario.world
    rates = [leaf.freq for leaf in world.leaves.values()]
    rates += [Fraction(str(world.physics["rate"])), effective_log_rate(scenario.log_rate, world)]
    return cycle_problem(rates)


def written_values(world: WorldSpec, data: dict[str, Any]) -> int:
    """At least as many values as the YAML loader builds from this scenario written out in
    full (its resolved ``scenario.yaml``): kept under the loader's limit, so a run's
    ``scenario.yaml`` always loads again."""
    return resolved_values(world) + _own_values(data)


def _own_values(data: dict[str, Any]) -> int:
    """The values of a scenario document outside its world (as the YAML loader counts)."""

    def count(value: Any) -> int:
        if isinstance(value, dict):
            return 1 + sum(count(v) for v in value.values())
        if isinstance(value, list):
            return 1 + sum(count(v) for v in value)
        return 1

    return 1 + sum(count(v) for k, v in data.items() if k != "world")


def check_phases(scenario: Scenario, doc: YamlDoc | None, overridden: Collection[str] = ()) -> None:
    """Refuse a scenario whose phases would break a template's rules, before anything runs.

    Each leaf's values are followed through the phases: after every phase, a leaf it changed
    must pass its template's ``check_params`` (powerMin <= powerMax, ...), and a timeline
    entry must not change a parameter read only by ``initialize`` (a rover's mass: the
    change would fault mid-run). A change at t = 0 of a key in ``overridden`` is a ``--set``
    (which replaced the file's own, if any: ``Timeline.with_initial``) and is named as such.
    Without a ``doc`` (a sweep's grid point) the error names the change only.
    """
    world = scenario.world
    values = {path: dict(leaf.params) for path, leaf in world.leaves.items()}

    def error(entry: int | None, change: Change, message: str) -> ConfigError:
        if doc is None:
            return ConfigError(message, key=change.written_key)
        if entry is None and change.key in overridden:
            return ConfigError(message, key=f"--set {change.written_key}")
        where = ("set",) if entry is None else ("timeline", entry, "set")
        return doc.error((*where, change.written_key), message)

    timeline = scenario.timeline
    steps: list[tuple[bool, int | None, Sequence[Change]]] = [(True, None, timeline.initial)]
    steps += [(False, p.entry, p.changes) for p in timeline.points()]  # (at t = 0, entry, ...)
    for initial, entry, changes in steps:
        last: dict[str, Change] = {}
        for change in changes:
            template = world.leaves[change.leaf].template
            if not initial and change.param in template.fixed_once_running:
                raise error(
                    entry,
                    change,
                    f"{change.param} is read only when the run starts; "
                    "set it in set: or in the world",
                )
            values[change.leaf][change.param] = change.value
            last[change.leaf] = change
        for leaf, change in last.items():
            try:
                world.leaves[leaf].template.check_params(values[leaf])
            except ValueError as exc:
                raise error(entry, change, str(exc)) from None
