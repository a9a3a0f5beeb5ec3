"""GNSS: a GPS whose error grows near walls and obstacles, with a fix quality and stamps.

It lives in ``physics/`` because the sky a receiver sees is the world's geometry (pymunk
segment queries, as the lidar's beams). The plain ``GPS`` template stays as it is: the
paper's worlds, their goldens and the ROS 1 export's C++ twin depend on it bit for bit.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Mapping
from fractions import Fraction
from typing import Any

import numpy as np

from ..engine import noise as nz
from ..model.params import Param
from ..model.sensorclock import SensorClock, clock_params
from ..model.template import Kind, Port, Template
from .lidar import cast_rays
from .space import physics_of
from .terrain import POLYGON, Zone, check_polygon

#: Slack when comparing float times (steps fall on a rational grid; floats of it round).
_EPS = 1e-9


class GNSS(Template):
    """Position fix with sky blockage, multipath, outage zones, a fix quality and time stamps.

    **Sky.** ``skyRays`` horizontal rays around the receiver find the nearest obstacle or
    wall in each azimuth (rovers are too low to count). Every shape is taken as
    ``obstacleHeight`` tall, so at distance d it hides the sky below elevation
    atan(h/d); with satellites spread evenly in elevation above ``elevationMask`` the
    hidden share of that azimuth is (atan(h/d) − mask)/(90° − mask), and ``blocked`` is the
    mean over azimuths. ``obstacleHeight`` 0: open sky everywhere.

    **Fix quality** (HDOP-like, published as ``fixQuality``): ``hdopOpen``/√(1 − blocked),
    since DOP grows roughly as one over the square root of the satellites in view. The white
    noise is ``stddev``·fixQuality/``hdopOpen`` (position error = UERE × HDOP).

    **Multipath / NLOS**: a per-axis Gauss–Markov error of unit stationary variance and
    correlation time ``multipathTime``, scaled by ``multipathStd``·exp(−d_min/``multipathRange``)
    where d_min is the nearest obstacle's distance: metres beside a wall, nothing in the open.

    **Outages**: no fix where the visible sky falls below ``minSky`` (share), inside the
    denied rectangle [``deniedXMin``, ``deniedXMax``] × [``deniedYMin``, ``deniedYMax``]
    (a tunnel, a covered yard; empty by default), inside any ``gpsDeniedZone`` of the world,
    or for a lost sample (``lostDataGPS`` %).
    Nothing published: readers keep the stale fix.

    **Timing**: ``fixTime`` is the receiver's stamp of the published fix: its true
    measurement time + ``clockOffset`` + ``syncDrift``·1e-6·t (the receiver's clock drifting
    from the robot's since the last sync at t = 0) + ``stampJitter``·N(0,1). The trace keeps
    the true time in its time column and the stamp in ``fixTime``.

    Draws per step (whatever the parameters, so changing one keeps the others' draws): the
    noise channel's white and bias draws, two multipath innovations, one loss and one
    jitter draw, each from its own stream.
    """

    batchable = True  # each run's copy steps alone in a batch

    kind = Kind.SENSOR
    inputs = (Port("posX", 0.0, "true x", "m"), Port("posY", 0.0, "true y", "m"))
    outputs = (
        Port("gpsPosX", 0.0, "measured x", "m"),
        Port("gpsPosY", 0.0, "measured y", "m"),
        Port("fixQuality", 0.0, "horizontal dilution of precision of the fix (HDOP-like)", ""),
        Port("fixTime", 0.0, "receiver's time stamp of the fix", "s"),
    )
    params = (
        *nz.noise_params("", "m", "position on each axis (open sky)", 100.0),
        Param("latency", "float", "age of a fix when published", 0.0, 0.0, 10.0, "s"),
        Param("lostDataGPS", "int", "share of samples lost independently", 0, 0, 100, "%"),
        Param("hdopOpen", "float", "HDOP under an open sky", 1.0, 0.1, 50.0, ""),
        Param("obstacleHeight", "float", "height of every obstacle and wall", 0.0, 0.0, 500.0, "m"),
        Param("elevationMask", "float", "lowest satellite elevation used", 0.1745, 0.0, 1.5, "rad"),
        Param("skyRays", "int", "azimuths sampled for the sky view", 16, 4, 360, "rays"),
        Param("minSky", "float", "visible sky share below which there is no fix", 0.0, 0.0, 1.0),
        Param("multipathStd", "float", "multipath error beside an obstacle", 0.0, 0.0, 500.0, "m"),
        Param(
            "multipathRange", "float", "distance over which multipath fades", 5.0, 0.01, 500.0, "m"
        ),
        Param(
            "multipathTime", "float", "correlation time of the multipath error", 2.0, 0.0, 1e4, "s"
        ),
        Param("deniedXMin", "float", "west edge of the no-fix rectangle", 0.0, -1e6, 1e6, "m"),
        Param("deniedXMax", "float", "east edge of the no-fix rectangle", 0.0, -1e6, 1e6, "m"),
        Param("deniedYMin", "float", "south edge of the no-fix rectangle", 0.0, -1e6, 1e6, "m"),
        Param("deniedYMax", "float", "north edge of the no-fix rectangle", 0.0, -1e6, 1e6, "m"),
        *clock_params("fix", "receiver"),
    )

    @classmethod
    def is_random(cls, values: Mapping[str, Any]) -> bool:
        """Noise, multipath, loss or jitter make the fixes depend on the seed."""
        return (
            nz.is_noisy(values)
            or values["multipathStd"] > 0
            or values["lostDataGPS"] > 0
            or values["stampJitter"] > 0
        )

    def initialize(self, ctx: Any) -> None:
        """Find the world; split the streams: noise channel, multipath, loss, jitter."""
        self.physics = physics_of(ctx)
        self.zones = denied_zones(ctx)
        chan, mp, loss, jit = ctx.rng.spawn(4)
        self.noise = nz.Channel(chan, 2)
        self.mp_start = mp.standard_normal(2).tolist()
        self.mp_rng = mp
        self.loss_rng = loss
        self.clock = SensorClock(jit)  # the one clock model of every sensor (model/sensorclock.py)
        self.mp = [0.0, 0.0]
        self.t_prev: float | None = None
        self.lost = 0  # samples without a fix so far (losses and outages)
        self.history: deque[tuple[float, float, float, float, float]] = deque()

    def sky(self, x: float, y: float) -> tuple[float, float]:
        """(blocked share of the sky, distance to the nearest obstacle) at (x, y)."""
        p = self.p
        h = p.obstacleHeight
        if h <= 0:
            return 0.0, math.inf
        mask = p.elevationMask
        reach = h / math.tan(mask) if mask > 0 else 1e4
        reach = max(reach, 3.0 * p.multipathRange)
        az = np.linspace(0.0, 2 * math.pi, p.skyRays, endpoint=False)
        rovers = {r.body for r in self.physics.rovers}
        d = cast_rays(self.physics.space, (x, y), az, reach, rovers, miss=math.inf)
        return blocked_share(d, h, mask), float(d.min()) if len(d) else math.inf

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """Measure, stamp, delay; publish nothing in an outage or for a lost sample."""
        p = self.p
        now = float(t)
        off = self.noise.offsets(now, p)
        ex = self.noise.draw_white()
        ey = self.noise.draw_white()
        gx, gy = self.mp_rng.standard_normal(2).tolist()
        u_loss = float(self.loss_rng.random())
        jitter = self.clock.draw()
        if self.t_prev is None:
            self.mp = list(self.mp_start)
        else:
            phi, q = unit_gauss_markov(p.multipathTime, now - self.t_prev)
            self.mp = [phi * self.mp[0] + q * gx, phi * self.mp[1] + q * gy]
        self.t_prev = now
        px, py = inp["posX"], inp["posY"]
        blocked, dmin = self.sky(px, py)
        visible = 1.0 - blocked
        hdop = p.hdopOpen / math.sqrt(visible) if visible > 0 else math.inf
        mp_std = p.multipathStd * math.exp(-dmin / p.multipathRange) if dmin < math.inf else 0.0
        scale = hdop / p.hdopOpen if visible > 0 else 0.0
        x = px + off[0] + p.stddev * scale * ex + mp_std * self.mp[0]
        y = py + off[1] + p.stddev * scale * ey + mp_std * self.mp[1]
        if p.precision > 0:
            x = nz.quantise(x, p.precision)
            y = nz.quantise(y, p.precision)
        stamp = SensorClock.at(now, p, jitter)
        denied = (
            visible <= 0
            or visible < p.minSky
            or any(z.contains(px, py) for z in self.zones.values())
            or (
                p.deniedXMin <= px <= p.deniedXMax
                and p.deniedYMin <= py <= p.deniedYMax
                and p.deniedXMin < p.deniedXMax
                and p.deniedYMin < p.deniedYMax
            )
        )
        lost = denied or u_loss * 100.0 < p.lostDataGPS
        fix = (now, x, y, hdop if visible > 0 else 0.0, stamp)
        if p.latency > 0 or self.history:
            fix, ready = self._delay(fix, p.latency)
            if not ready:
                return {}
        if lost:
            self.lost += 1
            return {}
        _, x, y, q, s = fix
        return {"gpsPosX": x, "gpsPosY": y, "fixQuality": q, "fixTime": s}

    def _delay(
        self, fix: tuple[float, float, float, float, float], latency: float
    ) -> tuple[tuple[float, float, float, float, float], bool]:
        """The newest fix measured at least ``latency`` ago (and whether there is one)."""
        hist = self.history
        hist.append(fix)
        due = fix[0] - latency + _EPS
        while len(hist) > 1 and hist[1][0] <= due:
            hist.popleft()
        return hist[0], hist[0][0] <= due


def denied_zones(ctx: Any) -> dict[str, Zone]:
    """The run's ``gpsDeniedZone`` polygons by component path (shared by its receivers)."""
    return ctx.shared("gpsDenied", lambda sim: {})


class GpsDeniedZone(Template):
    """A region with no satellite fix (a tunnel, a covered yard, under a bridge).

    Every ``GNSS`` receiver whose true position is inside ``polygon`` publishes nothing, so
    its readers keep the last fix; the plain ``GPS`` template ignores it. Change
    ``polygon`` in a timeline to move the zone.
    """

    batchable = True  # each run's copy steps alone in a batch

    template_name = "gpsDeniedZone"
    kind = Kind.ENVIRONMENT
    params = (POLYGON,)

    @classmethod
    def check_params(cls, values: Mapping[str, Any]) -> None:
        """A zone needs a polygon with an area."""
        check_polygon(values)

    def initialize(self, ctx: Any) -> None:
        """Register the zone with the run's receivers (it lives beside the physics)."""
        self.check_params(self.p.as_dict())
        physics_of(ctx)  # the zone belongs to the simulated world (ROS: the simulator node)
        self.zones = denied_zones(ctx)
        self._register()

    def _register(self) -> None:
        self.zones[self.path] = Zone(self.path, tuple(map(tuple, self.p.polygon)), 0.0, 0.0)

    def on_param_change(self, name: str, value: Any) -> None:
        """A moved polygon applies from the next fix."""
        self.check_params(self.p.as_dict())
        self._register()

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """Nothing to publish: the zone acts through the receivers."""
        return {}


def unit_gauss_markov(tau: float, dt: float) -> tuple[float, float]:
    """``(phi, q)`` of an exact step of a Gauss–Markov process of unit stationary variance.

    ``tau`` 0 is white (a fresh draw each step): multipath with no memory.
    """
    if tau <= 0:
        return 0.0, 1.0
    return math.exp(-dt / tau), math.sqrt(-math.expm1(-2.0 * dt / tau))


def blocked_share(dist: np.ndarray, height: float, mask: float) -> float:
    """Mean over azimuths of the share of satellites (even in elevation) hidden at ``dist``."""
    elev = np.arctan2(height, np.maximum(dist, 1e-9))
    share = np.clip((elev - mask) / (math.pi / 2 - mask), 0.0, 1.0)
    return float(share.mean())
