"""The ``frictionZone`` and ``gradeZone`` templates: patches of ground with their own friction
and resistance, or slope.

The template lives here, beside the other templates of the physics package and above
``space.py``, while ``terrain.py`` holds only the zones' geometry and lookup that the physics
world uses: when the template sat in ``terrain.py`` the two modules imported each other (the
package's only import circle).
"""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from ..model.params import Param
from ..model.template import Kind, Template
from ..templatemarks import Zone as ZoneMark
from .space import physics_of
from .terrain import POLYGON, Grade, Zone, check_polygon


class FrictionZone(Template):
    """A patch of ground with its own friction and rolling resistance (mud, ice, sand, grass).

    The wheels of any rover over ``polygon`` use this friction (tyre grip, scrub) and
    rolling resistance instead of the world's ``physics.ground``. Change ``friction`` in a
    scenario's timeline to make the ground change mid-run ("mud from t = 60":
    ``{at: 60, set: {Mud.friction: 0.3}}``). Overlapping zones: the last declared wins.
    """

    batchable = True  # each run's copy steps alone in a batch (no step_many needed)

    template_name = "frictionZone"
    #: a zone changes the ground itself: the batch's column physics has one ground
    shares_physics = False
    kind = Kind.ENVIRONMENT
    #: drawn as a patch of ground coloured by its friction, live, replayed and plotted
    marks = (ZoneMark(),)
    params = (
        Param(
            "friction",
            "float",
            "tyre-ground friction coefficient mu in the zone (dry asphalt 0.8, wet grass "
            "0.35, mud 0.3, snow 0.2, ice 0.05)",
            0.3,
            0.0,
            5.0,
        ),
        Param(
            "rollingResistance",
            "float",
            "rolling-resistance coefficient Crr in the zone (concrete 0.015, grass 0.05, "
            "sand 0.15, mud 0.1-0.3)",
            0.1,
            0.0,
            1.0,
        ),
        POLYGON,
    )

    @classmethod
    def check_params(cls, values: Mapping[str, Any]) -> None:
        """A zone needs a polygon with an area."""
        check_polygon(values)

    def initialize(self, ctx: Any) -> None:
        """Register the zone with the run's physics world."""
        self.check_params(self.p.as_dict())
        self.terrain = physics_of(ctx).terrain
        self.terrain.add(
            Zone(self.path, tuple(self.p.polygon), self.p.friction, self.p.rollingResistance)
        )

    def on_param_change(self, name: str, value: Any) -> None:
        """Tell the physics: the next step's wheels see the new ground."""
        self.check_params(self.p.as_dict())
        key = {"friction": "friction", "rollingResistance": "rolling_resistance"}.get(
            name, "polygon"
        )
        self.terrain.update(self.path, **{key: tuple(value) if key == "polygon" else value})

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: nothing to publish (the ground acts through the physics)."""
        return {}


class GradeZone(Template):
    """A slope: over ``polygon`` the ground rises at ``angle`` towards ``direction``.

    Gravity pulls every rover whose centre is over the zone downhill with ``m g sin(angle)``
    and the ground carries ``m g cos(angle)`` (its tyres' grip and rolling resistance scale
    with it). A rover holds on a slope while its rims' static resistance can hold the
    pull, rolls back above that, and climbs at the speed its motors allow
    (``tests/physics/test_slopes.py``). The world stays a plane: a slope changes forces,
    not the height or the drawing.
    """

    batchable = True  # each run's copy steps alone in a batch (no step_many needed)

    template_name = "gradeZone"
    #: a zone changes the ground itself: the batch's column physics has one ground
    shares_physics = False
    kind = Kind.ENVIRONMENT
    params = (
        Param("angle", "float", "slope angle (0.1 rad is a 10 % grade)", 0.05, 0.0, 0.8, "rad"),
        Param(
            "direction",
            "float",
            "uphill direction, world frame (0: uphill towards +x)",
            0.0,
            -7.0,
            7.0,
            "rad",
        ),
        POLYGON,
    )

    @classmethod
    def check_params(cls, values: Mapping[str, Any]) -> None:
        """A zone needs a polygon with an area."""
        FrictionZone.check_params(values)

    def initialize(self, ctx: Any) -> None:
        """Register the slope with the run's physics world."""
        self.check_params(self.p.as_dict())
        self.terrain = physics_of(ctx).terrain
        self.terrain.add_grade(
            Grade(self.path, tuple(self.p.polygon), self.p.angle, self.p.direction)
        )

    def on_param_change(self, name: str, value: Any) -> None:
        """Tell the physics: the next step's rovers feel the new slope."""
        self.check_params(self.p.as_dict())
        self.terrain.update_grade(self.path, **{name: tuple(value) if name == "polygon" else value})

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: nothing to publish (the slope acts through the physics)."""
        return {}
