"""The robots' compiled bodies command the rover's driver as ``DiffDriveRover.set_power``
does: the same saturation, deadband, attributes and batch slot, bit for bit, and the Python
method wherever the plain one does not apply (``engine/kernels.py``'s ``driver``)."""

from __future__ import annotations

import contextlib
import importlib.util
import sys
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from amsa_phys.engine import kernels, publish
from amsa_phys.engine.tasks import Steppers
from amsa_phys.gym import FollowEnv
from amsa_phys.physics.rover import DiffDriveRover

#: built, and not switched off (``AMSA_PHYS_PURE=1``: the Python paths alone run)
BUILT = (
    importlib.util.find_spec("amsa_phys.engine._kernels") is not None
    and publish._extension("_kernels") is not None
)
pytestmark = pytest.mark.skipif(
    not BUILT, reason="the extension was not built (no C compiler), or the pure path was asked for"
)

BAND = 2.0  # the MDE world's wheels' deadband (checked below)
NAN, INF = float("nan"), float("inf")
POWERS = [
    (33.0, -150.0),  # one saturated
    (150.0, NAN),  # a NaN saturates to -100, as min(100, max(-100, nan))
    (-INF, INF),
    (100.0, -100.0),  # the limits themselves
    (BAND, -BAND),  # the band's edges: outside the open band, applied
    (-BAND, BAND),
    (BAND / 2, -BAND / 2),  # inside: 0.0
    (-0.0, 0.0),
    (5e-324, -1e-300),
    (1.9999999999999998, -2.0000000000000004),
]
ATTRS = ("_power_l", "_power_r", "_drive_l", "_drive_r")


def _paused(seed: int = 3) -> FollowEnv:
    """An env one step in: the physics step has attached the rovers' batch slots."""
    env = FollowEnv(duration=10)
    env.reset(seed=seed)
    env.step(np.array([0.3, -0.2]))
    return env


def _follower(env: FollowEnv, body: bool) -> tuple[Any, Any, DiffDriveRover, Any]:
    """The follower's step (its body, or the Python step), its task and its rover."""
    sim = env._episode.sim
    task = next(t for e in sim._plan for _, t in e[1] if getattr(t, "path", "") == "Follower")
    steppers = Steppers(sim.store.data, lambda *_: None, lambda p: p, sim.store.col)
    if not body:
        steppers._scalar = steppers._kernel = None
    step = steppers.for_task(task)
    assert (type(step).__name__ == "Kernel") is body
    return step, task, task.comp.rover, sim


@contextlib.contextmanager
def _python_calls(name: str) -> Iterator[list[int]]:
    """Count the calls of Python functions named ``name`` meanwhile (``sys.setprofile``)."""
    count = [0]

    def profile(frame: Any, event: str, _arg: Any) -> None:
        if event == "call" and frame.f_code.co_name == name:
            count[0] += 1

    sys.setprofile(profile)
    try:
        yield count
    finally:
        sys.setprofile(None)


def _commanded(body: bool, powers: tuple[float, float], prepare: Any = None) -> tuple[Any, ...]:
    """The rover's commands, its batch slot and the store after the follower's step with
    ``powers`` as its inputs, and how many Python ``set_power`` calls it made."""
    env = _paused()
    step, task, rover, sim = _follower(env, body)
    assert rover.wheel.deadband_pct == BAND
    assert rover._slot is not None  # the compiled physics' slot: written too
    for (_, at), value in zip(task.reads, powers, strict=True):
        sim.store.data[at] = value
    if prepare is not None:
        prepare(rover)
    with _python_calls("set_power") as calls:
        step(task, sim.now)
    drives, i = rover._slot
    state = (
        np.array([rover.__dict__[a] for a in ATTRS]).tobytes(),
        np.array([drives[0, i], drives[1, i]]).tobytes(),
        np.asarray(drives).tobytes(),
        np.array(sim.store.data).tobytes(),
    )
    env.close()
    return state, calls[0]


@pytest.mark.parametrize("powers", POWERS, ids=repr)
def test_the_body_commands_the_driver_as_set_power(powers: tuple[float, float]) -> None:
    got, python = _commanded(True, powers)
    want, called = _commanded(False, powers)
    assert called == 1  # the Python step: set_power itself
    assert python == 0  # the body: the driver in C, no Python call
    assert got == want


def test_the_driver_values_are_the_documented_ones() -> None:
    """Not only alike: what set_power is meant to give (saturation, band, slot)."""
    env = _paused()
    step, task, rover, sim = _follower(env, True)
    for (_, at), value in zip(task.reads, (150.0, BAND / 2), strict=True):
        sim.store.data[at] = value
    step(task, sim.now)
    drives, i = rover._slot
    assert [rover.__dict__[a] for a in ATTRS] == [100.0, 1.0, 100.0, 0.0]
    assert (drives[0, i], drives[1, i]) == (100.0, 0.0)
    env.close()


def _replaced(rover: DiffDriveRover) -> None:
    original = DiffDriveRover.set_power

    def set_power(left: float, right: float) -> None:  # named so: counted as a Python call
        original(rover, left / 2, right / 2)

    rover.set_power = set_power  # type: ignore[method-assign]


def _pending(rover: DiffDriveRover) -> None:
    """A group command pending for this rover (``PhysicsWorld.set_powers``'s)."""
    k = rover._slot_k
    one = np.array([k])
    rover._pending.put(one, np.array([7.0]), np.array([8.0]), np.array([7.0]), np.array([8.0]))


@pytest.mark.parametrize("prepare", [_replaced, _pending], ids=["replaced", "pending"])
def test_what_the_plain_driver_does_not_cover_goes_to_python(prepare: Any) -> None:
    got, python = _commanded(True, (33.0, -150.0), prepare)
    want, _ = _commanded(False, (33.0, -150.0), prepare)
    assert python >= 1  # the rover's own set_power ran
    assert got == want


def test_a_replaced_class_method_is_called(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[tuple[float, float]] = []
    original = DiffDriveRover.set_power

    def set_power(self: DiffDriveRover, left: float, right: float) -> None:
        calls.append((left, right))
        original(self, left, right)

    env = _paused()
    step, task, _, sim = _follower(env, True)  # the body, made before the replacement
    monkeypatch.setattr(DiffDriveRover, "set_power", set_power)
    for (_, at), value in zip(task.reads, (12.0, -13.0), strict=True):
        sim.store.data[at] = value
    step(task, sim.now)
    env.close()
    assert calls == [(12.0, -13.0)]
    assert kernels.driver() is None  # and a body made now does not take it at all
