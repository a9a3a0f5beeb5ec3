"""A scenario file: a world plus a timed sequence of parameter changes (the paper's 2.1).

Each timeline entry starts a new phase; phase 0 starts at t = 0 with the ``set`` values.
Every value is judged by the parameter's own ``Param.coerce``, with file, line and key.
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from . import schema, tracecols
from .params import short_repr
from .rates import MAX_RATE_HZ, MIN_RATE_HZ, cycle_problem
from .schema import MAX_SEED
from .suggest import did_you_mean
from .template import Kind
from .timing import TIMING_KEYS, check_phase, set_timing
from .wording import plural
from .world import WorldSpec, build_world, load_world, resolved_values
from .yamlio import MAX_NODES, KeyPath, YamlDoc, load_yaml, parse_value

#: Metrics an ``expect`` entry may name (see engine/metrics.py), in the order of the columns
#: of a sweep's ``results.csv``.
METRICS = (
    "max_distance",
    "min_distance",
    "mean_error",
    "rms_error",
    "settling_time",
    "max_after_approach",
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
class Step:
    """Changes made inside a phase without starting a new one, at ``at``.

    A timeline entry with ``new_phase: false`` and a change made live in the window are
    steps: the phase structure (and so what ``expect: {phase: i}`` means) stays the one the
    scenario's author wrote, however many changes land inside a phase.
    """

    at: Fraction
    changes: list[Change]
    label: str = ""
    entry: int | None = None  # index in the file's ``timeline`` (None: made live)


@dataclass
class Phase:
    """A phase of the scenario: from ``at`` (phase 0 at 0) with the changes made then."""

    at: Fraction
    changes: list[Change]
    label: str = ""
    #: changes inside this phase after its start (``new_phase: false``), in time order
    within: list[Step] = field(default_factory=list)
    entry: int | None = None  # index in the file's ``timeline`` (None: phase 0)


@dataclass
class Quality:
    """The quality-of-control signal (a Data buffer) and its reference and tolerance."""

    signal: str
    reference: float
    tolerance: float
    #: seconds the signal must stay in the band for ``settling_time`` (None: the default,
    #: ``engine/metrics.default_dwell`` of each block)
    dwell: float | None = None


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
    #: when ``--duration`` shortened the run: the file's phase starts followed by its
    #: duration. The phase the run stops in (and the run as a whole) is then cut short: its
    #: metrics are partial and its checks skipped, not judged as if it were complete.
    planned_bounds: list[Fraction] | None = None
    #: ``trace_columns:`` glob patterns (None: trace every Data buffer); see
    #: :func:`traced_columns` for what is kept
    trace_columns: list[str] | None = None


def traced_columns(scenario: Scenario) -> list[str]:
    """The Data buffers the scenario's trace holds, in world order (``model/tracecols``).

    The quality signal and every ``expect: {trace: ...}`` column are always kept: the run
    reads them back.
    """
    required = [e.trace for e in scenario.expect if e.trace]
    if scenario.quality:
        required.append(scenario.quality.signal)
    return tracecols.selected(scenario.trace_columns, list(scenario.world.buffers), required)


def shorten(scenario: Scenario, duration: Fraction) -> None:
    """Run ``scenario`` until ``duration`` instead (``--duration``): later changes drop out.

    A shorter run remembers the file's duration, so the phase it stops in is reported as
    cut short (partial) rather than judged as if it were complete.
    """
    if duration < scenario.duration and scenario.planned_bounds is None:
        scenario.planned_bounds = [p.at for p in scenario.phases] + [scenario.duration]
    scenario.duration = duration
    scenario.phases = [p for p in scenario.phases if p.at < duration]
    for phase in scenario.phases:
        phase.within = [s for s in phase.within if s.at < duration]


def load_scenario(
    path: str | Path,
    overrides: list[str] | None = None,
    seed: int | None = None,
    duration: float | None = None,
    log_rate: float | None = None,
    trace_columns: str | Sequence[str] | None = None,
) -> Scenario:
    """Load a scenario; command-line overrides are judged like file values."""
    return configure_scenario(load_yaml(path), overrides, seed, duration, log_rate, trace_columns)


def configure_scenario(
    doc: YamlDoc,
    overrides: list[str] | None = None,
    seed: int | None = None,
    duration: float | None = None,
    log_rate: float | None = None,
    trace_columns: str | Sequence[str] | None = None,
) -> Scenario:
    """:func:`load_scenario` of a document already parsed (a file, or a mapping given in
    Python: ``amsa_phys.run``), so both judge the options the same way."""
    # with overrides, the rules are checked once they are in: a --set may repair the file
    scenario = build_scenario(doc, check_rules=not overrides)
    if seed is not None:
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
            raise ConfigError(
                f"must be an integer from 0 to {MAX_SEED} (2**63 - 1), like seed: in a "
                f"scenario; got {short_repr(seed)}",
                key="--seed",
            )
        scenario.seed = seed
    if duration is not None:
        shorten(scenario, _positive_fraction(duration, "--duration"))
    if log_rate is not None:
        scenario.log_rate = _positive_fraction(log_rate, "--log-rate")
        if not MIN_RATE_HZ <= scenario.log_rate <= MAX_RATE_HZ:
            raise ConfigError(
                f"{log_rate:g} Hz is outside the rates amsa-phys runs "
                f"({MIN_RATE_HZ:g} to {MAX_RATE_HZ:g} Hz)",
                key="--log-rate",
            )
        why = _cycle_problem(scenario)
        if why is not None:
            raise ConfigError(why, key="--log-rate")
    if trace_columns is not None:
        if isinstance(trace_columns, str):
            patterns = tracecols.parse_patterns(trace_columns)
        elif isinstance(trace_columns, (list, tuple)) and all(
            isinstance(p, str) for p in trace_columns
        ):
            patterns = list(trace_columns)
        else:
            raise ConfigError(
                "expected glob patterns: a comma-separated string or a list of strings, got "
                + short_repr(trace_columns),
                key="--trace-columns",
            )
        if not patterns:
            raise ConfigError(
                "needs at least one pattern, like 'Car*.Gap.*'", key="--trace-columns"
            )
        bad = tracecols.unmatched(patterns, list(scenario.world.buffers))
        if bad:
            raise ConfigError(
                tracecols.no_match_message(bad[0], list(scenario.world.buffers)),
                key="--trace-columns",
            )
        scenario.trace_columns = patterns
    in_file = len(scenario.phases[0].changes)
    for text in overrides or []:
        if text.strip().startswith(PHYSICS_PREFIX):
            scenario.world = with_physics(scenario.world, parse_physics_override(text))
            continue
        change = parse_override(text, scenario.world)
        if change is not None:  # None: a frequency, set on the world's Leaf
            scenario.phases[0].changes.append(change)
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
        if not world_path.exists():
            raise doc.error(
                ("world",), f"world file not found: {world_path}" + _nearby_file(world_path)
            )
        world = load_world(world_path)
    else:
        world = build_world(world_ref, doc, ("world",))
    if "physics" in data:
        world = with_physics(world, data["physics"])
    duration = Fraction(str(data["duration"]))
    if duration <= 0:
        raise doc.error(("duration",), f"must be > 0, got {data['duration']}")
    initial = _changes(data.get("set", {}), ("set",), doc, world, frequencies=True)
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
        changes = _changes(entry["set"], ("timeline", i, "set"), doc, world)
        if entry.get("new_phase", True):
            phases.append(Phase(at, changes, entry.get("label", ""), entry=i))
        else:
            phases[-1].within.append(Step(at, changes, entry.get("label", ""), entry=i))
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
            if "after" in e and "before" in e and e["after"] > e["before"]:
                raise doc.error(
                    (*kp, "before"),
                    f"before ({e['before']:g} s) is earlier than after ({e['after']:g} s): "
                    "the window holds no instant",
                )
            if "after" in e and Fraction(str(e["after"])) > duration:
                raise doc.error(  # it would check nothing and pass (issue 33, 13)
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
        if "phase" in e and e["phase"] >= len(phases):
            raise doc.error(
                (*kp, "phase"),
                f"phase {e['phase']} does not exist "
                f"(the scenario has {plural(len(phases), 'phase')}, "
                + (f"0..{len(phases) - 1})" if len(phases) > 1 else "only phase 0)"),
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
        trace_columns=_trace_patterns(doc, data, world),
    )
    why = _cycle_problem(scenario)
    if why is not None:
        raise doc.error(("log_rate",) if "log_rate" in data else ("world",), why)
    size = written_values(world, data)
    if size > MAX_NODES:
        raise doc.error(
            (),
            f"too large: written out in full (every copy and parameter) the scenario holds "
            f"{size:,} values, over the limit of {MAX_NODES:,}",
        )
    if check_rules:
        check_phases(scenario, doc)
    return scenario


def _nearby_file(path: Path) -> str:
    """`` (did you mean x.yaml?)`` for a YAML file beside ``path`` with a close name
    (``x.yml`` for ``x.yaml``, a typo in the stem); empty if there is none."""
    try:
        names = [p.name for p in path.parent.iterdir() if p.suffix in (".yaml", ".yml")]
    except OSError:
        return ""
    same_stem = [n for n in names if Path(n).stem == path.stem]
    return f" (did you mean {same_stem[0]}?)" if same_stem else did_you_mean(path.name, names)


def _cycle_problem(scenario: Scenario) -> str | None:
    """Why the world's rates with the trace's cannot be scheduled (``model/rates.py``)."""
    world = scenario.world
    rates = [leaf.freq for leaf in world.leaves.values()]
    rates += [Fraction(str(world.physics["rate"])), _effective_log_rate(scenario.log_rate, world)]
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

    def error(entry: int | None, index: int, change: Change, message: str) -> ConfigError:
        if doc is None:
            return ConfigError(message, key=change.written_key)
        if entry is None and in_file is not None and index >= in_file:
            return ConfigError(message, key=f"--set {change.written_key}")
        where = ("set",) if entry is None else ("timeline", entry, "set")
        return doc.error((*where, change.written_key), message)

    steps: list[tuple[bool, int | None, list[Change]]] = []  # (at t = 0, entry, changes)
    for i, phase in enumerate(scenario.phases):
        steps.append((i == 0, phase.entry, phase.changes))
        steps += [(False, s.entry, s.changes) for s in phase.within]
    for initial, entry, changes in steps:
        last: dict[str, tuple[int, Change]] = {}
        for j, change in enumerate(changes):
            template = world.leaves[change.leaf].template
            if not initial and change.param in template.fixed_once_running:
                raise error(
                    entry,
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
                raise error(entry, j, change, str(exc)) from None


def _changes(
    sets: dict[str, Any], kp: KeyPath, doc: YamlDoc, world: WorldSpec, frequencies: bool = False
) -> list[Change]:
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
                set_frequency(str(key), value, world)
                continue
            out.append(resolve_change(str(key), value, world))
        except ValueError as exc:
            raise doc.error((*kp, key), str(exc)) from None
    return out


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


def set_frequency(key: str, value: Any, world: WorldSpec) -> None:
    """Give a Leaf another frequency (``set: {Leaf.freq: 4}``) or timing for the whole run.

    A value the world leaves to the scenario: an imported AMSA model whose Leaf has no
    frequency runs at the metamodel's 10 Hz unless a scenario says otherwise. The world's
    Leaf itself changes, so the resolved scenario writes the value into its world.
    """
    leaf_path, _, name = key.rpartition(".")
    leaf = world.leaves[leaf_path]
    if name != "freq":
        set_timing(leaf.timing, name, value, leaf.freq)
        return
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
    leaf.freq = freq


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


def parse_override(text: str, world: WorldSpec) -> Change | None:
    """``Comp.param=V`` from the command line (V read as a YAML scalar).

    ``Leaf.freq=V`` sets the Leaf's frequency on ``world`` and returns None.
    """
    key, sep, raw = text.partition("=")
    if not sep:
        raise ConfigError(f"expected Component.parameter=value, got {text!r}", key="--set")
    value = parse_value(raw, f"--set {key.strip()}")
    try:
        if is_frequency(key.strip(), world):
            set_frequency(key.strip(), value, world)
            return None
        return resolve_change(key.strip(), value, world)
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


def _positive_fraction(value: float, option: str) -> Fraction:
    if not value > 0 or value != value or value == float("inf"):
        raise ConfigError(f"must be a positive finite number, got {value}", key=option)
    return Fraction(str(value))


def _effective_log_rate(rate: Fraction, world: WorldSpec) -> Fraction:
    """The trace is never sampled slower than the fastest sensor (design.md)."""
    sensors = [leaf.freq for leaf in world.leaves.values() if leaf.kind is Kind.SENSOR]
    return max([rate, *sensors])


def _trace_patterns(doc: YamlDoc, data: dict[str, Any], world: WorldSpec) -> list[str] | None:
    """``trace_columns:``, each pattern checked to keep at least one buffer."""
    if "trace_columns" not in data:
        return None
    raw = data["trace_columns"]
    if isinstance(raw, str):  # "Car*.Gap.*, Leader.*", as --trace-columns takes it
        patterns = tracecols.parse_patterns(raw)
        if not patterns:
            raise doc.error(("trace_columns",), "needs at least one pattern, like 'Car*.Gap.*'")
        for pattern in patterns:
            if tracecols.unmatched([pattern], list(world.buffers)):
                raise doc.error(
                    ("trace_columns",), tracecols.no_match_message(pattern, list(world.buffers))
                )
        return patterns
    patterns = [str(p) for p in raw]
    for i, pattern in enumerate(patterns):
        if tracecols.unmatched([pattern], list(world.buffers)):
            raise doc.error(
                ("trace_columns", i), tracecols.no_match_message(pattern, list(world.buffers))
            )
    return patterns
