"""Lidar: a planar range scanner whose beams are pymunk segment queries against the world.

It lives in ``physics/`` because it asks the pymunk Space for geometry (the only package
allowed to import pymunk); it reads its mount's pose through its input Data like any
sensor, and its noise model is the one every sensor shares (``engine/noise.py``).
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping
from fractions import Fraction
from typing import Any

import numpy as np
import pymunk

from ..engine import noise as nz
from ..model.params import Param
from ..model.sensorclock import stamped
from ..model.template import Kind, Port, Template
from ..templatemarks import Scan
from .space import physics_of

_ALL = pymunk.ShapeFilter()


class Lidar(Template):
    """Planar lidar: ``beams`` rays cast in the world, range noise, max range, dropouts, lost scans.

    Beam i points at ``angle_min + i (angle_max - angle_min) / (beams - 1)`` from the
    heading (ROS ``LaserScan`` conventions), from the position read on ``posX``/``posY``
    (the lidar sits at the rover's centre). Each beam is a pymunk segment query to
    ``range_max`` against every shape — obstacles, walls, other rovers — except the mount
    rover's own (the rover whose ``posX`` the lidar reads) and sensor shapes; the nearest
    hit's distance gets the SDFormat noise of ``engine/noise.py`` (white per beam, biases
    shared by the scan), is rounded to ``precision`` and clipped to [``range_min``,
    ``range_max``]. A beam with no hit, or one of the ``dropout`` % that return nothing,
    reads ``range_max`` (ROS would say +inf; Data buffers hold finite numbers). A lost scan
    (``lostScan`` %) publishes nothing, so readers keep the previous scan.

    The pose comes from the Data, the geometry from the world at the instant of the scan:
    run the lidar at its robot's rate (or a divisor) and after it, so both describe the same
    instant. ``ranges`` is an array port: one Data buffer per beam, ``Lidar.ranges[i]``, one
    trace column each; they read 0 until the first scan. Not modelled: beam divergence,
    intensity, motion during a scan (the whole scan is instantaneous), multiple echoes,
    mixed pixels at edges.
    """

    batchable = True  # each run's copy steps alone in a batch (no step_many needed)

    kind = Kind.SENSOR
    #: drawn as beams to each echo, in the colour of the rover it is mounted on
    marks = (Scan(),)
    inputs = (
        Port("posX", 0.0, "x of the mount", "m"),
        Port("posY", 0.0, "y of the mount", "m"),
        Port("heading", 0.0, "heading of the mount", "rad"),
    )
    outputs = (Port("ranges", 0.0, "range along each beam", "m", array=True, size="beams"),)
    params = (
        Param(
            "beams",
            "int",
            "number of beams (fixed by the world: one Data each)",
            16,
            1,
            1024,
            "beams",
        ),
        Param(
            "angle_min",
            "float",
            "angle of the first beam from the heading",
            -math.pi / 2,
            -math.pi,
            math.pi,
            "rad",
        ),
        Param(
            "angle_max",
            "float",
            "angle of the last beam from the heading",
            math.pi / 2,
            -math.pi,
            math.pi,
            "rad",
        ),
        Param(
            "range_min",
            "float",
            "shortest range reported (closer reads this)",
            0.1,
            0.0,
            1000.0,
            "m",
        ),
        Param("range_max", "float", "longest range: no echo reads this", 20.0, 0.01, 1000.0, "m"),
        *nz.noise_params("", "m", "range", 10.0),
        Param("dropout", "float", "share of beams that return nothing", 0.0, 0.0, 100.0, "%"),
        Param("lostScan", "float", "share of scans lost", 0.0, 0.0, 100.0, "%"),
    )

    #: the beam count sizes the Data buffers: the window's panel shows it as fixed
    fixed_once_running = frozenset({"beams"})

    @classmethod
    def check_params(cls, values: Mapping[str, Any]) -> None:
        """angle_min <= angle_max and range_min < range_max."""
        if values["angle_min"] > values["angle_max"]:
            raise ValueError(
                f"angle_min ({values['angle_min']:g}) is above angle_max ({values['angle_max']:g})"
            )
        if values["range_min"] >= values["range_max"]:
            raise ValueError(
                f"range_min ({values['range_min']:g}) must be below range_max "
                f"({values['range_max']:g})"
            )

    @classmethod
    def is_random(cls, values: Mapping[str, Any]) -> bool:
        """Noise, random biases, dropouts or lost scans make the ranges depend on the seed."""
        return nz.is_noisy(values) or values["dropout"] > 0 or values["lostScan"] > 0

    def initialize(self, ctx: Any) -> None:
        """Find the world; three streams: range noise, dropouts, lost scans."""
        self.check_params(self.p.as_dict())
        self.physics = physics_of(ctx)
        noise, drop, loss = ctx.rng.spawn(3)
        self.noise = nz.Channel(noise, 1)
        self.drop = drop
        self.loss = loss
        link = ctx.world.leaves[ctx.path].inputs.get("posX", "") if ctx.world else ""
        self.mount = link.rpartition(".")[0]
        self.own: pymunk.Body | None = None
        self.lost = 0
        #: the last published scan, for the renderer: (x, y, heading, ranges)
        self.scan: tuple[float, float, float, np.ndarray] | None = None

    def on_param_change(self, name: str, value: Any) -> None:
        """A rule between the parameters holds for changes made from code too."""
        self.check_params(self.p.as_dict())

    def angles(self) -> np.ndarray:
        """Each beam's angle from the heading (rad)."""
        p = self.p
        if p.beams == 1:
            return np.array([p.angle_min])
        return np.linspace(p.angle_min, p.angle_max, p.beams)

    def _own_body(self) -> pymunk.Body | None:
        if self.own is None:
            for rover in self.physics.rovers:
                if rover.name == self.mount:
                    self.own = rover.body
        return self.own

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: one scan, or none if lost."""
        p = self.p
        x, y, heading = inp["posX"], inp["posY"], inp["heading"]
        own = self._own_body()
        true = cast_rays(
            self.physics.space,
            (x, y),
            heading + self.angles(),
            p.range_max,
            () if own is None else (own,),
        )
        noisy = self.noise.apply_array(true, float(t), p)
        dropped = self.drop.random(p.beams) * 100.0 < p.dropout
        echo = (true < p.range_max) & ~dropped
        ranges = np.where(echo, np.clip(noisy, p.range_min, p.range_max), p.range_max)
        if float(self.loss.random()) * 100.0 < p.lostScan:
            self.lost += 1
            return {}
        self.scan = (x, y, heading, ranges)
        return {"ranges": ranges}


def cast_rays(
    space: pymunk.Space,
    origin: tuple[float, float],
    angles: np.ndarray,
    reach: float,
    ignore: Collection[pymunk.Body] = (),
    miss: float | None = None,
) -> np.ndarray:
    """Distance to the nearest shape along each ray from ``origin`` (``miss``, by default
    ``reach``: none within reach).

    Shapes of the bodies in ``ignore`` (the mount rover; a GNSS receiver's rovers) and sensor
    shapes (terrain zones, if any) are not seen. One pymunk segment query per ray: a C call
    that returns every hit. The lidar's beams and a GNSS receiver's sky both cast here.
    """
    ox, oy = origin
    out = np.full(len(angles), reach if miss is None else miss)
    for i, a in enumerate(angles.tolist()):
        end = (ox + reach * math.cos(a), oy + reach * math.sin(a))
        best = 1.0
        for hit in space.segment_query((ox, oy), end, 0.0, _ALL):
            shape = hit.shape
            if (
                hit.alpha < best
                and shape is not None
                and shape.body not in ignore
                and not shape.sensor
            ):
                best = hit.alpha
        if best < 1.0:
            out[i] = best * reach
    return out


#: Lidar with the sensor's own clock: an output ``stamp`` (``model/sensorclock.py``)
StampedLidar = stamped(Lidar)
