"""What a frame shows, read from a running Simulation: no drawing, no pygame.

The renderer draws a :class:`Frame`; the :class:`Scene` builds one per frame and keeps what
needs history (trails, GPS fixes, lost fixes, live metrics). Keeping this apart from the
drawing code lets tests check the picture's *content* (where the rovers are, which fixes were
lost) without decoding pixels, and lets the window and the recorder share one source.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

from ..engine.face import SimView
from ..model.geometry import Obstacle, static_obstacles
from ..model.scenario import Quality
from ..palette import rover_names
from ..templatemarks import Fix, Scan, marked
from ..valuetext import value_text

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
    #: colour index: the rover's rank among the world's rovers (-1: its rank in the frame)
    index: int = -1


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
    #: the trace columns (``path.port``) of the fix, and the running component's counter of
    #: lost samples ("": it counts none), as its template's :class:`Fix` mark declares
    x: str = ""
    y: str = ""
    lost_count: str = ""
    fixes: deque[tuple[float, float]] = field(default_factory=lambda: deque(maxlen=GPS_POINTS))
    lost: deque[tuple[float, float]] = field(default_factory=lambda: deque(maxlen=LOST_POINTS))
    lost_total: int = 0


@dataclass(frozen=True)
class LidarScan:
    """A lidar's last published scan: where it stood, each beam's direction and range."""

    mount: str
    x: float
    y: float
    angles: tuple[float, ...]  # absolute, world frame
    ranges: tuple[float, ...]
    range_max: float


@dataclass
class LiveMetrics:
    """Quality of control over the logged instants so far: ``metrics.json``'s samples."""

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
    scans: list[LidarScan] = field(default_factory=list)
    #: terrain zones, bottom first (their values now: a timeline change shows)
    zones: list[ZoneView] = field(default_factory=list)
    #: draw a "true distance" line between consecutive rovers (see Scene.pair_lines)
    pair_lines: bool = True
    #: where collisions happened so far (world metres; the replay knows them from its events)
    collisions: list[tuple[float, float]] = field(default_factory=list)


def describe_phase(
    sim: SimView,
    planned: Sequence[Fraction] | None = None,
    replaced: Sequence[str] = (),
) -> str:
    """``phase 2 (of 0–3) from 125 s: Kv=0.15`` — what the HUD prints about the current phase.

    A parameter set twice at a phase's start (the scenario's ``set:`` and a ``--set``
    override) is listed once, with the value in force. A live change made in this phase
    (the window's panel) is in force now and the phase's own value no longer is: it
    replaces that value in the line and says when it landed (``Kv=0.35 live at 130.2 s``),
    and so does a timeline step that starts no phase (``new_phase: false``) once applied
    (``Kv=0.15 at 20.0 s``): the HUD never shows a value the run is not using. ``planned``:
    the file's phase starts and duration when ``--duration`` shortened the run
    (``Timeline.planned``): the count is then the file's, and the line says where
    this run stops. ``replaced``: components an agent stands in for (the Gymnasium env):
    their parameters are set but act on nothing, so they are not listed as if they did
    (the env's status box says ``agent: MyFollowerController``).
    """
    phase = sim.timeline.phases[sim.phase_index]
    live: dict[tuple[str, str], tuple[Any, Any, str]] = {}
    # changes made inside this phase and already in force: the timeline's
    # ``new_phase: false`` steps, then the window's live changes (in time order)
    for point in sim.timeline.points():
        if phase.at < point.at <= sim.now and not point.starts_phase:
            for c in point.changes:
                if c.leaf not in replaced:
                    live[(c.leaf, c.param)] = (point.at, c.value, "at")
    for at, c in sim.live_changes:
        if at >= phase.at and c.leaf not in replaced:
            live[(c.leaf, c.param)] = (at, c.value, "live at")
    latest: dict[tuple[str, str], Any] = {}
    for c in phase.changes:  # the last assignment of a key wins, in its first place
        if c.leaf not in replaced:
            latest[(c.leaf, c.param)] = c.value
    parts = [f"{p}={value_text(v)}" for (leaf, p), v in latest.items() if (leaf, p) not in live]
    parts += [
        f"{p}={value_text(v)} {how} {float(at):.1f} s" for (_, p), (at, v, how) in live.items()
    ]
    count = len(planned) - 1 if planned else len(sim.timeline.phases)
    text = phase_line(sim.phase_index, count, phase.label, float(phase.at), parts)
    if planned and sim.duration < planned[-1]:
        text += f" (run stops at {float(sim.duration):g} s of {float(planned[-1]):g})"
    return text + adapt_text(sim)


def phase_line(index: int, count: int, label: str, start_s: float, sets: Sequence[str]) -> str:
    """The HUD's phase line from its parts (the live window and the replay word it alike)."""
    # numbered from 0 like the summary table, describe and expect: {phase: i}
    of = f" (of 0–{count - 1})" if count > 1 else ""
    named = f" {label}" if label else ""
    text = f"phase {index}{of}{named} from {start_s:g} s"
    joined = ", ".join(sets)
    return f"{text}: {joined}" if joined else text


def adapt_text(sim: SimView) -> str:
    """`` | adapt at 327.3 s: rule 3 (worn motors): Kv=0.35``: the last ``adapt:`` switch
    (events are few: the scan from the end stops at the first one found)."""
    for event in reversed(sim.events):
        if event.kind == "adapt":
            rule, _, rest = event.detail.partition(": ")
            sets = rest.rsplit(" (", 1)[0]
            short = ", ".join(
                part.split("=", 1)[0].rsplit(".", 1)[-1] + "=" + part.split("=", 1)[-1]
                for part in sets.split(", ")
            )
            return f" | adapt at {event.t:.1f} s: {rule}: {short}"
    return ""


def fix_track(path: str, leaf: Any, fix: Fix) -> GpsTrack:
    """The track of one declared fix: its columns, and the rover whose position the
    ``measures`` port reads (its colour; where a lost fix is marked)."""
    source = leaf.inputs.get(fix.measures, "") if fix.measures else ""
    rover = source.rpartition(".")[0] or None
    return GpsTrack(path, rover, f"{path}.{fix.x}", f"{path}.{fix.y}", fix.lost)


class Scene:
    """Builds :class:`Frame` s from one Simulation, remembering trails and GPS history.

    History is sampled at every logged instant (:meth:`Simulation.add_log_listener`), not
    per frame: at x256 a frame spans seconds of simulated time, so per-frame sampling drew
    trails as chords, missed GPS fixes and put lost-fix marks where the rover was at the
    next frame. The live metrics use the same samples as ``metrics.json``, so they stand
    still while the run is paused and end equal to its overall block.
    """

    def __init__(
        self,
        sim: SimView,
        quality: Quality | None = None,
        planned: Sequence[Fraction] | None = None,
        replaced: Sequence[str] = (),
    ) -> None:
        self.sim = sim
        #: components an agent stands in for: their parameters are not shown as acting
        self.replaced = tuple(replaced)
        self.quality = quality
        #: the file's phase bounds when ``--duration`` shortened the run (the HUD counts them)
        self.planned = planned
        self.obstacles = static_obstacles(sim.world.physics)
        self.trails: dict[str, deque[tuple[float, float]]] = {}
        self.gps: list[GpsTrack] = []
        for path, leaf, fix in marked(sim.world.leaves, Fix):
            self.gps.append(fix_track(path, leaf, fix))
        #: every declared scan: the component's path and what its template says it holds
        self.lidars: list[tuple[str, Scan]] = [(p, m) for p, _, m in marked(sim.world.leaves, Scan)]
        self.metrics = LiveMetrics()
        self._last_fix: dict[str, tuple[float, float]] = {}
        #: where collisions happened (the midpoint of the rovers named), as the plots mark them
        self.collisions: deque[tuple[float, float]] = deque(maxlen=LOST_POINTS)
        self._events_seen = 0
        #: the logged instant a picture is due at (``expect``) and the rovers as they stood
        #: there: the physics step that ends an instant moves the bodies on, so a picture
        #: drawn after the instant would show them one step later than its HUD's sample
        self._due: float | None = None
        self._held: tuple[float, list[RoverPose]] | None = None
        # rovers in declaration order: the i-th has the i-th colour, as in the plots
        self._rank = {name: i for i, name in enumerate(rover_names(list(sim.world.buffers)))}
        self.pair_lines = self._between_rovers()
        sim.add_log_listener(self._sample)

    def _between_rovers(self) -> bool:
        """Whether the distance between rovers is what this run is about.

        The line between consecutive rovers reads as "the distance the quality signal
        measures" (leader and follower, a platoon's gaps). When the quality signal is
        produced by a component that reads the position of fewer than two rovers (the
        obstacle course's distance to a goal), a line to a parked rover would mislead:
        no line. Without a quality signal the gaps are still drawn (a platoon's spacing).
        """
        if self.quality is None:
            return True
        producer = self.sim.world.leaves.get(self.quality.signal.rpartition(".")[0])
        if producer is None:
            return True
        rovers = set(self._rank)
        read = {src.rpartition(".")[0] for src in producer.inputs.values()}
        return len(read & rovers) >= 2

    def _physics(self) -> Any:
        return self.sim.service("physics")

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
                    index=self._rank.get(r.name, -1),
                )
            )
        out.sort(key=lambda r: self._rank.get(r.name, len(self._rank)))
        return out

    def expect(self, t: float) -> None:
        """A picture will be drawn at ``t``: if a logged instant falls there, keep the rovers
        as they stand at its log (after its components, before its physics step)."""
        self._due = t

    def _sample(self, t_s: float, values: dict[str, float]) -> None:
        """One logged instant: extend trails, note new and lost GPS fixes, update metrics."""
        if t_s == self._due:
            self._held = (t_s, self.rovers())
        physics = self._physics()
        where: dict[str, tuple[float, float]] = {}
        for r in physics.rovers if physics is not None else ():
            x, y, _ = r.pose
            where[r.name] = (x, y)
            trail = self.trails.get(r.name)
            if trail is None:
                trail = self.trails[r.name] = deque(maxlen=TRAIL_POINTS)
            if not trail or math.dist(trail[-1], (x, y)) >= TRAIL_STEP_M:
                trail.append((x, y))
        sim = self.sim
        for event in sim.events[self._events_seen :]:
            if event.kind == "collision":
                named = [where[n] for n in str(event.detail).split("-") if n in where]
                if named:
                    xs, ys = zip(*named, strict=True)
                    self.collisions.append((sum(xs) / len(xs), sum(ys) / len(ys)))
        self._events_seen = len(sim.events)
        for track in self.gps:
            fix = (values[track.x], values[track.y])
            if self._last_fix.get(track.x) != fix:
                self._last_fix[track.x] = fix
                track.fixes.append(fix)
            counted = sim.components.get(track.path) if track.lost_count else None
            lost = int(getattr(counted, track.lost_count, 0)) if counted is not None else 0
            if lost > track.lost_total:
                pos = where.get(track.rover or "")
                if pos is not None:
                    track.lost.append(pos)  # where the rover really was when it was lost
                track.lost_total = lost
        if self.quality is not None:
            v = values[self.quality.signal]
            m = self.metrics
            m.value = v
            m.max = max(m.max, v)
            m.min = min(m.min, v)
            # a product, not ``** 2``: a huge legal reference overflows to inf (as the
            # metrics' rms does) instead of raising OverflowError mid-run
            error = v - self.quality.reference
            m.sum_sq += error * error
            m.count += 1

    def frame(self, t: float | None = None) -> Frame:
        """What to draw now: the history sampled so far, and every rover where it is now.

        ``t`` is the time the picture stands for (a video frame's time); by default the
        simulation's current instant. A trail ends at the rover's current position.
        """
        sim = self.sim
        when = float(sim.now) if t is None else t
        held = self._held
        # at a logged instant, the rovers where its components and log saw them
        rovers = held[1] if held is not None and held[0] == when else self.rovers()
        trails = {k: list(v) for k, v in self.trails.items()}
        for r in rovers:
            trails.setdefault(r.name, []).append((r.x, r.y))
        m = self.metrics
        physics = self._physics()
        m.collisions = physics.collisions if physics is not None else 0
        return Frame(
            t=when,
            rovers=rovers,
            trails=trails,
            gps=self.gps,
            obstacles=self.obstacles,
            metrics=m,
            quality=self.quality,
            phase_index=sim.phase_index,
            phase_count=len(sim.timeline.phases),
            phase_text=describe_phase(sim, self.planned, self.replaced),
            duration=float(sim.duration),
            scans=self.scans(),
            zones=self.zones(),
            pair_lines=self.pair_lines,
            collisions=list(self.collisions),
        )

    def scans(self) -> list[LidarScan]:
        """Each lidar's last published scan (none before its first)."""
        out = []
        for path, mark in self.lidars:
            comp = self.sim.components.get(path)
            scan = getattr(comp, mark.latest, None)
            if comp is None or scan is None:
                continue
            x, y, heading, ranges = scan
            angles = (heading + getattr(comp, mark.angles)()).tolist()
            reach = float(getattr(comp.p, mark.max_range))
            mount = str(getattr(comp, mark.mount, ""))
            out.append(LidarScan(mount, x, y, tuple(angles), tuple(ranges.tolist()), reach))
        return out
