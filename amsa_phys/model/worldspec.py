"""A loaded world as data: Leaves, Composites, Data buffers and the WorldSpec.

Built by ``world.py`` (which re-exports these names); frozen where something could share
them (a WorldSpec and its LeafSpecs are cached and shared by a sweep's runs): a change is a
new object (``world.with_leaf``, ``changes.set_frequency``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

from ..errors import ConfigError
from .template import Template
from .timing import LeafTiming
from .yamlio import KeyPath, YamlDoc

#: The AMSA metamodel's default frequency (``TimeableObject.freq`` in amsaCore.ecore).
DEFAULT_FREQ_HZ = 10
#: Most Leaf components in a world, ``count:`` copies included (checked before any copy is
#: built: 30 aliases of a ``count: 10000`` Composite would be 300,000 from a 1 KB file).
MAX_COMPONENTS = 10_000

PHYSICS_DEFAULTS: dict[str, Any] = {
    "rate": 100,
    "gravity": 9.81,
    "ground": {"friction": 0.8, "rolling_resistance": 0.02},
    "obstacles": [],
    "walls": None,
    "max_speed": 100.0,
    "extent": 100000.0,
}


@dataclass(frozen=True)
class LeafSpec:
    """One Leaf component: a template instance with its frequency, parameters and links."""

    path: str
    template: type[Template]
    template_ref: str
    freq: Fraction
    params: dict[str, Any]
    #: input port -> buffer name (``Producer.path.output``)
    inputs: dict[str, str]
    keypath: KeyPath
    #: transport latency, jitter and timer phase (``model/timing.py``)
    timing: LeafTiming = field(default_factory=LeafTiming)

    @property
    def kind(self) -> Any:
        """The template's kind."""
        return self.template.kind


@dataclass
class CompositeSpec:
    """A Composite: a named group of components (the root is the system)."""

    path: str
    children: list[LeafSpec | CompositeSpec] = field(default_factory=list)


@dataclass
class BufferSpec:
    """A Data buffer: one producer's output, read by any number of consumers."""

    name: str
    producer: str
    port: str
    initial: Any


@dataclass(frozen=True)
class WorldSpec:
    """A loaded, checked world."""

    name: str
    source: YamlDoc
    keypath: KeyPath
    data: dict[str, Any]
    physics: dict[str, Any]
    root: CompositeSpec
    leaves: dict[str, LeafSpec]
    buffers: dict[str, BufferSpec]
    order: list[str]
    schedule: list[str]
    #: Named Data (``data:``, the AMSA model's Data names): name -> buffer ``Component.output``
    data_names: dict[str, str] = field(default_factory=dict)
    #: array outputs: ``Lidar.ranges`` -> its element buffers ``Lidar.ranges[0]``, ...
    arrays: dict[str, list[str]] = field(default_factory=dict)
    #: the world's ``timing:`` section (``free_running``, ``resolution``)
    timing: dict[str, Any] = field(default_factory=dict)

    @property
    def free_running(self) -> bool:
        """Whether Leaves without their own ``phase`` get a random one."""
        return bool(self.timing.get("free_running", False))

    def error(self, keypath: KeyPath, message: str) -> ConfigError:
        """A ConfigError at ``keypath`` (relative to this world) in its source file."""
        return self.source.error((*self.keypath, *keypath), message)
