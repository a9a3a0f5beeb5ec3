"""What a frame shows, read from a running Simulation: no drawing, no pygame.

The renderer draws a :class:`Frame`; the :class:`Scene` builds one per frame and keeps what
needs history (trails, GPS fixes, lost fixes, live metrics). Keeping this apart from the
drawing code lets tests check the picture's *content* (where the rovers are, which fixes were
lost) without decoding pixels, and lets the window and the recorder share one source.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from ..engine.runner import Simulation
from ..model.scenario import Quality

#: Trail and GPS history kept per rover: bounded, so a long run draws in constant time.
TRAIL_POINTS = 1500
TRAIL_STEP_M = 0.1
GPS_POINTS = 60
LOST_POINTS = 60


@dataclass(frozen=True)
class RoverPose:
    """One rover as drawn: pose, body size, wheel commands (percent)."""

    name: str
    x: float
    y: float
    heading: float
    length: float
    width: float
    track: float
    power_l: float
    power_r: float
    speed: float


@dataclass(frozen=True)
class Obstacle:
    """Static geometry in world metres: ``poly`` (closed), ``circle`` or ``line`` (open)."""

    kind: str
    points: tuple[tuple[float, float], ...]
    radius: float = 0.0


@dataclass(frozen=True)
class ZoneView:
    """A friction zone as drawn: its polygon (world metres) and current ground values."""

    name: str
    polygon: tuple[tuple[float, float], ...]
    friction: float
    rolling_resistance: float


@dataclass
class GpsTrack:
    """A GPS sensor's recent fixes and the true positions where fixes were lost."""

    path: str
    rover: str | None
    fixes: deque[tuple[float, float]] = field(default_factory=lambda: deque(maxlen=GPS_POINTS))
    lost: deque[tuple[float, float]] = field(default_factory=lambda: deque(maxlen=LOST_POINTS))
    lost_total: int = 0


@dataclass
class LiveMetrics:
    """Quality of control over the frames seen so far (the trace-based metrics come at the end)."""

    value: float | None = None
    max: float = -math.inf
    min: float = math.inf
    sum_sq: float = 0.0
    count: int = 0
    collisions: int = 0

    @property
    def rms_error(self) -> float | None:
        """Root-mean-square error of the sampled signal against the reference."""
        return math.sqrt(self.sum_sq / self.count) if self.count else None


@dataclass(frozen=True)
class Frame:
    """Everything one picture needs, at simulated time ``t``."""

    t: float
    rovers: list[RoverPose]
    trails: dict[str, list[tuple[float, float]]]
    gps: list[GpsTrack]
    obstacles: list[Obstacle]
    metrics: LiveMetrics
    quality: Quality | None
    phase_index: int
    phase_count: int
    phase_text: str
    duration: float
    #: terrain zones, bottom first (their values now: a timeline change shows)
    zones: list[ZoneView] = field(default_factory=list)


def static_obstacles(physics: dict[str, Any]) -> list[Obstacle]:
    """Obstacles and walls from the world's ``physics:`` settings (the same data pymunk got)."""
    out: list[Obstacle] = []
    for ob in physics.get("obstacles") or []:
        if ob["type"] == "box":
            w, h = ob["width"] / 2, ob["height"] / 2
            a = float(ob.get("angle", 0.0))
            c, s = math.cos(a), math.sin(a)
            pts = tuple(
                (ob["x"] + c * dx - s * dy, ob["y"] + s * dx + c * dy)
                for dx, dy in ((-w, -h), (w, -h), (w, h), (-w, h))
            )
            out.append(Obstacle("poly", pts))
        elif ob["type"] == "circle":
            out.append(Obstacle("circle", ((ob["x"], ob["y"]),), ob["radius"]))
        else:
            pts = tuple((float(p[0]), float(p[1])) for p in ob["points"])
            out.append(Obstacle("line", pts, float(ob.get("thickness", 0.1)) / 2))
    walls = physics.get("walls")
    if walls:
        x0, x1, y0, y1 = walls["xmin"], walls["xmax"], walls["ymin"], walls["ymax"]
        out.append(Obstacle("line", ((x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)), 0.1))
    return out


def describe_phase(sim: Simulation) -> str:
    """``phase 2/4 from 125 s: Kv=0.15`` — what the HUD prints about the current phase."""
    phase = sim.phases[sim.phase_index]
    sets = ", ".join(f"{c.param}={_short(c.value)}" for c in phase.changes)
    label = f" {phase.label}" if phase.label else ""
    text = f"phase {sim.phase_index + 1}/{len(sim.phases)}{label} from {float(phase.at):g} s"
    return f"{text}: {sets}" if sets else text


def _short(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, tuple):
        return f"[{len(value)} points]"
    return str(value)


class Scene:
    """Builds :class:`Frame` s from one Simulation, remembering trails and GPS history."""

    def __init__(self, sim: Simulation, quality: Quality | None = None) -> None:
        self.sim = sim
        self.quality = quality
        self.obstacles = static_obstacles(sim.world.physics)
        self.trails: dict[str, deque[tuple[float, float]]] = {}
        self.gps: list[GpsTrack] = []
        for path, leaf in sim.world.leaves.items():
            if leaf.template.name() == "GPS":
                source = leaf.inputs.get("posX", "")
                self.gps.append(GpsTrack(path, source.rpartition(".")[0] or None))
        self.metrics = LiveMetrics()
        self._last_fix: dict[str, tuple[float, float]] = {}

    def _physics(self) -> Any:
        return self.sim.shared.get("physics")

    def zones(self) -> list[ZoneView]:
        """The world's friction zones with their current values (empty without physics)."""
        physics = self._physics()
        if physics is None:
            return []
        return [
            ZoneView(z.name, z.polygon, z.friction, z.rolling_resistance)
            for z in physics.terrain.zones
        ]

    def rovers(self) -> list[RoverPose]:
        """Every rover's current pose (empty for a world without physics)."""
        physics = self._physics()
        if physics is None:
            return []
        out = []
        for r in physics.rovers:
            x, y, heading = r.pose
            out.append(
                RoverPose(
                    r.name,
                    x,
                    y,
                    heading,
                    r.length,
                    r.width,
                    2 * r.half_track,
                    r.power_l,
                    r.power_r,
                    r.forward_speed,
                )
            )
        return out

    def frame(self, t: float | None = None) -> Frame:
        """Sample the simulation now and return what to draw.

        ``t`` is the time the picture stands for (a video frame's time); by default the
        simulation's current instant.
        """
        sim = self.sim
        rovers = self.rovers()
        for r in rovers:
            trail = self.trails.setdefault(r.name, deque(maxlen=TRAIL_POINTS))
            if not trail or math.dist(trail[-1], (r.x, r.y)) >= TRAIL_STEP_M:
                trail.append((r.x, r.y))
        by_name = {r.name: r for r in rovers}
        values = sim.values
        for track in self.gps:
            fix = (values[f"{track.path}.gpsPosX"], values[f"{track.path}.gpsPosY"])
            if self._last_fix.get(track.path) != fix:
                self._last_fix[track.path] = fix
                track.fixes.append(fix)
            comp = sim.components.get(track.path)
            lost = int(getattr(comp, "lost", 0))
            if lost > track.lost_total:
                rover = by_name.get(track.rover or "")
                if rover is not None:
                    track.lost.append((rover.x, rover.y))
                track.lost_total = lost
        m = self.metrics
        if self.quality is not None and sim.now > 0:  # before t = 0 runs, buffers hold 0
            v = values[self.quality.signal]
            m.value = v
            m.max = max(m.max, v)
            m.min = min(m.min, v)
            m.sum_sq += (v - self.quality.reference) ** 2
            m.count += 1
        physics = self._physics()
        m.collisions = physics.collisions if physics is not None else 0
        return Frame(
            t=float(sim.now) if t is None else t,
            rovers=rovers,
            trails={k: list(v) for k, v in self.trails.items()},
            gps=self.gps,
            obstacles=self.obstacles,
            metrics=m,
            quality=self.quality,
            phase_index=sim.phase_index,
            phase_count=len(sim.phases),
            phase_text=describe_phase(sim),
            duration=float(sim.duration),
            zones=self.zones(),
        )
