"""A finished run as :class:`~amsa_phys.view.scene.Frame` s: what ``amsa-phys view`` draws.

The live :class:`~amsa_phys.view.scene.Scene` builds frames from a running Simulation; this
one builds the same frames from a run directory's trace, metrics and resolved world, at any
logged instant, forwards or backwards. Both feed one :class:`~amsa_phys.view.draw.Renderer`,
so a replayed run looks like the live one (colours, trails, GPS crosses, lost-fix marks, the
HUD). A frame shows the trace's own values at a logged row, never interpolated: what you
read is what the run wrote. Everything with history (trails, GPS fixes, lost fixes, running
metrics) is computed once when the run is loaded, so scrubbing costs a binary search.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model.geometry import static_obstacles
from ..model.scenario import Quality
from ..model.world import WorldSpec
from ..palette import rover_names, rover_ranks
from ..templatemarks import Zone, marked
from ..tracemarks import GpsLink, gps_links, lossy_in_run, lost_fix_rows
from ..valuetext import value_text
from .scene import (
    GPS_POINTS,
    LOST_POINTS,
    TRAIL_POINTS,
    TRAIL_STEP_M,
    Frame,
    GpsTrack,
    LiveMetrics,
    RoverPose,
    ZoneView,
    phase_line,
)

_BODY_DEFAULTS = {"length": 0.8, "width": 0.6, "track": 0.5}


@dataclass(frozen=True)
class Event:
    """Something to jump to: a phase start, a change, a collision, a lost fix."""

    t: float
    kind: str  # "phase", "change", "collision", "lost fix", or the run's own event kinds
    text: str


class ReplayScene:
    """Frames of a finished run, by row of its trace."""

    def __init__(
        self, columns: list[str], data: np.ndarray, metrics: dict[str, Any], world: WorldSpec
    ) -> None:
        if columns[:1] != ["t"] or data.ndim != 2 or len(data) == 0:
            raise ValueError("a trace with a t column and at least one row")
        self.columns = columns
        self.data = data
        self.t = data[:, 0]
        self.metrics = metrics
        self.world = world
        self.col = {c: i for i, c in enumerate(columns)}
        q = metrics.get("quality") or None
        self.quality = (
            Quality(q["signal"], float(q["reference"]), float(q["tolerance"]), q.get("dwell"))
            if q
            else None
        )
        # the run's end, which the slider says too: a run closed early in the window keeps
        # the file's duration in metrics.json ("/ 200 s" in the HUD beside "/ 63.4 s")
        self.duration = float(self.t[-1])
        self.phases: list[dict[str, Any]] = list(metrics.get("phases") or [])
        shown = rover_names(columns)
        self.ranks = rover_ranks(rover_names(list(world.buffers)), shown)
        self.rover_names = sorted(shown, key=lambda r: self.ranks[r])
        self.obstacles = static_obstacles(world.physics or {})
        self._trail_rows = {r: self._thin_rows(r) for r in self.rover_names}
        self._gps = self._gps_history()
        self._metric_prefix = self._running_metrics()
        self.events = self._events()
        self._hits = self._collision_points()
        self._zones, self._zone_changes = self._zone_history()

    # -- loading -----------------------------------------------------------------------------
    def _xy(self, rover: str) -> np.ndarray:
        return self.data[:, [self.col[f"{rover}.posX"], self.col[f"{rover}.posY"]]]

    def _thin_rows(self, rover: str) -> np.ndarray:
        """Rows kept in a trail: each at least :data:`TRAIL_STEP_M` from the last kept (the
        live scene's rule, so a replayed trail has the same points)."""
        xy = self._xy(rover)
        keep = [0]
        lx, ly = xy[0]
        for i in range(1, len(xy)):
            x, y = xy[i]
            if math.hypot(x - lx, y - ly) >= TRAIL_STEP_M:
                keep.append(i)
                lx, ly = x, y
        return np.asarray(keep, dtype=int)

    def _gps_history(self) -> list[tuple[GpsLink, str | None, np.ndarray, np.ndarray]]:
        """Per traced fix: its link, rover, rows where a new fix appeared, rows of lost fixes."""
        out = []
        for link in gps_links(self.world.leaves, lossy_in_run(self.metrics)):
            if link.x not in self.col or link.y not in self.col:
                continue
            fx, fy = self.data[:, self.col[link.x]], self.data[:, self.col[link.y]]
            new = np.flatnonzero(np.r_[True, (fx[1:] != fx[:-1]) | (fy[1:] != fy[:-1])])
            lost = lost_fix_rows(self.t, fx, fy, link.period_s) if link.lossy else new[:0]
            rover = link.rover if link.rover in self.ranks else None
            out.append((link, rover, new, lost))
        return out

    def _running_metrics(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """Prefix max, min and sum of squared errors of the quality signal, per row."""
        q = self.quality
        if q is None or q.signal not in self.col:
            return None
        s = self.data[:, self.col[q.signal]]
        with np.errstate(over="ignore", invalid="ignore"):  # a huge legal reference: inf
            sq = np.cumsum((s - q.reference) ** 2)
        return np.maximum.accumulate(s), np.minimum.accumulate(s), sq

    def _events(self) -> list[Event]:
        """Every instant worth jumping to, in time order."""
        out = []
        for i, p in enumerate(self.phases):
            if i > 0:
                sets = ", ".join(f"{k}={v}" for k, v in (p.get("set") or {}).items())
                out.append(Event(float(p["start"]), "phase", f"phase {i}: {sets}"))
            for c in p.get("changes") or []:
                sets = ", ".join(f"{k}={v}" for k, v in (c.get("set") or {}).items())
                how = "live change" if c.get("label") == "live" else "change"
                out.append(Event(float(c["at"]), "change", f"{how}: {sets}"))
        for e in self.metrics.get("events") or []:
            if e.get("kind") == "live change":
                continue  # the phase's change above: one mark and one stop for it, not two
            out.append(
                Event(float(e["t"]), str(e.get("kind")), f"{e.get('kind')} {e.get('detail', '')}")
            )
        for link, _, _, lost in self._gps:
            out += [Event(float(self.t[r]), "lost fix", f"lost fix {link.path}") for r in lost]
        return sorted(out, key=lambda e: (e.t, e.kind))

    def _collision_points(self) -> list[tuple[float, tuple[float, float]]]:
        """Each collision's time and place: the midpoint of the traced rovers it names
        (``Leader-Follower``) at the row logged then, as ``trajectory.png`` marks it."""
        out = []
        for e in self.metrics.get("events") or []:
            if e.get("kind") != "collision":
                continue
            names = [n for n in str(e.get("detail", "")).split("-") if n in self.ranks]
            if names:
                row = self.row_at(float(e["t"]))
                xy = np.mean([self._xy(n)[row] for n in names], axis=0)
                out.append((float(e["t"]), (float(xy[0]), float(xy[1]))))
        return out

    def _zone_history(
        self,
    ) -> tuple[list[ZoneView], list[tuple[float, str, int, float]]]:
        """The world's friction zones as declared, and every change to their values the
        run made (phase sets, in-phase and live changes: ``Mud.friction`` at 60 s), so a
        replayed zone shows the ground as it was at each instant, as the live window does."""
        zones = []
        #: (path, parameter) -> which value it sets (0 friction, 1 rolling resistance)
        slot: dict[tuple[str, str], int] = {}
        for path, leaf, mark in marked(self.world.leaves, Zone):
            params, declared = leaf.params, leaf.template
            polygon = params.get(mark.polygon) or ()
            zones.append(
                ZoneView(
                    path,
                    tuple((float(x), float(y)) for x, y in polygon),
                    float(params.get(mark.friction, declared.param(mark.friction).default)),
                    float(
                        params.get(
                            mark.rolling_resistance,
                            declared.param(mark.rolling_resistance).default,
                        )
                    ),
                )
            )
            slot[(path, mark.friction)] = 0
            slot[(path, mark.rolling_resistance)] = 1
        changes = []
        for p in self.phases:
            steps = [(float(p["start"]), p.get("set") or {})]
            steps += [(float(c["at"]), c.get("set") or {}) for c in p.get("changes") or []]
            for at, sets in steps:
                for key, value in sets.items():
                    leaf, _, param = str(key).rpartition(".")
                    if (leaf, param) in slot:
                        changes.append((at, leaf, slot[(leaf, param)], float(value)))
        return zones, sorted(changes, key=lambda c: c[0])

    def zones(self, t: float) -> list[ZoneView]:
        """The zones with the values in force at ``t``."""
        now = {z.name: [z.friction, z.rolling_resistance] for z in self._zones}
        for at, leaf, slot, value in self._zone_changes:
            if at > t:
                break
            now[leaf][slot] = value
        return [ZoneView(z.name, z.polygon, *now[z.name]) for z in self._zones]

    # -- reading -----------------------------------------------------------------------------
    @property
    def rows(self) -> int:
        """Number of logged instants."""
        return len(self.t)

    def row_at(self, t: float) -> int:
        """The last row logged at or before ``t`` (the first row before the trace starts)."""
        return max(0, int(np.searchsorted(self.t, t + 1e-9, side="right")) - 1)

    def phase_index(self, t: float) -> int:
        """Index of the phase in force at ``t`` (as metrics.json numbers them)."""
        index = 0
        for i, p in enumerate(self.phases):
            if float(p["start"]) <= t:
                index = i
        return index

    def rovers(self, row: int) -> list[RoverPose]:
        """Every traced rover's pose at ``row`` (body size from the world)."""
        out = []
        values = self.data[row]
        for name in self.rover_names:
            leaf = self.world.leaves.get(name)
            params = dict(leaf.params) if leaf is not None else {}
            inputs = leaf.inputs if leaf is not None else {}

            def val(column: str | None, default: float = 0.0) -> float:
                return float(values[self.col[column]]) if column in self.col else default

            out.append(
                RoverPose(
                    name,
                    val(f"{name}.posX"),
                    val(f"{name}.posY"),
                    val(f"{name}.heading"),
                    float(params.get("length", _BODY_DEFAULTS["length"])),
                    float(params.get("width", _BODY_DEFAULTS["width"])),
                    float(params.get("track", _BODY_DEFAULTS["track"])),
                    val(inputs.get("powerL")),
                    val(inputs.get("powerR")),
                    val(f"{name}.speed"),
                    index=self.ranks[name],
                )
            )
        return out

    def frame(self, row: int) -> Frame:
        """The picture of logged instant ``row``: history up to it, every rover there."""
        row = min(max(row, 0), self.rows - 1)
        t = float(self.t[row])
        rovers = self.rovers(row)
        trails = {}
        for r in rovers:
            kept = self._trail_rows[r.name]
            rows = kept[: int(np.searchsorted(kept, row, side="right"))][-TRAIL_POINTS:]
            xy = self._xy(r.name)[rows]
            trails[r.name] = [*map(tuple, xy.tolist()), (r.x, r.y)]
        gps = []
        for link, rover, new, lost in self._gps:
            track = GpsTrack(link.path, rover, link.x, link.y)
            fx, fy = self.col[link.x], self.col[link.y]
            shown = new[: int(np.searchsorted(new, row, side="right"))][-GPS_POINTS:]
            track.fixes = deque(
                zip(self.data[shown, fx].tolist(), self.data[shown, fy].tolist(), strict=True),
                maxlen=GPS_POINTS,
            )
            n_lost = int(np.searchsorted(lost, row, side="right"))
            if rover is not None:
                where = self._xy(rover)[lost[:n_lost][-LOST_POINTS:]]
                track.lost = deque(map(tuple, where.tolist()), maxlen=LOST_POINTS)
            track.lost_total = n_lost
            gps.append(track)
        metrics = LiveMetrics()
        metrics.collisions = sum(1 for e in self.events if e.kind == "collision" and e.t <= t)
        if self._metric_prefix is not None and self.quality is not None:
            hi, lo, sq = self._metric_prefix
            metrics.value = float(self.data[row, self.col[self.quality.signal]])
            metrics.max, metrics.min = float(hi[row]), float(lo[row])
            metrics.sum_sq, metrics.count = float(sq[row]), row + 1
        index = self.phase_index(t)
        return Frame(
            t=t,
            rovers=rovers,
            trails=trails,
            gps=gps,
            obstacles=self.obstacles,
            metrics=metrics,
            quality=self.quality,
            phase_index=index,
            phase_count=len(self.phases),
            phase_text=self.phase_text(index, t),
            duration=self.duration,
            pair_lines=self.quality is not None,
            collisions=[xy for at, xy in self._hits if at <= t],
            zones=self.zones(t),
        )

    def phase_text(self, index: int, t: float | None = None) -> str:
        """The HUD's phase line at time ``t``, as the live window words it: the phase's
        values, each changed inside the phase by ``t`` (timeline or live) replaced by the
        value in force and when it landed (``Kv=0.15 at 20.0 s``, ``live at`` for the window's)."""
        if not self.phases:
            return "phase 0"
        p = self.phases[index]
        inside: dict[str, tuple[float, object, str]] = {}
        for c in p.get("changes") or []:
            if t is None or float(c["at"]) <= t:
                how = "live at" if c.get("label") == "live" else "at"
                for k, v in (c.get("set") or {}).items():
                    inside[k] = (float(c["at"]), v, how)
        sets = [
            f"{k.rpartition('.')[2]}={value_text(v)}"
            for k, v in (p.get("set") or {}).items()
            if k not in inside
        ]
        sets += [
            f"{k.rpartition('.')[2]}={value_text(v)} {how} {at:.1f} s"
            for k, (at, v, how) in inside.items()
        ]
        return phase_line(index, len(self.phases), p.get("label", ""), float(p["start"]), sets)

    def series(self, column: str, row: int, span_s: float) -> tuple[np.ndarray, np.ndarray]:
        """``column``'s samples over the ``span_s`` seconds up to ``row`` (the plot pane)."""
        end = row + 1
        start = int(np.searchsorted(self.t, self.t[row] - span_s, side="left"))
        return self.t[start:end], self.data[start:end, self.col[column]]
