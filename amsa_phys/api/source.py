"""A scenario from Python: a file path or a mapping, with the CLI's options as arguments.

Everything goes through the loader the CLI uses (``model.scenario.configure_scenario``), so
a value is judged the same way and an error is the same one-line message. Two choices:

* ``set={"Comp.param": value}`` is turned into the CLI's ``--set Comp.param=value`` text
  (the value written as a one-line YAML scalar or list, which reads back as the same value)
  and parsed by the CLI's own code: the API's overrides cannot drift from ``--set``.
* A mapping has no file: its errors name ``<mapping>`` (no line), and a relative ``world:``
  path is resolved against ``base_dir`` (default: the current directory when the call is
  made). Python values that YAML has no word for are converted first: tuples become lists,
  numpy scalars numbers, paths strings and fractions exact ``"n/d"`` times.
"""

from __future__ import annotations

import functools
import math
import operator
import os
import sys
import warnings
from collections.abc import Callable, Mapping, Sequence
from fractions import Fraction
from pathlib import Path
from typing import Any, ParamSpec, TypeVar

import yaml

from ..errors import ConfigError
from ..model.params import short_repr
from ..model.scenario import (
    Scenario,
    build_scenario,
    configure_scenario,
    load_scenario,
    without_adapt,
)
from ..model.world import build_world
from ..model.yamlio import MAX_DEPTH, MAX_NODES, KeyPath, YamlDoc, dotted, load_yaml
from ..runs.overrides import OverrideWarning, timeline_notes
from ..runs.references import ReferenceWarning, reference_notes

#: What errors in a scenario given as a mapping name instead of a file.
MAPPING = "<mapping>"

Source = str | os.PathLike[str] | Mapping[str, Any]

_P = ParamSpec("_P")
_R = TypeVar("_R")


def api_errors(func: Callable[_P, _R]) -> Callable[_P, _R]:
    """``func`` with its ConfigErrors worded for Python: ``set={"Comp.param": ...}``,
    ``duration=``, not the CLI's ``--set``/``--duration`` (``ConfigError.worded_for_api``).

    The loader names an option as the CLI spells it; this is the API's front door saying
    it the way a Python user passed it. Rewording twice (``run`` calls ``load``) is harmless.
    """

    @functools.wraps(func)
    def worded(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        try:
            return func(*args, **kwargs)
        except ConfigError as err:
            err.worded_for_api()
            raise

    return worded


class MappingDoc(YamlDoc):
    """A scenario given as a Python mapping: errors name ``<mapping>`` and the key path."""

    def error(self, keypath: KeyPath, message: str) -> ConfigError:
        """A ConfigError at ``keypath`` of the mapping (there is no line to give)."""
        return ConfigError(message, file=MAPPING, key=dotted(keypath))


@api_errors
def load(
    source: Source,
    *,
    seed: int | None = None,
    duration: float | Fraction | None = None,
    set: Mapping[str, Any] | None = None,  # the CLI's --set, by its name
    log_rate: float | None = None,
    trace_columns: str | Sequence[str] | None = None,
    base_dir: str | os.PathLike[str] | None = None,
    adapt: bool = True,
) -> Scenario:
    """Load and check a scenario as ``amsa-phys run`` would, without running it.

    ``source`` is a scenario file or a mapping of the same shape; the keyword arguments are
    the CLI's ``--seed``, ``--duration``, ``--set``, ``--log-rate`` and ``--trace-columns``
    (a comma-separated string or a list of patterns; errors name those options, exactly as
    the CLI prints them); ``adapt=False`` is ``--no-adapt``. Raises
    :class:`~amsa_phys.errors.ConfigError`.
    """
    adapt = switch(adapt, "adapt")
    scenario = _load(source, seed, duration, set, log_rate, trace_columns, base_dir)
    return scenario if adapt else without_adapt(scenario)


def switch(value: Any, name: str) -> bool:
    """A True-or-False argument (``adapt``, ``progress``): ``adapt="no"``, a true string,
    kept the scenario's rules on. numpy's bool is taken (without importing numpy here)."""
    if isinstance(value, bool):
        return value
    dtype = getattr(value, "dtype", None)
    if getattr(dtype, "kind", None) == "b" and getattr(value, "shape", None) == ():
        return bool(value)
    raise ConfigError(f"expected True or False, got {short_repr(value)}", key=f"{name}=")


def _load(
    source: Source,
    seed: int | None,
    duration: float | Fraction | None,
    set: Mapping[str, Any] | None,
    log_rate: float | None,
    trace_columns: str | Sequence[str] | None,
    base_dir: str | os.PathLike[str] | None,
) -> Scenario:
    """:func:`load` before ``adapt``."""
    overrides = [override_text(key, value) for key, value in _set_items(set)]
    seed = _seed(seed)
    dur = None if duration is None else _number(duration, "--duration")
    rate = None if log_rate is None else _number(log_rate, "--log-rate")
    if isinstance(source, Mapping):
        doc = mapping_doc(source, base_dir)
        scenario = configure_scenario(doc, overrides, seed, dur, rate, trace_columns)
    elif isinstance(source, (str, os.PathLike)):
        if base_dir is not None:
            raise TypeError(
                "base_dir= is for a scenario given as a mapping; "
                "a file's relative paths resolve against the file"
            )
        scenario = load_scenario(source, overrides, seed, dur, rate, trace_columns)
    else:
        raise TypeError(f"expected a scenario file path or a mapping, got {type(source).__name__}")
    for note in timeline_notes(scenario, overrides, "set="):  # as the CLI's warning: lines
        warnings.warn(note, OverrideWarning, stacklevel=caller_level())
    for note in reference_notes(scenario):
        warnings.warn(note, ReferenceWarning, stacklevel=caller_level())
    return scenario


def caller_level() -> int:
    """The ``stacklevel`` that points a warning at the user's line: the first frame outside
    this package (``run`` -> ``load`` -> here, or a Gymnasium env's constructor)."""
    package = str(Path(__file__).resolve().parent.parent)
    frame, level = sys._getframe(1), 1
    while frame is not None and frame.f_code.co_filename.startswith(package):
        frame, level = frame.f_back, level + 1
    return level


@api_errors
def validate(source: Source, *, base_dir: str | os.PathLike[str] | None = None) -> str:
    """Check a world or a scenario (file or mapping) as ``amsa-phys validate`` does.

    Returns ``"scenario"`` or ``"world"`` (a document with a ``world:`` key is a scenario);
    raises the :class:`~amsa_phys.errors.ConfigError` the CLI would print.
    """
    if isinstance(source, Mapping):
        doc: YamlDoc = mapping_doc(source, base_dir)
    elif isinstance(source, (str, os.PathLike)):
        if base_dir is not None:
            raise TypeError("base_dir= is for a scenario given as a mapping")
        doc = load_yaml(source)
    else:
        raise TypeError(f"expected a file path or a mapping, got {type(source).__name__}")
    if isinstance(doc.data, dict) and "world" in doc.data:
        build_scenario(doc)
        return "scenario"
    build_world(doc.data, doc, ())
    return "world"


def mapping_doc(source: Mapping[str, Any], base_dir: str | os.PathLike[str] | None) -> MappingDoc:
    """``source`` as a document of plain YAML values; relative paths against ``base_dir``."""
    if base_dir is not None and not isinstance(base_dir, (str, os.PathLike)):
        raise TypeError(f"base_dir= is a directory path, got {type(base_dir).__name__}")
    data = _plain(source, ())
    if not isinstance(data, dict):  # pragma: no cover - a Mapping always gives a dict
        raise ConfigError("expected a mapping", file=MAPPING)
    data.setdefault("name", "mapping")
    base = Path(base_dir) if base_dir is not None else Path()
    return MappingDoc(path=base / MAPPING, data=data)


def override_text(key: Any, value: Any) -> str:
    """``--set`` text for one override: ``Comp.param=<value as one line of YAML>``."""
    if not isinstance(key, str) or "=" in key:
        raise ConfigError(f"expected Component.parameter, got {key!r}", key="--set")
    text = yaml.safe_dump(
        _plain(value, (key,), "--set"), default_flow_style=True, width=math.inf, allow_unicode=True
    )
    if text.endswith("\n...\n"):  # a bare scalar document
        text = text[: -len("\n...\n")]
    return f"{key}={text.strip()}"


def _set_items(overrides: Any) -> list[tuple[Any, Any]]:
    """``set=``'s items: a mapping ``{"Comp.param": value}`` (as ``--set Comp.param=value``)."""
    if overrides is None:
        return []
    if not isinstance(overrides, Mapping):
        hint = ""
        if isinstance(overrides, (str, list, tuple)):
            hint = ' (the command line\'s "Comp.param=value" is {"Comp.param": value} here)'
        raise ConfigError(
            f'expected a mapping like {{"Comp.param": value}}, got {type(overrides).__name__} '
            f"{short_repr(overrides)}{hint}",
            key="--set",
        )
    return list(overrides.items())


def _seed(seed: Any) -> int | None:
    if seed is None:
        return None
    try:
        if isinstance(seed, bool):
            raise TypeError
        return operator.index(seed)
    except TypeError:
        raise ConfigError(f"expected an integer, got {seed!r}", key="--seed") from None


def _number(value: Any, option: str) -> Any:
    """A time or rate for the loader, which judges it as it judges the CLI's option (a
    Fraction is kept: ``duration=Fraction(7, 3)`` is exactly 7/3 s)."""
    if isinstance(value, Fraction):
        return value
    if isinstance(value, bool) or not (isinstance(value, (int, float)) or _is_numpy(value)):
        raise ConfigError(f"expected a number, got {value!r}", key=option)
    return float(value)


def _is_numpy(value: Any) -> bool:
    return type(value).__module__ == "numpy" and hasattr(value, "item")


def _plain(value: Any, keypath: KeyPath, option: str | None = None) -> Any:
    """``value`` with only the types a YAML file can give (dict, list, str, numbers, bool).

    Bounded as a file is (``model/yamlio.py``): at most ``MAX_DEPTH`` levels and
    ``MAX_NODES`` values, and a mapping or list that contains itself is refused by name (it
    would recurse forever: a RecursionError, or an exponential walk of a shared list).
    """
    return _Plainer(keypath, option).convert(value, keypath)


class _Plainer:
    """One conversion: counts the values built and knows the containers being walked.

    Errors name ``<mapping>`` and the key path, or the CLI ``option`` (``--set``) and the
    override's key when converting an argument.
    """

    def __init__(self, root: KeyPath, option: str | None = None) -> None:
        self.root = root  # where a "too large" is reported (not deep inside)
        self.option = option
        self.nodes = 0
        self.open: set[int] = set()  # ids of the containers on the current path

    def convert(self, value: Any, keypath: KeyPath) -> Any:
        self.nodes += 1
        if self.nodes > MAX_NODES:
            raise self.error(self.root, f"too large: more than {MAX_NODES:,} values")
        if len(keypath) > MAX_DEPTH:
            raise self.error(keypath, f"nesting deeper than {MAX_DEPTH} levels")
        if isinstance(value, (Mapping, list, tuple)):
            if id(value) in self.open:
                raise self.error(keypath, "contains itself (a mapping or list cannot)")
            self.open.add(id(value))
            try:
                return self.container(value, keypath)
            finally:
                self.open.discard(id(value))
        return self.scalar(value, keypath)

    def container(
        self, value: Mapping[Any, Any] | list[Any] | tuple[Any, ...], keypath: KeyPath
    ) -> Any:
        if isinstance(value, Mapping):
            out = {}
            for key, item in value.items():
                if not isinstance(key, str):
                    raise self.error(keypath, f"keys must be strings, got {short_repr(key)}")
                out[key] = self.convert(item, (*keypath, key))
            return out
        return [self.convert(v, (*keypath, i)) for i, v in enumerate(value)]

    def scalar(self, value: Any, keypath: KeyPath) -> Any:
        if value is None or isinstance(value, (bool, str)):
            return value
        if isinstance(value, int):
            return int(value)  # an IntEnum is written as its number
        if isinstance(value, float):
            return float(value)
        if isinstance(value, Fraction):
            if value.denominator == 1:
                return int(value)
            if Fraction(repr(float(value))) == value:
                return float(value)
            return f"{value.numerator}/{value.denominator}"
        if isinstance(value, os.PathLike):
            return os.fspath(value)
        if _is_numpy(value):
            if getattr(value, "ndim", 0):
                if value.size > MAX_NODES:
                    raise self.error(self.root, f"too large: more than {MAX_NODES:,} values")
                return self.convert(value.tolist(), keypath)
            return self.convert(value.item(), keypath)
        raise self.error(
            keypath,
            f"a {type(value).__name__} cannot be written in a scenario "
            "(use numbers, strings, booleans, lists and mappings)",
        )

    def error(self, keypath: KeyPath, message: str) -> ConfigError:
        if self.option is not None:  # the override's key, then where inside its value
            inside = f"{dotted(keypath[1:])}: " if keypath[1:] else ""
            return ConfigError(inside + message, key=f"{self.option} {keypath[0]}")
        return ConfigError(message, file=MAPPING, key=dotted(keypath))
