"""Terrain zones on the trajectory plot, read from a run's resolved ``scenario.yaml``.

A zone is a ``frictionZone`` component of the world (``physics/zones.py``); the resolved
scenario holds its polygon and values at t = 0, and the timeline its changes, so the plot can
say "Mud: μ 0.8, from 60 s μ 0.3" without the run's objects. Drawn under the paths, in the
colours the window uses.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml

from ..physics.terrain import zone_colours

if TYPE_CHECKING:
    from matplotlib.axes import Axes

TEMPLATE = "frictionZone"
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
    """The friction zones of a run directory's ``scenario.yaml`` (none if it has none)."""
    try:
        text = scenario_yaml.read_text()
        # a wide run's resolved scenario is ~700 kB of YAML (seconds to parse in Python):
        # parsed only when it can hold a zone at all, and by libyaml when PyYAML has it
        if TEMPLATE not in text:
            return []
        data = yaml.load(text, Loader=_LOADER)  # a safe loader (C or Python)
    except (OSError, yaml.YAMLError):
        return []
    return zones_of_resolved(data)


def zones_of_resolved(data: Any) -> list[ZoneShape]:
    """The friction zones of a resolved scenario (the data ``scenario.yaml`` holds).

    Matplotlib-free, so a run's process can hand the zones to its plotting child with the
    job instead of the child reading ``scenario.yaml`` (which is then still being written).
    """
    if not isinstance(data, Mapping) or not isinstance(data.get("world"), Mapping):
        return []
    leaves: dict[str, Mapping[str, Any]] = {}
    _collect(data["world"].get("components") or {}, "", leaves)
    changes: dict[str, list[str]] = {}
    for entry in data.get("timeline") or []:
        said: dict[str, list[str]] = {}
        for key, value in (entry.get("set") or {}).items():
            path, _, param = str(key).rpartition(".")
            if path in leaves and param in ("friction", "rollingResistance"):
                word = "μ" if param == "friction" else "Crr"
                said.setdefault(path, []).append(f"{word} {value}")
        for path, words in said.items():
            text = f"from {_at(entry.get('at'))} s " + ", ".join(words)
            changes.setdefault(path, []).append(text)
    out = []
    for path, params in leaves.items():
        mu = float(params.get("friction", 0.3))
        crr = float(params.get("rollingResistance", 0.1))
        label = "; ".join([f"{path}: μ {mu:g}, Crr {crr:g}", *changes.get(path, [])])
        pts = tuple((float(x), float(y)) for x, y in params.get("polygon") or ())
        if len(pts) >= 3:
            out.append(ZoneShape(path, pts, mu, crr, label))
    return out


def _collect(components: Mapping[str, Any], prefix: str, out: dict[str, Any]) -> None:
    for name, spec in components.items():
        if not isinstance(spec, Mapping):
            continue
        if "components" in spec:
            _collect(spec["components"], f"{prefix}{name}.", out)
        elif spec.get("template") == TEMPLATE:
            out[prefix + name] = spec.get("params") or {}


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
