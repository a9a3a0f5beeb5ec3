"""Component groups' arithmetic in one compiled call each (``_groupbodies.c``), where built.

Why: a vector env of 16 to 64 envs steps each component group through numpy calls on short
arrays, ~0.5 µs each whatever their length; a GPS group's fix was ~30 of them, a compass
group's ~20. The compiled bodies do the same elementwise operations, in the same order and
rounded the same way, as one loop: the same floats bit for bit (``tests/engine/
test_group_bodies.py`` holds them to the numpy path). Each template's ``step_many`` asks
here once per group and keeps its numpy path for what a body does not take (a group's first
step, delayed fixes, deviation terms) and for installs without the extension or with
``AMSA_PHYS_PURE=1`` (``publish.py``).
"""

from __future__ import annotations

from typing import Any

from . import publish


def gps_fix() -> Any:
    """``_groupbodies.gps_fix`` (the GPS group's fix after its first step), or None."""
    return _body("gps_fix")


def compass_heading() -> Any:
    """``_groupbodies.compass_heading`` (a compass group's heading without deviation terms,
    after its first step), or None."""
    return _body("compass_heading")


def distance() -> Any:
    """``_groupbodies.distance`` (a DistanceMonitor group's ``math.hypot`` of each member's
    differences), or None."""
    return _body("distance")


def deviation() -> Any:
    """``_groupbodies.deviation`` (a compass group's deviation terms combined from numpy's
    sines and cosines), or None."""
    return _body("deviation")


def follower() -> Any:
    """``_groupbodies.follower`` (a FollowerController group's whole step: its leader-speed
    estimate and its powers), or None."""
    return _body("follower")


def write_outputs() -> Any:
    """``_groupbodies.write_outputs`` (a group's finite float64 output columns written into the
    store in one call, ``Steppers.step_group``), or None."""
    return _body("write_outputs")


def gather_inputs() -> Any:
    """``_groupbodies.gather_inputs`` (a group's input columns copied out of the store into
    the rows of one new block in one call, ``Steppers.step_group``), or None."""
    return _body("gather_inputs")


def _body(name: str) -> Any:
    module = publish._extension("_groupbodies")
    return None if module is None else getattr(module, name, None)
