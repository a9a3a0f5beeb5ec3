"""A scenario file: a world plus a timed sequence of parameter changes (the paper's 2.1).

Each timeline entry starts a new phase; phase 0 starts at t = 0 with the ``set`` values.
Every value is judged by the parameter's own ``Param.coerce``, with file, line and key.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

import yaml

from ..errors import ConfigError
from . import schema
from .suggest import did_you_mean
from .template import Kind
from .world import WorldSpec, build_world, load_world
from .yamlio import KeyPath, YamlDoc, load_yaml

#: Metrics an ``expect`` entry may name (see engine/metrics.py), in the order of the columns
#: of a sweep's ``results.csv``.
METRICS = (
    "max_distance",
    "min_distance",
    "mean_error",
    "rms_error",
    "settling_time",
    "final_distance",
    "collisions",
)

DEFAULT_LOG_RATE_HZ = 20
DEFAULT_TOLERANCE = 1.5


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


@dataclass
class Phase:
    """A phase of the scenario: from ``at`` (phase 0 at 0) with the changes made then."""

    at: Fraction
    changes: list[Change]
    label: str = ""


@dataclass
class Quality:
    """The quality-of-control signal (a Data buffer) and its reference and tolerance."""

    signal: str
    reference: float
    tolerance: float


@dataclass
class Expectation:
    """A bound on a run.

    Either ``metric`` (overall, or of ``phase``) must be ``below`` and/or ``above`` a bound,
    or every sample of the Data ``trace`` in [``after``, ``before``] must be.
    """

    metric: str | None
    phase: int | None
    below: float | None
    above: float | None
    line: int | None
    trace: str | None = None
    after: float | None = None
    before: float | None = None


@dataclass
class Scenario:
    """A loaded, checked scenario."""

    path: Path
    name: str
    world: WorldSpec
    duration: Fraction
    seed: int
    log_rate: Fraction
    quality: Quality | None
    phases: list[Phase]
    expect: list[Expectation] = field(default_factory=list)
    data: dict[str, Any] = field(default_factory=dict)


def load_scenario(
    path: str | Path,
    overrides: list[str] | None = None,
    seed: int | None = None,
    duration: float | None = None,
    log_rate: float | None = None,
) -> Scenario:
    """Load a scenario; command-line overrides are judged like file values."""
    doc = load_yaml(path)
    # with overrides, the rules are checked once they are in: a --set may repair the file
    scenario = build_scenario(doc, check_rules=not overrides)
    if seed is not None:
        scenario.seed = seed
    if duration is not None:
        scenario.duration = _positive_fraction(duration, "--duration")
        scenario.phases = [p for p in scenario.phases if p.at < scenario.duration]
    if log_rate is not None:
        scenario.log_rate = _positive_fraction(log_rate, "--log-rate")
    in_file = len(scenario.phases[0].changes)
    for text in overrides or []:
        scenario.phases[0].changes.append(parse_override(text, scenario.world))
    if overrides:
        check_phases(scenario, doc, in_file)
    scenario.log_rate = _effective_log_rate(scenario.log_rate, scenario.world)
    return scenario


def build_scenario(doc: YamlDoc, check_rules: bool = True) -> Scenario:
    """Check a scenario document and build it (the world loaded or inlined).

    ``check_rules`` runs :func:`check_phases`; a caller that still adds changes to phase 0
    runs it afterwards instead.
    """
    data = doc.data
    schema.validate(data, schema.SCENARIO, doc)
    world_ref = data["world"]
    if isinstance(world_ref, str):
        world_path = doc.path.parent / world_ref
        if world_path.is_dir():
            raise doc.error(("world",), f"{world_path} is a directory, expected a world file")
        if not world_path.is_file():
            raise doc.error(("world",), f"world file not found: {world_path}")
        world = load_world(world_path)
    else:
        world = build_world(world_ref, doc, ("world",))
    duration = Fraction(str(data["duration"]))
    if duration <= 0:
        raise doc.error(("duration",), f"must be > 0, got {data['duration']}")
    phases = [Phase(Fraction(0), _changes(data.get("set", {}), ("set",), doc, world))]
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
        phases.append(
            Phase(
                at,
                _changes(entry["set"], ("timeline", i, "set"), doc, world),
                entry.get("label", ""),
            )
        )
    quality = None
    if "quality" in data:
        q = data["quality"]
        if q["signal"] not in world.buffers:
            raise doc.error(
                ("quality", "signal"),
                f"unknown Data {q['signal']!r}" + did_you_mean(q["signal"], world.buffers),
            )
        quality = Quality(
            q["signal"], float(q["reference"]), float(q.get("tolerance", DEFAULT_TOLERANCE))
        )
    expect = []
    for i, e in enumerate(data.get("expect", [])):
        kp = ("expect", i)
        if ("metric" in e) == ("trace" in e):
            raise doc.error(kp, "give exactly one of 'metric' or 'trace'")
        if "trace" in e:
            if e["trace"] not in world.buffers:
                raise doc.error(
                    (*kp, "trace"),
                    f"unknown Data {e['trace']!r}" + did_you_mean(e["trace"], world.buffers),
                )
            if "phase" in e:
                raise doc.error((*kp, "phase"), "a trace check takes after/before, not phase")
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
        if "phase" in e and e["phase"] >= len(phases):
            raise doc.error(
                (*kp, "phase"),
                f"phase {e['phase']} does not exist "
                f"(the scenario has {len(phases)} phases, 0..{len(phases) - 1})",
            )
        if quality is None:
            raise doc.error(kp, "metric expectations need a quality: section")
        expect.append(
            Expectation(e["metric"], e.get("phase"), e.get("below"), e.get("above"), doc.line(kp))
        )
    scenario = Scenario(
        path=doc.path,
        name=str(data.get("name", doc.path.stem)),
        world=world,
        duration=duration,
        seed=int(data.get("seed", 0)),
        log_rate=Fraction(str(data.get("log_rate", DEFAULT_LOG_RATE_HZ))),
        quality=quality,
        phases=phases,
        expect=expect,
        data=data,
    )
    if check_rules:
        check_phases(scenario, doc)
    return scenario


def check_phases(scenario: Scenario, doc: YamlDoc | None, in_file: int | None = None) -> None:
    """Refuse a scenario whose phases would break a template's rules, before anything runs.

    Each leaf's values are followed through the phases: after every phase, a leaf it changed
    must pass its template's ``check_params`` (powerMin <= powerMax, ...), and a timeline
    entry must not change a parameter read only by ``initialize`` (a rover's mass: the
    change would fault mid-run). Only the first ``in_file`` changes of phase 0 come from the
    file's ``set``; later ones are ``--set`` overrides and are named as such. Without a
    ``doc`` (a sweep's grid point) the error names the change only.
    """
    world = scenario.world
    values = {path: dict(leaf.params) for path, leaf in world.leaves.items()}

    def error(phase: int, index: int, change: Change, message: str) -> ConfigError:
        if doc is None:
            return ConfigError(message, key=change.written_key)
        if phase == 0 and in_file is not None and index >= in_file:
            return ConfigError(message, key=f"--set {change.written_key}")
        where = ("set",) if phase == 0 else ("timeline", phase - 1, "set")
        return doc.error((*where, change.written_key), message)

    for i, phase in enumerate(scenario.phases):
        last: dict[str, tuple[int, Change]] = {}
        for j, change in enumerate(phase.changes):
            template = world.leaves[change.leaf].template
            if i > 0 and change.param in template.fixed_once_running:
                raise error(
                    i,
                    j,
                    change,
                    f"{change.param} is read only when the run starts; "
                    "set it in set: or in the world",
                )
            values[change.leaf][change.param] = change.value
            last[change.leaf] = (j, change)
        for leaf, (j, change) in last.items():
            try:
                world.leaves[leaf].template.check_params(values[leaf])
            except ValueError as exc:
                raise error(i, j, change, str(exc)) from None


def _changes(sets: dict[str, Any], kp: KeyPath, doc: YamlDoc, world: WorldSpec) -> list[Change]:
    out = []
    for key, value in sets.items():
        try:
            out.append(resolve_change(str(key), value, world))
        except ValueError as exc:
            raise doc.error((*kp, key), str(exc)) from None
    return out


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


def parse_override(text: str, world: WorldSpec) -> Change:
    """``Comp.param=V`` from the command line (V read as a YAML scalar)."""
    key, sep, raw = text.partition("=")
    if not sep:
        raise ConfigError(f"expected Component.parameter=value, got {text!r}", key="--set")
    try:
        value = yaml.safe_load(raw) if raw.strip() else raw
    except yaml.YAMLError:
        value = raw
    try:
        return resolve_change(key.strip(), value, world)
    except ValueError as exc:
        raise ConfigError(str(exc), key=f"--set {key.strip()}") from None


def _positive_fraction(value: float, option: str) -> Fraction:
    if not value > 0 or value != value or value == float("inf"):
        raise ConfigError(f"must be a positive finite number, got {value}", key=option)
    return Fraction(str(value))


def _effective_log_rate(rate: Fraction, world: WorldSpec) -> Fraction:
    """The trace is never sampled slower than the fastest sensor (design.md)."""
    sensors = [leaf.freq for leaf in world.leaves.values() if leaf.kind is Kind.SENSOR]
    return max([rate, *sensors])
