"""Arithmetic components stepped as compiled bodies (``engine/kernels.py``) give the runs,
the episodes and the faults of their Python steps, bit for bit."""

from __future__ import annotations

import importlib.util
from array import array
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import amsa_phys as ap
from amsa_phys.control.monitor import DistanceMonitor
from amsa_phys.control.normalize import NormalizePower
from amsa_phys.engine import kernels, publish
from amsa_phys.engine.tasks import Steppers, Task
from amsa_phys.errors import RunFault
from amsa_phys.gym import FollowEnv
from amsa_phys.physics.freerobot import FreeRobot
from amsa_phys.physics.robots import ControlledRobot
from amsa_phys.sensors.compass import Compass
from amsa_phys.sensors.gps import GPS

ROOT = Path(__file__).resolve().parents[2]
#: built, and not switched off (``AMSA_PHYS_PURE=1``: the Python paths alone run)
BUILT = (
    importlib.util.find_spec("amsa_phys.engine._kernels") is not None
    and publish._extension("_kernels") is not None
)
needs_c = pytest.mark.skipif(
    not BUILT, reason="the extension was not built (no C compiler), or the pure path was asked for"
)
NOW = Fraction(5, 4)

#: scenario2 whose actuator's parameters change mid-run (the body reads them at each step):
#: worn motors from 20 s, a narrower range from 40 s, an int coefficient back at 60 s
CHANGING: dict[str, Any] = {
    "name": "kernels",
    "world": str(ROOT / "worlds" / "mde_challenge.yaml"),
    "duration": 80,
    "seed": 3,
    "set": {"Leader.behavior": 4, "LeaderGPS.lostDataGPS": 10},
    "timeline": [
        {"at": 20, "set": {"MyNormalizePower.motorCoef": 60}},
        {"at": 40, "set": {"MyNormalizePower.powerMax": 7.5, "MyNormalizePower.powerMin": -3.0}},
        {"at": 60, "set": {"MyNormalizePower.motorCoef": 85}},
    ],
}


def _leader(behavior: int, **more: Any) -> dict[str, Any]:
    """The MDE world, its leader driving by ``behavior``; a wheel parameter changes at 15 s."""
    return {
        "name": f"leader{behavior}",
        "world": str(ROOT / "worlds" / "mde_challenge.yaml"),
        "duration": 30,
        "seed": 5,
        "set": {"Leader.behavior": behavior, "Leader.cruisePower": 12.0, **more},
        "timeline": [{"at": 15, "set": {"Follower.freeSpeed": 4.0, "Leader.cruisePower": 20.0}}],
    }


def _without_bodies(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(kernels, "BODIES", {})


def _trace(source: Any) -> bytes:
    return ap.run(source).trace.tobytes()


@needs_c
def test_the_follow_world_steps_its_components_in_c() -> None:
    """Else the comparisons below would compare the Python step with itself."""
    env = FollowEnv()
    env.reset(seed=0)
    steps = {t.path: type(run).__name__ for e in env._episode.sim._plan for run, t in e[1]}
    env.close()
    for path in ("MyDistanceMonitor", "MyNormalizePower", "Leader", "Follower"):
        assert steps[path] == "Kernel", path
    for path in ("LeaderGPS", "FollowerGPS", "FollowerCompass"):
        assert steps[path] == "Kernel", path
    assert steps["MyFollowerController"] != "Kernel"  # the agent: delayed, its own step


@pytest.mark.parametrize(
    "source",
    [
        str(ROOT / "scenarios" / "scenario1.yaml"),
        str(ROOT / "scenarios" / "paper_fig6.yaml"),
        CHANGING,
        str(ROOT / "scenarios" / "obstacle_course.yaml"),  # contacts: collisions
        _leader(2, **{"Leader.circleRadius": 6.0}),
        _leader(3),
        _leader(5, **{"Leader.waypoints": [[30, 10], [10, 25], [0, 0]]}),
        # a battery and windings: the follower's Python step (its supply), the leader's body
        _leader(4, **{"Follower.batteryCapacity": 0.05, "Follower.motorThermalTau": 30.0}),
    ],
    ids=[
        "scenario1",
        "paper_fig6",
        "parameters-change",
        "obstacles",
        "circle",
        "speeds",
        "waypoints",
        "supply",
    ],
)
def test_runs_are_byte_identical_with_and_without_the_bodies(
    source: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    compiled = _trace(source)
    _without_bodies(monkeypatch)
    assert _trace(source) == compiled


def _episode(actions: np.ndarray) -> bytes:
    env = FollowEnv(duration=30)
    obs, _ = env.reset(seed=11)
    rows = [obs]
    rewards = []
    for a in actions:
        obs, reward, _, truncated, info = env.step(a)
        rows.append(obs)
        rewards.append([reward, info["signal"]])
        if truncated:
            break
    env.close()
    return np.concatenate([np.ravel(rows), np.ravel(rewards)]).tobytes()


def test_episodes_are_byte_identical_with_and_without_the_bodies(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    actions = np.random.default_rng(4).uniform(-1.2, 1.2, (130, 2))  # past the end, clamped
    compiled = _episode(actions)
    _without_bodies(monkeypatch)
    assert _episode(actions) == compiled


# -- one step, against the Python step, on what a run rarely meets -------------------------
def _stepped(comp: Any, inputs: list[float], body: bool) -> tuple[list[float], str, str]:
    """The store after one step of ``comp`` (inputs first, then its outputs), its fault,
    and how it stepped."""
    return _stepped_at(comp, inputs, body, NOW)


def _stepped_at(
    comp: Any, inputs: list[float], body: bool, now: Fraction
) -> tuple[list[float], str, str]:
    """:func:`_stepped` at ``now``."""
    ins = [p.name for p in comp.inputs]
    outs = [p.name for p in comp.outputs]
    n = len(ins)
    values = array("d", [*inputs, *[-7.0] * len(outs)])
    task = Task("C", comp, 1, [(p, f"S.{p}") for p in ins], {p: f"C.{p}" for p in outs})
    where = {f"S.{p}": i for i, p in enumerate(ins)} | {f"C.{p}": n + i for i, p in enumerate(outs)}
    task.bind(where.__getitem__)
    steppers = Steppers(values, lambda *_: None, lambda p: f"{p} (T)")
    if not body:  # the Python step (the packed store's other compiled step stays out too)
        steppers._scalar = steppers._kernel = None
    step = steppers.for_task(task)
    assert body or type(step).__name__ != "Kernel"  # else a body compared with itself
    try:
        step(task, now)
    except RunFault as exc:
        return values.tolist(), str(exc), type(step).__name__
    return values.tolist(), "", type(step).__name__


INF, NAN = float("inf"), float("nan")
MONITOR_INPUTS = [
    [3.0, 4.0, 0.0, 0.0],
    [1e308, -1e308, -1e308, 1e308],  # an infinite distance: a fault
    [NAN, 0.0, 0.0, 0.0],
    [INF, 0.0, INF, 0.0],  # inf - inf
    [5e-324, 0.0, 0.0, 0.0],
    [0.1, 0.2, 0.3, 0.4],
]


@needs_c
@pytest.mark.parametrize("inputs", MONITOR_INPUTS, ids=repr)
def test_the_monitor_body_publishes_and_faults_as_its_python_step(inputs: list[float]) -> None:
    got = _stepped(DistanceMonitor("M", {}), inputs, True)
    want = _stepped(DistanceMonitor("M", {}), inputs, False)
    assert got[2] == "Kernel"
    assert np.array(got[0]).tobytes() == np.array(want[0]).tobytes()
    assert got[1] == want[1]


def _normaliser(**params: Any) -> NormalizePower:
    comp = NormalizePower("N", {})
    comp.p.__dict__.update(params)
    return comp


POWERS = [[150.0, -150.0], [12.5, -0.3], [NAN, INF], [-INF, 99.99]]
PARAMS: list[dict[str, Any]] = [
    {},
    {"motorCoef": 60},
    {"motorCoef": 37.5},  # a float coefficient
    {"powerMin": -3.0, "powerMax": 7.5, "motorCoef": 7},
    {"powerMin": -5, "powerMax": 5},  # ints: the Python step compares them itself
    {"motorCoef": True},
    {"motorCoef": "60"},  # not a number: the Python step's fault
    {"powerMax": INF, "motorCoef": 100},  # an infinite output: its fault
]


@needs_c
@pytest.mark.parametrize("params", PARAMS, ids=repr)
@pytest.mark.parametrize("powers", POWERS, ids=repr)
def test_the_actuator_body_publishes_and_faults_as_its_python_step(
    powers: list[float], params: dict[str, Any]
) -> None:
    got = _stepped(_normaliser(**params), powers, True)
    want = _stepped(_normaliser(**params), powers, False)
    assert got[2] == "Kernel"
    assert np.array(got[0]).tobytes() == np.array(want[0]).tobytes()
    assert got[1] == want[1]


def test_a_replaced_step_is_called_not_the_body(monkeypatch: pytest.MonkeyPatch) -> None:
    """A class's do_step replaced (a test's, a plugin's), or an instance's own: that is
    what runs."""
    monkeypatch.setattr(
        DistanceMonitor, "do_step", lambda self, t, inp: {"distanceFollowerToLeader": 1.25}
    )
    values, fault, how = _stepped(DistanceMonitor("M", {}), [3.0, 4.0, 0.0, 0.0], True)
    assert (values[-1], fault, how) == (1.25, "", "Scalar" if BUILT else "function")
    monkeypatch.undo()
    comp = _normaliser()
    comp.do_step = lambda t, inp: {"normalizedPowerL": 2.0}  # type: ignore[method-assign]
    values, fault, how = _stepped(comp, [10.0, 10.0], True)
    assert values[2:] == [2.0, -7.0]
    assert how != "Kernel"


class Louder(NormalizePower):
    """A subclass: its step may differ (here it does), so it never runs as the body."""

    def do_step(self, t: Fraction, inp: Any) -> Any:
        return {"normalizedPowerL": 1.0, "normalizedPowerR": 1.0}


def test_a_subclass_is_stepped_as_written() -> None:
    values, _, how = _stepped(Louder("N", {}), [50.0, 50.0], True)
    assert values[2:] == [1.0, 1.0]
    assert how != "Kernel"


# -- the robots' bodies, on what the physics rarely gives -----------------------------------
class Rover:
    """A rover's readers and driver, as the physics world attaches them, giving ``state``."""

    def __init__(self, state: Any, rims: Any = (0.25, -0.5), fail: bool = False) -> None:
        self._source = (lambda: state) if state is not None else None
        self._rims = (lambda: rims) if rims is not None else None
        self.fail = fail
        self.powers: list[tuple[float, float]] = []

    def set_power(self, left: float, right: float) -> None:
        if self.fail:
            raise RuntimeError("driver fault")
        self.powers.append((left, right))

    def kinematics(self) -> Any:  # the pure path's reader (no physics step attached)
        return (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)


STATES = [
    (1.5, -2.0, 0.7, 1.25, -0.5, 0.1),
    (1.5, -2.0, -7.0, 1.25, -0.5, 0.1),  # a heading far from [-pi, pi)
    (1.5, -2.0, 3.141592653589793, 0.0, -0.0, -0.0),
    (1.5, float("nan"), 0.7, 1.25, -0.5, 0.1),  # a blown-up body: the fault
    (1.5, -2.0, float("inf"), 1.25, -0.5, 0.1),
    [1.5, -2.0, 0.7, 1.25, -0.5, 0.1],  # a list
    np.array([1.5, -2.0, 0.7, 1.25, -0.5, 0.1]),  # numpy floats: _pose's own dict
    (1, -2, 0, 1, 0, 0),  # ints
    None,  # no reader attached: the Python step
]


def _robot(cls: type, state: Any, rims: Any = (0.25, -0.5), fail: bool = False) -> Any:
    comp = cls("R", {"behavior": 1, "cruisePower": 7.0} if cls is FreeRobot else {})
    comp.rover = Rover(state, rims, fail)
    return comp


@needs_c
@pytest.mark.parametrize("cls", [ControlledRobot, FreeRobot], ids=lambda c: c.__name__)
@pytest.mark.parametrize(
    ("state", "rims", "fail"),
    [(s, (0.25, -0.5), False) for s in STATES]
    + [(STATES[0], None, False), (STATES[0], (0.25, float("nan")), False)]
    + [(STATES[0], (0.25, -0.5), True)],
    ids=repr,
)
def test_a_robot_body_publishes_and_faults_as_its_python_step(
    cls: type, state: Any, rims: Any, fail: bool
) -> None:
    inputs = [33.0, -150.0] if cls is ControlledRobot else []
    comps = [_robot(cls, state, rims, fail) for _ in range(2)]
    got = _stepped(comps[0], inputs, True)
    want = _stepped(comps[1], inputs, False)
    assert got[2] == "Kernel"
    assert np.array(got[0]).tobytes() == np.array(want[0]).tobytes()
    assert got[1] == want[1]
    assert comps[0].rover.powers == comps[1].rover.powers  # the driver commanded alike


# -- the sensors' bodies: a sequence of steps against the Python step's ---------------------
SENSED: dict[str, Any] = {
    "name": "sensors",
    "world": str(ROOT / "worlds" / "mde_challenge.yaml"),
    "duration": 40,
    "seed": 9,
    "set": {
        "LeaderGPS.burstLoss": 20.0,
        "LeaderGPS.burstLength": 3.0,
        "FollowerGPS.lostDataGPS": 15,
        "FollowerCompass.lostData": 5.0,
        "FollowerCompass.deviationB": 0.0,
        "FollowerCompass.deviationC": 0.0,
        "FollowerCompass.deviationD": 0.0,
    },
    "timeline": [  # the Gauss-Markov factors change, then a fix arrives late, then again not
        {"at": 10, "set": {"FollowerGPS.dynamic_bias_correlation_time": 5.0}},
        {
            "at": 15,
            "set": {"FollowerCompass.dynamic_bias_stddev": 0.0, "FollowerGPS.precision": 0.0},
        },
        {"at": 20, "set": {"LeaderGPS.latency": 0.6, "FollowerCompass.precision": 0.0}},
        {"at": 30, "set": {"LeaderGPS.latency": 0.0, "FollowerCompass.deviationE": 0.02}},
    ],
}


def test_a_run_with_losses_bursts_latency_and_changing_noise_is_byte_identical(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    compiled = _trace(SENSED)
    _without_bodies(monkeypatch)
    assert _trace(SENSED) == compiled


class Ctx:
    def __init__(self, seed: int) -> None:
        self.rng = np.random.default_rng(seed)


def _sensor(cls: type, params: dict[str, Any]) -> Any:
    comp = cls("S", params)
    comp.initialize(Ctx(21))
    return comp


SENSOR_CASES: list[tuple[type, dict[str, Any]]] = [
    (Compass, {"stddev": 0.01, "deviationB": 0.02, "lostData": 20.0, "precision": 0.0017}),
    (Compass, {"stddev": 0.01, "dynamic_bias_stddev": 0.003, "dynamic_bias_correlation_time": 0.0}),
    (Compass, {"stddev": 0.0, "precision": 0.0}),
    (  # every term of the deviation and a turn-on bias, unrounded: their order shows
        Compass,
        {
            "stddev": 0.01,
            "bias_mean": 0.01,
            "bias_stddev": 0.005,
            "deviationB": 0.02,
            "deviationC": -0.013,
            "deviationD": 0.005,
            "deviationE": 0.0031,
            "precision": 0.0,
        },
    ),
    (GPS, {"stddev": 0.015, "dynamic_bias_stddev": 0.0055, "precision": 0.01, "lostDataGPS": 30}),
    (GPS, {"stddev": 0.5, "burstLoss": 30.0, "burstLength": 4.0, "precision": 0.0}),
    (GPS, {"stddev": 0.1, "latency": 0.5, "precision": 0.01}),  # delayed fixes: Python's
]
#: the true inputs at each step: ordinary ones, then what a blown-up physics would give
READINGS = [[1.0, 2.0], [1.5, 2.5], [-3.25, 7.0], [1e9, -1e9], [2.0, 2.0], [0.5, 0.25]] * 3 + [
    [1.7e308, 0.0],  # twice the heading overflows; so does a fix over its precision
    [float("inf"), 0.0],
    [float("nan"), 1.0],
]


@needs_c
@pytest.mark.parametrize(("cls", "params"), SENSOR_CASES, ids=repr)
def test_a_sensor_body_steps_as_its_python_step(cls: type, params: dict[str, Any]) -> None:
    """Step after step (the first is always Python's): the same fixes, losses, state and
    faults, to the bit."""
    body, python = _sensor(cls, params), _sensor(cls, params)
    for k, reading in enumerate(READINGS):
        now = Fraction(k, 4)
        inputs = reading[: len(cls.inputs)]
        got = _stepped_at(body, inputs, True, now)
        want = _stepped_at(python, inputs, False, now)
        assert k == 0 or got[2] == "Kernel"
        assert np.array(got[0]).tobytes() == np.array(want[0]).tobytes(), k
        assert got[1] == want[1], k
        state = ("t_prev", "lost", "b", "bx", "by", "bad", "_gm")
        assert [getattr(body, a, None) for a in state] == [getattr(python, a, None) for a in state]
        if got[1]:
            break
    if not any(params.get(k) for k in ("lostData", "lostDataGPS", "burstLoss")):
        assert got[1], "the last readings end the run with the Python step's fault"


@needs_c
@pytest.mark.parametrize("target", [0.9, -2.5, 3.0, float("nan")], ids=repr)
@pytest.mark.parametrize("change", [Fraction(100), Fraction(1, 4)], ids=["steering", "change-due"])
def test_a_random_leader_steers_as_its_python_step(target: float, change: Fraction) -> None:
    """Behaviour 4 between two changes is the body's; at a change, the method's (it draws)."""
    comps = []
    for _ in range(2):
        comp = FreeRobot("R", {"behavior": 4, "cruisePower": 9.0, "steerGain": 1.5})
        comp.rover = Rover(STATES[0])
        comp.rng = np.random.default_rng(2)
        comp.next_change, comp.target_heading, comp.speed_factor = change, target, 0.85
        comps.append(comp)
    got = _stepped(comps[0], [], True)
    want = _stepped(comps[1], [], False)
    assert got[2] == "Kernel"
    assert np.array(got[0]).tobytes() == np.array(want[0]).tobytes()
    assert got[1] == want[1]
    powers = [np.array(c.rover.powers).tobytes() for c in comps]
    assert powers[0] == powers[1]
    assert (comps[0].next_change, comps[0].target_heading) == (
        comps[1].next_change,
        comps[1].target_heading,
    ) or np.isnan(target)


@needs_c
@pytest.mark.parametrize("cls", [ControlledRobot, FreeRobot], ids=lambda c: c.__name__)
def test_a_robot_never_initialised_faults_as_its_python_step(cls: type) -> None:
    inputs = [1.0, 2.0] if cls is ControlledRobot else []
    got = _stepped(cls("R", {}), inputs, True)
    want = _stepped(cls("R", {}), inputs, False)
    assert got[2] == "Kernel"
    assert got[1] == want[1]
    assert "has no attribute" in got[1]
