"""A run's ``metrics.json`` judged on reading: what ``plot`` and ``view`` may trust of it.

A run directory comes from anywhere (a colleague, a CI artefact, an editor), so every field
a reader uses is checked here once, with one line naming the file and the key (exit 2),
rather than trusted where it is drawn: an event that is a string, an event time of ``"x"``,
NaN or 1e308, a phase's ``set`` holding a list of lists, a phase that starts after the run's
length limit. Times must be finite and within ``[0, MAX_DURATION_S]`` (the limit a
scenario's ``duration:`` has); the file is read only if it is a regular file of at most
:data:`MAX_METRICS_BYTES`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..model.metrics import METRICS
from ..model.schema import MAX_DURATION_S
from ..model.yamlio import parse_json, read_regular_file

#: the largest metrics.json read (a run's own is kilobytes; thousands of events, megabytes)
MAX_METRICS_BYTES = 64 << 20


def read_metrics(path: Path) -> dict[str, Any]:
    """A run's ``metrics.json``, checked for what the plots and the replay read (one line
    naming the file and the key if it is not)."""
    raw = read_regular_file(Path(path), MAX_METRICS_BYTES, "a run's metrics.json")
    metrics = parse_json(raw, path)
    why = metrics_problem(metrics)
    if why is not None:
        raise ConfigError(f"not a run's metrics: {why}", file=path)
    return metrics


def metrics_problem(metrics: Any) -> str | None:
    """What is wrong with ``metrics`` for a reader (None if nothing), naming the key."""
    if not isinstance(metrics, dict):
        return f"expected an object, got {type(metrics).__name__}"
    for key in ("duration", "simulated"):
        if key in metrics and (why := _time_problem(metrics[key])):
            return f"{key} {why}"
    if "scenario" in metrics and not isinstance(metrics["scenario"], str | None):
        return "scenario is not text"
    if not isinstance(metrics.get("overall", {}), dict | None):
        return "overall is not an object"
    if (why := _values_problem(metrics.get("overall"))) is not None:
        return f"overall{why}"
    phases = metrics.get("phases", [])
    if not isinstance(phases, list):
        return "phases is not a list"
    for i, phase in enumerate(phases):
        if (why := _phase_problem(phase)) is not None:
            return f"phases[{i}]{why}"
    events = metrics.get("events", [])
    if not isinstance(events, list | None):
        return "events is not a list"
    for i, event in enumerate(events or []):
        if (why := _event_problem(event)) is not None:
            return f"events[{i}]{why}"
    quality = metrics.get("quality")
    if quality is not None:
        if not isinstance(quality, dict) or not isinstance(quality.get("signal"), str):
            return "quality is not an object with a signal"
        for key in ("reference", "tolerance"):
            if not _finite(quality.get(key)):
                return f"quality.{key} is not a finite number"
        if quality.get("dwell") is not None and _time_problem(quality["dwell"]):
            return "quality.dwell is not a time in seconds"
    return None


def _phase_problem(phase: Any) -> str | None:
    if not isinstance(phase, dict):
        return " is not an object"
    if (why := _time_problem(phase.get("start"))) is not None:
        return f".start {why}"
    if "end" in phase and phase["end"] is not None and (why := _time_problem(phase["end"])):
        return f".end {why}"
    if "label" in phase and not isinstance(phase["label"], str | None):
        return ".label is not text"
    if (why := _values_problem(phase)) is not None:
        return why
    if (why := _set_problem(phase.get("set", {}))) is not None:
        return f".set{why}"
    changes = phase.get("changes", [])
    if not isinstance(changes, list | None):
        return ".changes is not a list"
    for j, change in enumerate(changes or []):
        if not isinstance(change, dict):
            return f".changes[{j}] is not an object"
        if (why := _time_problem(change.get("at"))) is not None:
            return f".changes[{j}].at {why}"
        if "label" in change and not isinstance(change["label"], str | None):
            return f".changes[{j}].label is not text"
        if (why := _set_problem(change.get("set", {}))) is not None:
            return f".changes[{j}].set{why}"
    return None


def _values_problem(block: Any) -> str | None:
    """A block's metrics (``max_distance``, ``settling_time``, ...): each a number, or null
    for one never reached (a settling time); ``partial`` a flag."""
    if not isinstance(block, dict):
        return None
    for key in METRICS:
        if key in block and block[key] is not None and not _number(block[key]):
            return f".{key} is not a number"
    if "partial" in block and not isinstance(block["partial"], bool):
        return ".partial is not true or false"
    return None


def _set_problem(values: Any) -> str | None:
    """A ``set``: parameter key -> a value a parameter can hold (number, text, flag, or a
    list of numbers or of points)."""
    if not isinstance(values, dict | None):
        return " is not an object"
    for key, value in (values or {}).items():
        if not _settable(value, depth=0):
            return f".{key} is not a parameter value"
    return None


def _settable(value: Any, depth: int) -> bool:
    if value is None or isinstance(value, str | bool | int):
        return True
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, list) and depth < 2:
        return all(_settable(v, depth + 1) for v in value)
    return False


def _event_problem(event: Any) -> str | None:
    if not isinstance(event, dict):
        return f" is not an object (got {type(event).__name__})"
    if (why := _time_problem(event.get("t"))) is not None:
        return f".t {why}"
    if not isinstance(event.get("kind"), str):
        return ".kind is not text"
    if "detail" in event and not isinstance(event["detail"], str | None):
        return ".detail is not text"
    return None


def _time_problem(value: Any) -> str | None:
    """Why ``value`` is not an instant of a run (None if it is)."""
    if not _number(value):
        return "is not a number"
    if not math.isfinite(value):
        return f"is not finite ({value})"
    if not 0 <= value <= MAX_DURATION_S:
        return f"is outside 0..{MAX_DURATION_S:,} s ({value:g})"
    return None


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _finite(value: Any) -> bool:
    return _number(value) and math.isfinite(value)


def trace_header(path: Path) -> list[str]:
    """The column names on a trace's first line (at most 16 MiB read: a header, not a file)."""
    with open(path, "rb") as fh:
        return fh.readline(16 << 20).decode("utf-8", "replace").rstrip("\n").split(",")
