"""What a template shows: the marks it declares for the window, the video, the plots and
the Gymnasium renderer.

The pictures must not recognise templates by name: a user's own GPS template, declared in
their package under any name, should be drawn like the built-in one. So, as pymunk's shapes
tell its drawing protocol what they are, a template lists its marks
(``Template.marks``) and every picture draws what is declared:

* :class:`Fix` -- a position fix published on two output ports (the GPS's crosses, its lost
  fixes, the trajectory plot's fix tracks);
* :class:`Scan` -- a range scan held by the running component (the lidar's beams);
* :class:`Zone` -- a patch of ground given by parameters (the terrain zones, live, replayed
  and plotted);
* :class:`StandIn` -- a component whose behaviour comes from outside (an agent): its
  parameters act on nothing, so the HUD does not list them.

Plain frozen data, no behaviour: a top-level module because the model declares marks and
``view``, ``plots``, ``gym`` and ``runs`` read them, none importing another for it.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, TypeVar


@dataclass(frozen=True)
class Fix:
    """A position fix in world metres on output ports ``x`` and ``y``.

    ``measures``: the input port wired to the true x of what is measured (its source names
    the rover: ``Leader.posX`` -> ``Leader``), so fixes take the rover's colour and lost
    fixes are marked where the rover really was. ``lost``: the running component's counter
    of lost samples (live pictures mark each new loss). ``loss_params``: parameters that,
    above 0, make it lose samples (a finished run's trace is searched for losses only then).
    """

    x: str
    y: str
    measures: str = ""
    lost: str = ""
    loss_params: tuple[str, ...] = ()


@dataclass(frozen=True)
class Scan:
    """A range scan: the running component's attribute ``latest`` holds ``(x, y, heading,
    ranges)`` (None before the first), ``angles`` names its method giving each beam's angle
    from the heading, ``max_range`` the parameter a beam without echo reads, ``mount`` the
    attribute naming the body it is mounted on (whose colour it is drawn in)."""

    latest: str = "scan"
    angles: str = "angles"
    max_range: str = "range_max"
    mount: str = "mount"


@dataclass(frozen=True)
class Zone:
    """A patch of ground: the parameters holding its polygon, friction and rolling
    resistance (changes to the last two are shown as the run makes them)."""

    polygon: str = "polygon"
    friction: str = "friction"
    rolling_resistance: str = "rollingResistance"


@dataclass(frozen=True)
class StandIn:
    """The component stands in for another whose behaviour comes from outside (an agent
    acting in its place): its parameters act on nothing."""


#: every kind of mark a template may declare
Mark = Fix | Scan | Zone | StandIn

M = TypeVar("M", Fix, Scan, Zone, StandIn)


def marks_of(template: Any, kind: type[M]) -> Iterator[M]:
    """The marks of ``kind`` a template class declares (none for a template declaring none)."""
    for mark in getattr(template, "marks", ()):
        if isinstance(mark, kind):
            yield mark


def marked(leaves: Any, kind: type[M]) -> Iterator[tuple[str, Any, M]]:
    """``(path, leaf, mark)`` for every mark of ``kind`` in a world's leaves
    (``WorldSpec.leaves``: path -> leaf), in declaration order."""
    for path, leaf in leaves.items():
        for mark in marks_of(leaf.template, kind):
            yield path, leaf, mark
