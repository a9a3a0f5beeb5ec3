"""A run directory read as data: never importing a module its files name.

A run directory is what users share -- a colleague's failing run, a CI artefact -- so opening
one (``plot``, ``view``, ``monitor``, ``adapt`` over a sweep's kept runs) must never run
code. Loading its ``scenario.yaml`` as a scenario would: building the world imports every
``template: module:Class`` it names. This module is the one way readers get at a run's world
instead. The resolved ``scenario.yaml`` is read as YAML data, checked for its shape by the
world schema; a built-in template resolves from the package's own registry (its declared
parameters judge the written values, its outputs name the world's buffers); any other
template -- a ``module:Class`` or an installed plugin's name -- is *not* imported: it is named
in one warning line, and its leaf keeps only what the run's own files declare (the written
parameters that are finite numbers, the trace's columns). Nothing here reaches
:func:`~amsa_phys.model.template.resolve_template` for a name outside
:data:`~amsa_phys.model.template.BUILTINS`.

API::

    run = read_run(rundir)            # metrics judged, trace path, world (or None), notes
    world = read_world(scenario_yaml, trace_columns)   # the world alone
    timeline = timeline_of(run.resolved)  # its Timeline (values as written)
    kept_runs(sweepdir)               # a sweep's kept run directories, for read_run

Warnings go to ``warn`` (default: one line on stderr, terminal-safe) and are kept in
``RunDir.notes``.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import ConfigError, one_line
from ..model import schema
from ..model.changes import Change
from ..model.template import BUILTINS, Kind, Template, resolve_template
from ..model.timeline import Phase, Step, Timeline
from ..model.worldspec import DEFAULT_FREQ_HZ, PHYSICS_DEFAULTS
from ..model.yamlio import YamlDoc, load_yaml

#: the warning's words, after "FILE: KEY: names module M" (tests and docs quote them)
NOT_IMPORTED = "not imported: a run directory is data"

Warn = Callable[[str], None]


def _stderr(line: str) -> None:
    print(f"warning: {one_line(line)}", file=sys.stderr)


@dataclass(frozen=True)
class TemplateRef:
    """A leaf's template as a run directory names it: the built-in class, or only its name."""

    ref: str
    #: the built-in template class; None for a name that is not built in (never imported)
    cls: type[Template] | None

    def name(self) -> str:
        """The name readers compare against (``GPS``, ``frictionZone``; else the ref)."""
        return self.cls.name() if self.cls is not None else self.ref

    @property
    def builtin(self) -> bool:
        """Whether the template is one of the package's own."""
        return self.cls is not None

    @property
    def marks(self) -> tuple[Any, ...]:
        """What the built-in template declares the pictures draw of it (``Template.marks``);
        none for a template not imported: its own declaration is never read."""
        return self.cls.marks if self.cls is not None else ()

    def param(self, name: str) -> Any:
        """The built-in template's declared parameter ``name`` (KeyError when not imported)."""
        if self.cls is None:
            raise KeyError(name)
        return self.cls.param(name)


@dataclass(frozen=True)
class RunLeaf:
    """A leaf of a run's world, as data: what the plots and the replay read of it."""

    path: str
    template: TemplateRef
    params: dict[str, Any]
    #: input port -> absolute ``Producer.output`` (scoped references resolved)
    inputs: dict[str, str]
    freq: Fraction

    @property
    def kind(self) -> Kind | None:
        """The built-in template's kind (None when the template was not imported)."""
        return self.template.cls.kind if self.template.cls is not None else None


@dataclass(frozen=True)
class RunWorld:
    """A run's world as data: physics settings, leaves, and buffer names in world order."""

    name: str
    physics: dict[str, Any]
    leaves: dict[str, RunLeaf]
    buffers: list[str]
    #: the resolved scenario it was read from, as plain data (the plots read its zones
    #: and their changes without parsing the file again)
    resolved: Any = field(default=None, repr=False, compare=False)


@dataclass
class RunDir:
    """A run directory, read: its judged metrics, its trace's path, its world."""

    path: Path
    metrics: dict[str, Any]
    trace: Path
    #: the resolved scenario.yaml as plain data (None when absent and not required)
    resolved: dict[str, Any] | None
    #: the world it declares (None when scenario.yaml is absent and not required)
    world: RunWorld | None
    notes: list[str] = field(default_factory=list)


def refuse_sweep_dir(rundir: Path, verb: str) -> None:
    """Refuse a sweep's directory where one run is wanted, naming a kept run to give instead.

    A sweep directory and a run directory sit side by side under ``runs/``; a user who gives
    the one for the other should learn what to give, not that the directory "is not a run".
    """
    if (rundir / "results.csv").is_file() and not (rundir / "trace.csv").exists():
        kept = sorted(p.name for p in (rundir / "runs").glob("*") if (p / "trace.csv").is_file())
        hint = (
            f" (kept runs: {rundir / 'runs' / kept[0]} ...)"
            if kept
            else " (it kept no run: sweep again with --keep-runs)"
        )
        raise ConfigError(f"a sweep directory: {verb} one of its kept runs{hint}", file=rundir)


def read_run(
    rundir: Path,
    *,
    need_scenario: bool = True,
    warn: Warn | None = None,
) -> RunDir:
    """Read ``rundir`` (trace.csv, metrics.json, scenario.yaml) without importing anything
    it names. Refuses, with one line naming the file, a missing directory or file and
    metrics that are not a run's (:func:`amsa_phys.runs.runfiles.read_metrics`).
    With ``need_scenario=False`` a missing scenario.yaml gives ``world=None``."""
    from .runfiles import read_metrics, trace_header

    if not rundir.is_dir():
        raise ConfigError(
            "no such directory" if not rundir.exists() else "not a directory", file=rundir
        )
    names = ("trace.csv", "metrics.json", *(("scenario.yaml",) if need_scenario else ()))
    for name in names:
        if not (rundir / name).is_file():
            raise ConfigError(f"not a run directory: {name} is missing", file=rundir)
    metrics = read_metrics(rundir / "metrics.json")
    trace = rundir / "trace.csv"
    notes: list[str] = []

    def note(line: str) -> None:
        notes.append(line)
        (warn or _stderr)(line)

    resolved = world = None
    if (rundir / "scenario.yaml").is_file():
        doc = load_yaml(rundir / "scenario.yaml")
        resolved = doc.data if isinstance(doc.data, dict) else None
        if resolved is None:
            raise doc.error((), "not a resolved scenario: expected a mapping")
        world = _checked_world(doc, trace_header(trace), note)
    return RunDir(rundir, metrics, trace, resolved, world, notes)


def _checked_world(doc: YamlDoc, trace_columns: Sequence[str], warn: Warn) -> RunWorld:
    """:func:`world_of` a resolved scenario checked first as a scenario (its keys and their
    shapes) and after for what it sets on built-in templates: a hand edit is refused with
    its line and key, as ``amsa-phys validate`` refuses it."""
    if not isinstance(doc.data, dict):
        raise doc.error((), "not a resolved scenario: expected a mapping")
    schema.validate(doc.data, schema.SCENARIO, doc)
    world = world_of(doc, trace_columns, warn)
    _check_sets(doc, doc.data, world)
    return world


def _check_sets(doc: YamlDoc, resolved: dict[str, Any], world: RunWorld) -> None:
    """Each value ``set:`` and the timeline give a parameter of a built-in template, judged by
    the template's own parameter (a number where a number is declared, within its range);
    a parameter of a template that is not built in, or a key naming no leaf, is left as
    written (judging it would need the template's code, which a reader never imports)."""
    places: list[tuple[tuple[Any, ...], Any]] = [(("set",), resolved.get("set"))]
    places += [
        (("timeline", i, "set"), entry.get("set"))
        for i, entry in enumerate(resolved.get("timeline") or [])
    ]
    for where, values in places:
        for key, value in (values or {}).items():
            leaf_path, _, param = str(key).rpartition(".")
            leaf = world.leaves.get(leaf_path)
            cls = leaf.template.cls if leaf is not None else None
            if cls is None:
                continue
            declared = {p.name: p for p in cls.params}
            name = cls.canonical(param)
            if name not in declared:
                raise doc.error((*where, key), f"unknown parameter of template {leaf.template.ref}")
            try:
                declared[name].coerce(value)
            except ValueError as exc:
                raise doc.error((*where, key), str(exc)) from None


def timeline_of(resolved: Any) -> Timeline:
    """The :class:`~amsa_phys.model.timeline.Timeline` a resolved ``scenario.yaml`` holds,
    read as data: ``set:`` as phase 0, each ``timeline:`` entry a phase or a step inside one
    (``new_phase: false``), every value as written (no template is asked to judge it, so
    nothing is imported). An entry that is not well formed (a hand edit of a shared run
    directory) is left out rather than refused: readers draw what they can. Without a
    readable ``duration`` the run is taken to end at its last change.
    """
    data = resolved if isinstance(resolved, dict) else {}
    phases = [Phase(Fraction(0), _changes(data.get("set")))]
    for i, entry in enumerate(data.get("timeline") or []):
        at = _instant(entry.get("at")) if isinstance(entry, dict) else None
        if at is None or at <= 0:
            continue
        changes, label = _changes(entry.get("set")), str(entry.get("label") or "")
        if entry.get("new_phase", True) is False:
            step = Step(at, changes, label, entry=i)
            phases[-1] = Phase(
                phases[-1].at,
                phases[-1].changes,
                phases[-1].label,
                [*phases[-1].within, step],
                phases[-1].entry,
            )
        else:
            phases.append(Phase(at, changes, label, entry=i))
    last = max([p.at for p in phases] + [s.at for p in phases for s in p.within])
    duration = _instant(data.get("duration"))
    return Timeline.of(phases, duration if duration is not None and duration > last else last)


def _instant(value: Any) -> Fraction | None:
    """``at:`` or ``duration:`` as an exact number (``"61/4"`` too); None if it is none."""
    try:
        return Fraction(str(value)) if isinstance(value, int | float | str) else None
    except (ValueError, ZeroDivisionError):
        return None


def _changes(said: Any) -> list[Change]:
    """``{Leaf.param: value}`` as changes, values as written."""
    if not isinstance(said, dict):
        return []
    out = []
    for key, value in said.items():
        leaf, _, param = str(key).rpartition(".")
        if leaf and param:
            out.append(Change(leaf, param, value))
    return out


def read_world(path: Path, trace_columns: Sequence[str] = (), warn: Warn | None = None) -> RunWorld:
    """The world of a resolved ``scenario.yaml`` at ``path``, as data (see the module),
    the file checked as :func:`read_run` checks it."""
    return _checked_world(load_yaml(path), trace_columns, warn or _stderr)


def world_of(doc: YamlDoc, trace_columns: Sequence[str], warn: Warn) -> RunWorld:
    """The world of a loaded resolved scenario; ``trace_columns`` name the outputs of the
    templates that were not imported."""
    data = doc.data
    world = data.get("world") if isinstance(data, dict) else None
    if not isinstance(world, dict):
        raise doc.error(("world",), "not a resolved scenario: the world is not written out")
    schema.validate(world, schema.WORLD, doc, ("world",))
    leaves: dict[str, RunLeaf] = {}
    bodies: dict[str, tuple[dict[str, Any], tuple[Any, ...]]] = {}
    said: set[str] = set()

    def walk(comps: dict[str, Any], prefix: str, kp: tuple[Any, ...]) -> None:
        for name, body in comps.items():
            path = f"{prefix}.{name}" if prefix else name
            here = (*kp, name)
            if "components" in body:
                if "count" in body:
                    raise doc.error(
                        (*here, "count"), "not a resolved scenario: copies not written out"
                    )
                walk(body["components"], path, (*here, "components"))
                continue
            leaves[path] = _leaf(doc, path, body, here, warn, said)
            bodies[path] = (body, here)

    walk(world["components"], "", ("world", "components"))
    for path, (body, _) in bodies.items():
        leaves[path].inputs.update(_absolute_inputs(path, body.get("inputs") or {}, leaves))
    return RunWorld(
        name=str(world.get("name", "")),
        physics=_merge(PHYSICS_DEFAULTS, world.get("physics") or {}),
        leaves=leaves,
        buffers=_buffers(leaves, trace_columns),
        resolved=data,
    )


def _leaf(
    doc: YamlDoc, path: str, body: dict[str, Any], kp: tuple[Any, ...], warn: Warn, said: set[str]
) -> RunLeaf:
    ref = str(body["template"])
    cls = resolve_template(ref) if ref in BUILTINS else None
    if cls is None and ref not in said:
        said.add(ref)
        module = ref.partition(":")[0] if ":" in ref else None
        what = f"names module {module}" if module else f"names template {ref} (not built in)"
        warn(f"{doc.path}: {'.'.join(map(str, (*kp, 'template')))}: {what}; {NOT_IMPORTED}")
    try:
        freq = Fraction(str(body.get("freq", DEFAULT_FREQ_HZ)))
    except (ValueError, ZeroDivisionError):
        raise doc.error((*kp, "freq"), "not a frequency") from None
    written = body.get("params") or {}
    if cls is None:  # judged by no template: only finite numbers are kept (a body's size)
        params = {
            str(k): v
            for k, v in written.items()
            if isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
        }
    else:
        declared = {p.name: p for p in cls.params}
        params = {name: p.default for name, p in declared.items()}
        for key, value in written.items():
            name = cls.canonical(key)
            if name not in declared:
                raise doc.error((*kp, "params", key), f"unknown parameter of template {ref}")
            try:
                params[name] = declared[name].coerce(value)
            except ValueError as exc:
                raise doc.error((*kp, "params", key), str(exc)) from None
    return RunLeaf(path, TemplateRef(ref, cls), params, {}, freq)


def _absolute_inputs(
    consumer: str, inputs: dict[str, Any], leaves: dict[str, RunLeaf]
) -> dict[str, str]:
    """``port -> Producer.output`` with each producer found from the consumer's scope
    outwards, as the world's own linking does; a reference naming no leaf is kept as written."""
    out = {}
    for port, ref in inputs.items():
        comp, _, output = str(ref).rpartition(".")
        scope = consumer.split(".")[:-1]
        found = None
        while found is None:
            candidate = ".".join([*scope, comp])
            if candidate in leaves:
                found = candidate
            elif not scope:
                break
            else:
                scope.pop()
        out[str(port)] = f"{found}.{output}" if found else str(ref)
    return out


def _buffers(leaves: dict[str, RunLeaf], trace_columns: Sequence[str]) -> list[str]:
    """Every buffer name in world order: a built-in's declared outputs (an array port as
    its traced elements), a not-imported template's traced columns."""
    out: list[str] = []
    for path, leaf in leaves.items():
        traced = [c for c in trace_columns if c.startswith(path + ".")]
        if leaf.template.cls is None:
            out += [c for c in traced if "." not in c[len(path) + 1 :]]
            continue
        for port in leaf.template.cls.outputs:
            name = f"{path}.{port.name}"
            if port.array:
                out += [c for c in traced if c.startswith(name + "[")]
            else:
                out.append(name)
    return out


def _merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    out = dict(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = value
    return out


def kept_runs(sweepdir: Path) -> list[Path]:
    """A sweep directory's kept runs (``--keep-runs``), each a run directory for
    :func:`read_run`; the sweep's own files (results.csv) name no module."""
    return sorted(p for p in (sweepdir / "runs").glob("*") if (p / "trace.csv").is_file())
