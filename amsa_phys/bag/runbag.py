"""A run as it happens, into a ROS 2 MCAP bag (``amsa-phys run --bag``, ``ap.run(bag=...)``).

The hook into a run is one log listener (``Simulation.add_log_listener``): at every trace
instant the recorder sees every Data buffer, the exact simulated time, the components (their
live parameters) and the events so far. From that it writes:

* every traced Data buffer as an ``amsa_msgs/msg/Scalar`` on ``rosnames.DATA`` then
  ``/<path>/<port>``,
  one per trace row, the very values of ``trace.csv``;
* the standard messages of :mod:`amsa_phys.stdmsgs` on their topics, each at the trace
  instants at which a new step of its Leaf became visible (so at the sensor's own rate when
  its instants fall on the trace's, as with the default rates; a Leaf's transport latency
  later), stamped with that step's instant; a sample the Leaf reports lost (its ``lost``
  counter, kept by GPS, Compass and Lidar) writes no message, as the sensor publishes none;
* ``/tf`` (``tf2_msgs/msg/TFMessage``): each robot's true pose, ``<robot>/odom`` ->
  ``<robot>/base_link``, at its own instants, and ``/tf_static`` once at the start: ``map`` ->
  ``<robot>/odom``, the identity (REP 105's tree; ``stdmsgs/build.py`` says why);
* ``rosnames.EVENTS`` (``amsa_msgs/msg/Event``): phase starts with their ``set``, changes inside
  a phase, and the run's events (collisions, live changes...), at their own instants.

Every time in the bag (``header.stamp``, MCAP ``log_time`` and ``publish_time``) is
simulated time in nanoseconds from the run's start, as ``/clock`` in the exported ROS
package: the first messages are stamped 0 (1 January 1970 to a viewer showing dates; the
bag's ``amsa-phys`` metadata says ``time: simulated``). So the bag of a scenario and seed is
byte-identical from run to run.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Mapping
from fractions import Fraction
from pathlib import Path
from typing import Any

from .._version import __version__
from ..engine.face import SimDriver, SimView
from ..model.rosnames import EVENTS
from ..model.scenario import Scenario, traced_columns
from ..stdmsgs import (
    DEFAULT_ORIGIN,
    Context,
    Source,
    build,
    data_topic,
    fields_of,
    find_sources,
    static_transform,
    transform,
)
from ..stdmsgs.names import unique
from .writer import DOUBLE, BagWriter, scalar_prefix, split_ns

EVENTS_TOPIC = EVENTS
TF_TOPIC = "/tf"
TF_STATIC_TOPIC = "/tf_static"
SCALAR = "amsa_msgs/Scalar"
EVENT = "amsa_msgs/Event"
TF = "tf2_msgs/TFMessage"


def ns_of(t: Fraction) -> int:
    """Nanoseconds of an exact simulated time (rounded down)."""
    return (t.numerator * 1_000_000_000) // t.denominator


class _Stream:
    """One source's bookkeeping: its Leaf's timer in ticks, the steps seen, the lost count."""

    def __init__(self, src: Source, channel: int, freq: Fraction) -> None:
        self.src = src
        self.channel = channel
        self.freq = freq
        self.period = 1  # ticks between the Leaf's steps (set once the grid exists)
        self.phase = 0  # tick of its first step
        self.count = -1  # index of the Leaf's last step already seen
        self.lost = 0
        #: ticks from a step to its outputs' visibility (a Leaf's transport latency; with
        #: jitter its least); 0: visible at once
        self.delay = 0
        #: a delayed Leaf's (last step run, lost count then), noted at each trace instant:
        #: its losses are counted when they happen, its outputs seen ``delay`` later
        self.history: deque[tuple[int, int]] = deque()

    def steps(self, tick: int) -> int:
        """Index of the Leaf's last step at or before ``tick`` (-1: none yet)."""
        return (tick - self.phase) // self.period if tick >= self.phase else -1

    def lost_by(self, k: int) -> int:
        """A delayed Leaf's lost count once step ``k`` had run (the last one noted by then)."""
        hist = self.history
        while len(hist) > 1 and hist[1][0] <= k:
            hist.popleft()
        return hist[0][1] if hist and hist[0][0] <= k else self.lost


class BagRecorder:
    """Writes one run into an MCAP bag; :meth:`simulation` is the run's Simulation factory.

    Use it as ``execute(..., simulation=bag.simulation)`` (or attach it to a Simulation built
    elsewhere), then :meth:`close` whatever ended the run: the bag then holds every instant
    up to the last one run, finalised.
    """

    def __init__(
        self,
        path: str | Path,
        scenario: Scenario,
        *,
        origin: tuple[float, float] = DEFAULT_ORIGIN,
    ) -> None:
        self.path = Path(path)
        self.scenario = scenario
        self.origin = origin
        self.sources = find_sources(scenario.world)
        self.columns = traced_columns(scenario)
        self.writer: BagWriter | None = None
        self.sim: SimView | None = None
        self._streams: list[_Stream] = []
        self._timeline = _timeline_events(scenario)
        self._next_point = 0
        self._next_event = 0
        self._ready = False

    # -- hooking into a run --------------------------------------------------------------
    def simulation(self, scenario: Scenario, trace: Any) -> SimDriver:
        """A :data:`~amsa_phys.runs.single.SimulationFactory`: the engine's Simulation with
        this recorder attached."""
        from ..runs.single import default_simulation  # a ros2: scenario's Leaves too

        sim = default_simulation(scenario, trace)
        self.attach(sim)
        return sim

    def attach(self, sim: SimView) -> None:
        """Open the bag and listen to ``sim``'s trace instants."""
        self.sim = sim
        sc = self.scenario
        self.writer = w = BagWriter(
            self.path,
            {
                "scenario": sc.name,
                "seed": str(sc.seed),
                "duration_s": repr(float(sc.duration)),
                "origin_lat_lon": f"{self.origin[0]!r},{self.origin[1]!r}",
                "amsa_phys": __version__,
                "time": "simulated: nanoseconds since the run's start (stamps from 0)",
            },
        )
        taken = {EVENTS_TOPIC, TF_TOPIC, TF_STATIC_TOPIC}
        w.channel(EVENTS_TOPIC, EVENT)
        w.channel(TF_TOPIC, TF)
        robots = [s for s in self.sources if s.role.name == "Pose"]
        if robots:
            w.channel(TF_STATIC_TOPIC, TF)
        leaves = sc.world.leaves
        for src in self.sources:
            cid = w.channel(src.topic, src.role.msg)
            taken.add(src.topic)
            self._streams.append(_Stream(src, cid, leaves[src.leaf].freq))
        self._scalars = [
            (w.channel(unique(data_topic(col), taken), SCALAR), col) for col in self.columns
        ]
        sim.add_log_listener(self._on_log)

    # -- every trace instant -------------------------------------------------------------
    def _on_log(self, t_s: float, values: Mapping[str, float]) -> None:
        sim = self.sim
        w = self.writer
        assert sim is not None
        assert w is not None
        grid = sim.grid
        if not self._ready:  # the grid and timer phases exist once the run is initialised
            self._ready = True
            robots = [st.src for st in self._streams if st.src.role.name == "Pose"]
            if robots:
                stamp = split_ns(ns_of(sim.now))
                tfs = {"transforms": [static_transform(src, stamp) for src in robots]}
                w.write(TF_STATIC_TOPIC, TF, tfs, ns_of(sim.now))
            for st in self._streams:
                st.period = grid.ticks(1 / st.freq)
                st.phase = grid.ticks(Fraction(sim.timer_phases.get(st.src.leaf, 0)))
                timing = self.scenario.world.leaves[st.src.leaf].timing
                if timing.delayed:  # as the engine's DelayLine: whole ticks, at least one
                    st.delay = max(1, math.ceil(timing.latency / grid.tick))
        now = sim.now
        tick = grid.ticks(now)
        ns = ns_of(now)
        self._flush_events(now)
        prefix = scalar_prefix(ns)
        pack = DOUBLE.pack
        write_raw = w.write_raw
        for cid, col in self._scalars:
            write_raw(cid, prefix + pack(values[col]), ns)
        for st in self._streams:
            comp = sim.components[st.src.leaf]
            lost = getattr(comp, "lost", None)
            if st.delay and isinstance(lost, int):
                st.history.append((st.steps(tick), lost))
            k = st.steps(tick - st.delay)  # the last step whose outputs are visible now
            if k <= st.count:
                continue
            due, st.count = k - st.count, k
            if isinstance(lost, int):
                total = st.lost_by(k) if st.delay else lost
                dropped, st.lost = total - st.lost, total
                if dropped >= due:  # every step since the last message lost its sample
                    continue
            step_at = grid.time(st.phase + k * st.period)
            ctx = Context(split_ns(ns_of(step_at)), float(step_at), 1 / float(st.freq), self.origin)
            src = st.src
            msg = build(src, values, comp.p.as_dict(), ctx)
            w.write(src.topic, src.role.msg, msg, ns)
            if src.role.name == "Pose":
                tf = {"transforms": [transform(src, fields_of(src, values), ctx)]}
                w.write(TF_TOPIC, TF, tf, ns)

    def _flush_events(self, until: Fraction) -> None:
        """Write the timeline changes and run events at or before ``until``, in time order."""
        sim = self.sim
        w = self.writer
        assert sim is not None
        assert w is not None
        due: list[tuple[int, int, str, str]] = []
        points = self._timeline
        while self._next_point < len(points) and points[self._next_point][0] <= until:
            at, kind, detail = points[self._next_point]
            due.append((ns_of(at), 0, kind, detail))
            self._next_point += 1
        events = sim.events
        while self._next_event < len(events):
            e = events[self._next_event]
            due.append((round(e.t * 1e9), 1, e.kind, e.detail))
            self._next_event += 1
        for ns, _, kind, detail in sorted(due):
            sec, nsec = split_ns(ns)
            stamp = {"sec": sec, "nanosec": nsec}
            msg = {"header": {"stamp": stamp, "frame_id": ""}, "kind": kind, "detail": detail}
            w.write(EVENTS_TOPIC, EVENT, msg, ns)

    def close(self) -> Path | None:
        """Write what is left (events up to the last instant run) and finalise the bag.

        Returns its path, or None if it could not be written (or the run never started).
        """
        if self.writer is None:
            return None
        if self.sim is not None and not self.writer.closed:
            try:
                self._flush_events(self.sim.now)
            except BaseException:
                self.writer.discard()
                raise
        return self.writer.close()


def _timeline_events(scenario: Scenario) -> list[tuple[Fraction, str, str]]:
    """The scenario's phase starts and in-phase changes as (at, kind, detail), in time order."""
    timeline = scenario.timeline
    first = timeline.phases[0]
    sets = ", ".join(f"{c.key}={c.value!r}" for c in first.changes)
    label = f" ({first.label})" if first.label else ""
    out = [(first.at, "phase", f"phase 0{label} starts: {sets}".rstrip(": "))]
    for point in timeline.points():
        sets = ", ".join(f"{c.key}={c.value!r}" for c in point.changes)
        label = f" ({point.label})" if point.label else ""
        if point.starts_phase:
            text = f"phase {point.phase}{label} starts: {sets}".rstrip(": ")
            out.append((point.at, "phase", text))
        else:
            out.append((point.at, "change", f"in phase {point.phase}{label}: {sets}"))
    return out
