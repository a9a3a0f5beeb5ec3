"""Component templates: the paper's "class" of a Leaf (kind, ports, parameters, behaviour).

A template is a Python class whose declaration is data: the loader, ``describe`` and
``templates`` read ``kind``, ``inputs``, ``outputs`` and ``params`` without running anything.
Built-in templates are registered by name as ``"module:Class"`` strings and imported only
when a world uses them, so this layer never imports the physics.
"""

from __future__ import annotations

import importlib
import re
from collections.abc import Mapping
from dataclasses import dataclass
from enum import Enum
from fractions import Fraction
from pathlib import Path
from typing import Any, ClassVar, Protocol

from ..templatemarks import Mark
from .suggest import did_you_mean


class Kind(str, Enum):
    """The six kinds of component of the AMSA architectural style."""

    PROCESS = "process"
    ENVIRONMENT = "environment"
    SENSOR = "sensor"
    ACTUATOR = "actuator"
    CONTROLLER = "controller"
    OBSERVER = "observer"


@dataclass(frozen=True)
class Port:
    """An input or output of a template. ``initial`` is what an unwritten buffer holds.

    An *array* port carries several numbers at once (a lidar's ranges). Data buffers hold one
    number each, so an array output ``ranges`` of a leaf ``Lidar`` is the buffers
    ``Lidar.ranges[0]`` .. ``Lidar.ranges[n-1]``, ``n`` being the value of the integer
    parameter named by ``size`` (fixed by the world: it sizes the buffers). An array input
    links to a whole array output (``ranges: Lidar.ranges``) and receives a numpy array of
    its length; ``do_step`` returns an array output as a sequence of that length. The trace
    thus has one column per element, and a scalar input or a quality signal may read one
    element (``Lidar.ranges[3]``).
    """

    name: str
    initial: float = 0.0
    description: str = ""
    unit: str = ""
    array: bool = False
    size: str = ""  # array outputs: the int parameter giving the length


class ParamValues:
    """A Leaf's live parameter values, read as attributes (``self.p.Kv``).

    The timeline writes here between steps, so a component always sees the current value
    without a lookup per step.
    """

    def __init__(self, values: Mapping[str, Any]) -> None:
        self.__dict__.update(values)

    def as_dict(self) -> dict[str, Any]:
        """A copy of the current values."""
        return dict(self.__dict__)


class InitContext(Protocol):
    """What ``initialize`` receives from the engine (``engine.context.Context``).

    Attributes:
        rng: the Leaf's own ``numpy.random.Generator``, keyed by the scenario's seed and the
            Leaf's path (split it by purpose with ``rng.spawn(n)``).
        path: the Leaf's dotted path in the world.
        world: the loaded world (read only): ``world.leaves[path]`` gives a Leaf's template,
            parameters and input links.

    ``shared(name, factory)`` returns the run's service ``name`` (the physics world), made by
    ``factory(sim)`` on first request; ``add_hook(rate_hz, fn, name)`` calls ``fn()`` at
    ``rate_hz`` after the components due at the same instant (only during ``initialize``);
    ``record_event(kind, detail)`` records an event at the current simulated time. The manual's
    tutorial "Your first template" describes each, and how a batch or a ROS node differs.
    """

    rng: Any
    path: str
    world: Any

    def shared(self, name: str, factory: Any) -> Any: ...

    def add_hook(self, rate_hz: Fraction, fn: Any, name: str) -> None: ...

    def record_event(self, kind: str, detail: str) -> None: ...


class Template:
    """Base of every component template.

    Subclasses set the class attributes and override :meth:`initialize` and :meth:`do_step`.
    ``do_step`` takes the inputs read at the start of the step and returns the outputs to
    publish at its end (run-to-completion); a missing key publishes nothing, so consumers
    keep the previous value.

    A template may also define a classmethod ``step_many(comps, t, inputs, p, state)`` that
    steps many copies of itself at once (``engine/batch.py``): ``inputs`` maps each input
    port to an array with one value per copy, ``p`` gives each parameter as such an array,
    ``state`` is a dict kept for the group; it returns ``(outputs, published)`` with one
    array per output port and a boolean mask of the copies that publish (``None``: all).
    A leaf is stepped either always through ``step_many`` or always through ``do_step``.
    """

    kind: ClassVar[Kind]
    inputs: ClassVar[tuple[Port, ...]] = ()
    outputs: ClassVar[tuple[Port, ...]] = ()
    params: ClassVar[tuple[Any, ...]] = ()  # tuple[Param, ...]
    #: Name used in files; defaults to the class name.
    template_name: ClassVar[str] = ""
    #: Parameters read only by ``initialize`` (a body's mass, an initial pose): changing them
    #: once the run has started is refused, so the window's parameter panel does not offer it.
    fixed_once_running: ClassVar[frozenset[str]] = frozenset()
    #: Other names a parameter answers to (``{"noise": "stddev"}``): the paper's names kept
    #: working beside the Gazebo/SDFormat ones. Files, ``--set`` and sweeps may use either;
    #: resolved scenarios write the canonical name.
    param_aliases: ClassVar[Mapping[str, str]] = {}
    #: Parameters that are the setpoint of the quantity a scenario's quality signal judges
    #: (a follower's ``distanceRef``): a run that moves one away from ``quality.reference``
    #: is judged against a reference its controller no longer aims at, so it is warned.
    setpoints: ClassVar[frozenset[str]] = frozenset()
    #: Whether a leaf of this template may draw random numbers that reach its outputs; a
    #: template whose randomness depends on its values overrides :meth:`is_random`. The
    #: default (True) is the safe answer for user templates: ``sweep`` warns that seeds
    #: cannot differ only when every leaf says False.
    uses_random: ClassVar[bool] = True
    #: Capabilities a batch of runs relies on (``runs/batched.py``), declared here rather
    #: than inferred from names. ``batchable``: runs of one batch may hold this template
    #: (None: yes if it defines ``step_many``; the built-in templates declare it).
    #: ``shares_physics``: copies in different runs can share the batch's one physics world
    #: (False for what changes the ground itself, a terrain zone).
    #: ``batch_params_at_start``: a batch sets this template's parameters at t = 0 only (a
    #: rover's, held in the batch's columns), so a timeline that changes them mid-run runs
    #: alone.
    batchable: ClassVar[bool | None] = None
    shares_physics: ClassVar[bool] = True
    batch_params_at_start: ClassVar[bool] = False
    #: What the pictures draw of this template (``amsa_phys/templatemarks.py``): a position
    #: fix on two output ports, a range scan, a zone of ground, a stand-in. The window, the
    #: video, the plots and the Gymnasium renderer draw what is declared here, never by
    #: template name, so a user's own GPS declaring a fix is drawn like the built-in one.
    marks: ClassVar[tuple[Mark, ...]] = ()

    def __init__(self, path: str, params: Mapping[str, Any]) -> None:
        self.path = path
        # direct construction (tests, scripts) may give a few values, by any alias: the rest
        # are the declared defaults
        aliases = self.param_aliases
        values = {p.name: p.default for p in self.params}
        values.update({aliases.get(k, k): v for k, v in params.items()})
        self.p = ParamValues(values)

    @classmethod
    def name(cls) -> str:
        """The template's name as written in world files."""
        return cls.template_name or cls.__name__

    @classmethod
    def describe(cls) -> str:
        """The first line of the docstring."""
        doc = (cls.__doc__ or "").strip()
        return doc.splitlines()[0] if doc else ""

    @classmethod
    def param(cls, name: str) -> Any:
        """The declared parameter called ``name`` or aliased by it (KeyError if none)."""
        name = cls.param_aliases.get(name, name)
        for p in cls.params:
            if p.name == name:
                return p
        raise KeyError(name)

    @classmethod
    def canonical(cls, name: str) -> str:
        """The declared name of parameter ``name`` (``noise`` -> ``stddev``)."""
        return cls.param_aliases.get(name, name)

    @classmethod
    def aliases_of(cls, name: str) -> list[str]:
        """The other names of declared parameter ``name``."""
        return [a for a, target in cls.param_aliases.items() if target == name]

    @classmethod
    def size_params(cls) -> frozenset[str]:
        """Parameters that size array outputs: fixed by the world, like a body's mass."""
        return frozenset(p.size for p in cls.outputs if p.array and p.size)

    @classmethod
    def has_arrays(cls) -> bool:
        """Whether any port is an array (the engine steps such leaves on a general path)."""
        return any(p.array for p in (*cls.inputs, *cls.outputs))

    @classmethod
    def is_random(cls, values: Mapping[str, Any]) -> bool:
        """Whether a leaf with parameter ``values`` has random outputs (see ``uses_random``)."""
        return cls.uses_random

    def initialize(self, ctx: InitContext) -> None:
        """The paper's ``initialize()``: called once, before the first step."""

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's ``doStep()``: one run-to-completion step at simulated time ``t``."""
        return {}

    def on_param_change(self, name: str, value: Any) -> None:
        """Called after the timeline or the user changed a parameter (``self.p`` is updated)."""

    @classmethod
    def check_params(cls, values: Mapping[str, Any]) -> None:
        """Rules *between* parameters (each one's type and range is its Param's job).

        Raise ValueError saying what is wrong. Called on every leaf's values at load time --
        after the world, after ``set`` and after each timeline entry -- so ``validate`` and
        ``run`` refuse a scenario that would break a rule (exit 2, naming the key), and by
        the window's panel before a live change is queued. ``initialize`` and
        ``on_param_change`` should call it too, for changes made from code.
        """


#: Built-in templates: name -> "module:Class", imported on first use.
BUILTINS: dict[str, str] = {
    "freeRobot": "amsa_phys.physics.templates:FreeRobot",
    "controlledRobot": "amsa_phys.physics.templates:ControlledRobot",
    "GPS": "amsa_phys.sensors.gps:GPS",
    "GNSS": "amsa_phys.physics.gnss:GNSS",
    "gpsDeniedZone": "amsa_phys.physics.gnss:GpsDeniedZone",
    "Compass": "amsa_phys.sensors.compass:Compass",
    "IMU": "amsa_phys.sensors.imu:IMU",
    "WheelOdometry": "amsa_phys.sensors.odometry:WheelOdometry",
    "Lidar": "amsa_phys.physics.lidar:Lidar",
    "StampedCompass": "amsa_phys.sensors.compass:StampedCompass",
    "StampedIMU": "amsa_phys.sensors.imu:StampedIMU",
    "StampedWheelOdometry": "amsa_phys.sensors.odometry:StampedWheelOdometry",
    "StampedLidar": "amsa_phys.physics.lidar:StampedLidar",
    "GoalMonitor": "amsa_phys.control.monitor:GoalMonitor",
    "ReactiveAvoider": "amsa_phys.control.avoider:ReactiveAvoider",
    "DistanceMonitor": "amsa_phys.control.monitor:DistanceMonitor",
    "GpsDistance": "amsa_phys.control.gpsdistance:GpsDistance",
    "NormalizePower": "amsa_phys.control.normalize:NormalizePower",
    "FollowerController": "amsa_phys.control.follower:FollowerController",
    "ConstantPower": "amsa_phys.control.constant:ConstantPower",
    "frictionZone": "amsa_phys.physics.zones:FrictionZone",
    "gradeZone": "amsa_phys.physics.zones:GradeZone",
    "GPSLossMonitor": "amsa_phys.control.estimators.gpsloss:GPSLossMonitor",
    "MotorMonitor": "amsa_phys.control.estimators.motor:MotorMonitor",
    "LeaderMonitor": "amsa_phys.control.estimators.leader:LeaderMonitor",
    "SwingMonitor": "amsa_phys.control.estimators.swing:SwingMonitor",
}


class TemplateNotFound(LookupError):
    """A template reference that names nothing; the message says why."""


#: An absolute dotted module path (``.foo`` or ``..`` would be a relative import).
_MODULE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*")


def _import(module_name: str) -> Any:
    """Import a user module; whatever goes wrong in it becomes one line naming the module.

    A user module may fail to import in any way -- missing, a syntax error, an exception
    or even ``sys.exit()`` at import time: all are the world's problem, reported where the
    world names the template (exit 2), never a traceback.
    """
    try:
        return importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        hint = ""
        if exc.name == module_name.split(".")[0]:  # the module itself, not one it imports
            hint = (
                " (user templates load from sys.path: install its package, or put its folder"
                " on PYTHONPATH)"
            )
        raise TemplateNotFound(f"cannot import module {module_name!r}: {exc}{hint}") from None
    except SyntaxError as exc:
        where = f"{Path(exc.filename).name}:{exc.lineno}" if exc.filename else "its source"
        raise TemplateNotFound(
            f"cannot import module {module_name!r}: syntax error at {where}: {exc.msg}"
        ) from None
    except (Exception, SystemExit) as exc:
        raise TemplateNotFound(
            f"cannot import module {module_name!r}: importing it raised {exc!r}"
        ) from None


def known_names() -> list[str]:
    """Every short template name a world may use: built-ins, then installed plugins'
    (what "did you mean" suggests from)."""
    from .plugins import installed

    return [*BUILTINS, *(n for n in installed() if n not in BUILTINS)]


def _plugin_target(name: str) -> str:
    """The ``module:Class`` an installed plugin registers under ``name``."""
    from .plugins import target_of

    try:
        target = target_of(name)
    except LookupError as exc:
        raise TemplateNotFound(str(exc)) from None
    if target is None:
        raise TemplateNotFound(f"unknown template {name!r}")
    return target


def resolve_template(ref: str) -> type[Template]:
    """Return the template class for a built-in name, an installed plugin's name (the
    ``amsa_phys.templates`` entry points, :mod:`.plugins`) or an explicit ``module:Class``.

    Code is loaded only where a world names it: a ``module:Class`` it writes, or a plugin
    name whose package the user installed; the module is imported like any Python import.
    """
    target = BUILTINS.get(ref)
    if target is None:
        target = _plugin_target(ref) if ":" not in ref else ref
    module_name, _, attr = target.partition(":")
    if not _MODULE.fullmatch(module_name) or not attr.isidentifier():
        raise TemplateNotFound(
            f"{ref!r} is not a template name nor package.module:Class "
            "(a dotted module path, then a class name)"
        )
    module = _import(module_name)
    cls = getattr(module, attr, None)
    if cls is None:
        found = [
            n for n, v in vars(module).items() if isinstance(v, type) and issubclass(v, Template)
        ]
        raise TemplateNotFound(
            f"module {module_name!r} has no {attr!r}" + did_you_mean(attr, found)
        )
    if not (isinstance(cls, type) and issubclass(cls, Template)):
        raise TemplateNotFound(
            f"{target!r} is not a Template subclass (from amsa_phys import Template)"
        )
    kind = getattr(cls, "kind", None)
    if not isinstance(kind, Kind):
        got = "none" if kind is None else repr(kind)
        raise TemplateNotFound(
            f"template {target!r} declares no valid kind (got {got}); valid kinds: "
            f"{', '.join(k.value for k in Kind)} (e.g. kind = Kind.CONTROLLER, "
            "from amsa_phys import Kind)"
        )
    return cls
