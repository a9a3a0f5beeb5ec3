"""Component templates: the paper's "class" of a Leaf (kind, ports, parameters, behaviour).

A template is a Python class whose declaration is data: the loader, ``describe`` and
``templates`` read ``kind``, ``inputs``, ``outputs`` and ``params`` without running anything.
Built-in templates are registered by name as ``"module:Class"`` strings and imported only
when a world uses them, so this layer never imports the physics.
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping
from dataclasses import dataclass
from enum import Enum
from fractions import Fraction
from typing import Any, ClassVar, Protocol


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
    """An input or output of a template. ``initial`` is what an unwritten buffer holds."""

    name: str
    initial: float = 0.0
    description: str = ""
    unit: str = ""


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
    """What ``initialize`` receives from the engine (see ``engine.runner.Context``)."""

    rng: Any
    path: str

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

    def __init__(self, path: str, params: Mapping[str, Any]) -> None:
        self.path = path
        self.p = ParamValues(params)

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
        """The declared parameter called ``name`` (KeyError if none)."""
        for p in cls.params:
            if p.name == name:
                return p
        raise KeyError(name)

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
    "Compass": "amsa_phys.sensors.compass:Compass",
    "DistanceMonitor": "amsa_phys.control.monitor:DistanceMonitor",
    "NormalizePower": "amsa_phys.control.normalize:NormalizePower",
    "FollowerController": "amsa_phys.control.follower:FollowerController",
    "ConstantPower": "amsa_phys.control.constant:ConstantPower",
    "frictionZone": "amsa_phys.physics.terrain:FrictionZone",
}


class TemplateNotFound(LookupError):
    """A template reference that names nothing; the message says why."""


def resolve_template(ref: str) -> type[Template]:
    """Return the template class for a built-in name or an explicit ``module:Class``.

    A ``module:Class`` reference is the only way user code is loaded: the world file names
    it explicitly, and the module is imported like any Python import.
    """
    target = BUILTINS.get(ref)
    if target is None:
        if ":" not in ref:
            raise TemplateNotFound(f"unknown template {ref!r}")
        target = ref
    module_name, _, attr = target.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise TemplateNotFound(f"cannot import module {module_name!r}: {exc}") from None
    cls = getattr(module, attr, None)
    if not (isinstance(cls, type) and issubclass(cls, Template)):
        raise TemplateNotFound(f"{target!r} is not a Template subclass")
    if not isinstance(getattr(cls, "kind", None), Kind):
        raise TemplateNotFound(f"template {target!r} declares no valid kind")
    return cls
