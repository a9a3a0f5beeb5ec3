"""Terrain zones on the trajectory plot, read from a run's resolved ``scenario.yaml``.

A zone is a component whose template declares a :class:`~amsa_phys.templatemarks.Zone` mark
(the built-in ``frictionZone``, ``physics/zones.py``, or a user's own); the resolved scenario
holds its polygon and values at t = 0, and the timeline its changes, so the plot can say
"Mud: μ 0.8, from 60 s μ 0.3" without the run's objects. Drawn under the paths, in the
colours the window uses.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml

from ..model.template import BUILTINS, resolve_template
from ..physics.terrain import zone_colours
from ..templatemarks import Zone, marks_of

if TYPE_CHECKING:
    from matplotlib.axes import Axes

_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


@dataclass(frozen=True)
class ZoneShape:
    """A zone as plotted: path, polygon, values at t = 0 and a one-line label."""

    name: str
    polygon: tuple[tuple[float, float], ...]
    friction: float
    rolling_resistance: float
    label: str


def zones_of_run(scenario_yaml: Path) -> list[ZoneShape]:
    """The zones of a run directory's ``scenario.yaml`` (none if it has none), read without
    its world: the zones the built-in templates it names declare (a template that is not
    built in is never imported to ask)."""
    try:
        data = yaml.load(scenario_yaml.read_text(), Loader=_LOADER)  # a safe loader (C or Python)
    except (OSError, yaml.YAMLError):
        return []
    return zones_of_resolved(data, builtin_zones(data))


def builtin_zones(data: Any) -> dict[str, Zone]:
    """Path -> the zone mark of every leaf of a resolved scenario whose built-in template
    declares one."""
    out: dict[str, Zone] = {}
    for path, spec in _leaves(data).items():
        ref = spec.get("template")
        if isinstance(ref, str) and ref in BUILTINS:
            for mark in marks_of(resolve_template(ref), Zone):
                out[path] = mark
    return out


def zones_of_resolved(data: Any, declared: Mapping[str, Zone]) -> list[ZoneShape]:
    """The zones of a resolved scenario (the data ``scenario.yaml`` holds); ``declared``:
    path -> the zone mark its template declares (``plot_context`` reads them from the world).

    Matplotlib-free, so a run's process can hand the zones to its plotting child with the
    job instead of the child reading ``scenario.yaml`` (which is then still being written).
    """
    leaves = {p: spec.get("params") or {} for p, spec in _leaves(data).items() if p in declared}
    if not leaves or not isinstance(data, Mapping):
        return []
    changes: dict[str, list[str]] = {}
    for entry in data.get("timeline") or []:
        said: dict[str, list[str]] = {}
        for key, value in (entry.get("set") or {}).items():
            path, _, param = str(key).rpartition(".")
            mark = declared.get(path)
            if path in leaves and mark and param in (mark.friction, mark.rolling_resistance):
                word = "μ" if param == mark.friction else "Crr"
                said.setdefault(path, []).append(f"{word} {value}")
        for path, words in said.items():
            text = f"from {_at(entry.get('at'))} s " + ", ".join(words)
            changes.setdefault(path, []).append(text)
    out = []
    for path, params in leaves.items():
        mark = declared[path]
        mu = float(params.get(mark.friction, 0.3))
        crr = float(params.get(mark.rolling_resistance, 0.1))
        label = "; ".join([f"{path}: μ {mu:g}, Crr {crr:g}", *changes.get(path, [])])
        pts = tuple((float(x), float(y)) for x, y in params.get(mark.polygon) or ())
        if len(pts) >= 3:
            out.append(ZoneShape(path, pts, mu, crr, label))
    return out


def _leaves(data: Any) -> dict[str, Mapping[str, Any]]:
    """Path -> spec of every leaf of a resolved scenario's world (none if it has none)."""
    if not isinstance(data, Mapping) or not isinstance(data.get("world"), Mapping):
        return {}
    out: dict[str, Mapping[str, Any]] = {}
    _collect(data["world"].get("components") or {}, "", out)
    return out


def _collect(components: Mapping[str, Any], prefix: str, out: dict[str, Any]) -> None:
    for name, spec in components.items():
        if not isinstance(spec, Mapping):
            continue
        if "components" in spec:
            _collect(spec["components"], f"{prefix}{name}.", out)
        else:
            out[prefix + name] = spec


def _at(value: Any) -> str:
    try:
        return f"{float(value):g}"
    except (TypeError, ValueError):
        return str(value)  # an exact fraction such as "7/3"


def draw_zones(
    ax: Axes,
    zones: list[ZoneShape],
    view: Callable[[np.ndarray], np.ndarray] | None = None,
) -> None:
    """Fill each zone (blue if slippery, else brown) and name it, under everything else.

    ``view`` maps world metres to plot coordinates (the trajectory plot's lateral-offset
    frame), so a zone stays under the paths that cross it in any view.
    """
    from matplotlib.patches import Polygon  # here: zones_of_resolved runs without matplotlib

    for z in zones:
        pts = np.asarray(z.polygon, dtype=float)
        if view is not None:
            pts = view(pts)
        fill, edge = zone_colours(z.friction, z.rolling_resistance, (255, 255, 255))
        ax.add_patch(
            Polygon(
                pts,
                closed=True,
                fc=tuple(c / 255 for c in fill),
                ec=tuple(c / 255 for c in edge),
                lw=0.8,
                zorder=0.5,
                label=z.label,
            )
        )
