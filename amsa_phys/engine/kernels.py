"""The standard components' steps as compiled bodies (``_kernels.Kernel``).

Through the ordinary scalar step a component's step is a dict of inputs, a Python frame, a
dict of outputs and their judging: ~1 µs for a distance monitor's few floating-point
operations, more for a robot's pose or a GPS fix, at every step of every run. Where the
extension is built and the store is packed, the robots, the GPS, the compass, the distance
monitor and the power normaliser step as C bodies instead — only the template's class
itself (a subclass may step differently) with its own ``do_step`` (not a replaced one):
``Kernel`` reads the store and the component's state, does the template's operations in the
same order and writes the results. What stays Python it calls by name (the rover's driver,
the leader's behaviour at a change, the Gauss–Markov factors when their parameters change,
the random streams), and what it cannot take as the Python step would (its first step, a
delayed fix, a battery model, a parameter of another type, an output that is not finite)
goes to the component's ordinary step, which publishes or raises exactly as before. So a
run is the same bit for bit and fault for fault either way (``tests/engine/test_kernels.py``).
``AMSA_PHYS_PURE=1`` (``publish.py``) runs every component through Python.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from fractions import Fraction
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .tasks import Task

#: what both robots publish, in ``Robot._pose``'s order
POSE = ("posX", "posY", "heading", "speed", "yawRate", "wheelSpeedL", "wheelSpeedR")

#: the bodies ``_kernels.Kernel`` knows: (module, class) -> (code, input ports, output ports)
BODIES: dict[tuple[str, str], tuple[int, tuple[str, ...], tuple[str, ...]]] = {
    ("amsa_phys.control.monitor", "DistanceMonitor"): (
        0,
        ("xLeader", "yLeader", "xFollower", "yFollower"),
        ("distanceFollowerToLeader",),
    ),
    ("amsa_phys.control.normalize", "NormalizePower"): (
        1,
        ("powerL", "powerR"),
        ("normalizedPowerL", "normalizedPowerR"),
    ),
    ("amsa_phys.physics.robots", "ControlledRobot"): (2, ("powerL", "powerR"), POSE),
    ("amsa_phys.physics.freerobot", "FreeRobot"): (3, (), POSE),
    ("amsa_phys.sensors.compass", "Compass"): (4, ("heading",), ("compassHeading",)),
    ("amsa_phys.sensors.gps", "GPS"): (5, ("posX", "posY"), ("gpsPosX", "gpsPosY")),
}

#: methods a body computes itself, besides ``do_step``: each must still be the one written
#: in its module (the body calls the others, ``set_power`` and ``_behaviour``, by name)
COMPUTED = {2: ("_pose",), 3: ("_pose",), 5: ("_delay",)}
#: where those methods are written
WRITTEN = {
    "_pose": ("amsa_phys.physics.robots", "Robot._pose"),
    "_delay": ("amsa_phys.sensors.gps", "GPS._delay"),
}


def body_of(comp: Any) -> tuple[int, tuple[str, ...], tuple[str, ...]] | None:
    """The compiled body of ``comp``'s step, or None: only an instance of a listed class
    itself (a subclass may change what its step does) whose ``do_step`` is the class's own."""
    cls = type(comp)
    key = (cls.__module__, cls.__qualname__)
    body = BODIES.get(key)
    if body is None or "do_step" in getattr(comp, "__dict__", {}):
        return None
    # the class's do_step as written in its module (a test or a plugin may have replaced it)
    fn = cls.__dict__.get("do_step")
    if _where(fn) != (key[0], f"{key[1]}.do_step"):
        return None
    for name in COMPUTED.get(body[0], ()):
        if (
            name in getattr(comp, "__dict__", {})
            or _where(getattr(cls, name, None)) != WRITTEN[name]
        ):
            return None
    return body


def driver() -> tuple[type, Any, Any] | None:
    """What the robots' bodies need to command the rover's driver themselves: the rover
    class with its ``set_power`` and ``update_drive`` as written in ``physics/rover.py``
    (and its ``_saturate``), or None if any was replaced (a test, a plugin), so the body
    calls ``rover.set_power`` in Python. Why: that call, two frames and two item writes,
    was a fifth of a robot's step, three and a half times an env-step. The body also checks
    at every step that the rover is of this class and the methods are still these.

    The module is looked up by name, as the bodies' classes are (:data:`BODIES`): the engine
    never imports the physics (``tests/structure/test_layers.py``); a robot's module has
    loaded it before any robot is stepped."""
    rover = sys.modules.get("amsa_phys.physics.rover")
    cls = getattr(rover, "DiffDriveRover", None)
    if cls is None:
        return None
    set_power, update = cls.__dict__.get("set_power"), cls.__dict__.get("update_drive")
    mod = "amsa_phys.physics.rover"
    if (
        _where(set_power) != (mod, "DiffDriveRover.set_power")
        or _where(update) != (mod, "DiffDriveRover.update_drive")
        or _where(rover._saturate) != (mod, "_saturate")
    ):
        return None
    return cls, set_power, update


def _where(fn: Any) -> tuple[Any, Any]:
    """Where a function was written: its module and qualified name."""
    return getattr(fn, "__module__", None), getattr(fn, "__qualname__", None)


def kernel(
    make: Any,
    task: Task,
    values: Any,
    fallback: Callable[[Task, Fraction], None],
    judges: Callable[[Task], tuple[Callable[..., None], Callable[..., None]]],
) -> Any:
    """``task``'s step as a compiled body (see the module docstring) made by ``make``
    (``publish.kernel()``, asked by the caller once), or None: no body for this component.
    ``fallback`` is the component's ordinary step; ``judges(task)`` gives the scalar step's
    ``(failed, judge)`` (``Steppers._judges``), for what a robot's or a sensor's body meets
    after it has called into Python."""
    body = body_of(task.comp)
    if body is None:
        return None
    code, ins, outs = body
    reads = dict(task.reads)
    writes = task.writes
    # every input connected and every output bound to a position: else the Python step
    if set(reads) != set(ins) or any(type(reads[p]) is not int or reads[p] < 0 for p in ins):
        return None
    if set(writes) != set(outs) or any(type(writes[p]) is not int for p in outs):
        return None
    return make(
        code,
        task.comp,
        tuple(reads[p] for p in ins),
        tuple(writes[p] for p in outs),
        values,
        fallback,
        *judges(task),
        driver() if code in (2, 3) else None,
    )
