"""Free mode: a quality signal a node publishes is no measurement before its first message.

Until the node's first message the simulator's buffer holds the port's initial value (0.0):
counted as samples, a follower starting 8 m behind reported ``min_distance`` 0.000 and an rms
error inflated by the seconds of zeros. The simulator takes no quality sample until the
signal's first message (``Simulation.hold_quality``, released by ``RosSimulation.pace``).
"""

from __future__ import annotations

import threading
from fractions import Fraction
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np

from amsa_phys.engine.log import RunLog
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.runtime.rossim import RosSimulation, awaited_signal

ROOT = Path(__file__).resolve().parents[2]
SIGNAL = "MyDistanceMonitor.distanceFollowerToLeader"


def test_a_waiting_log_takes_no_quality_sample() -> None:
    log = RunLog(["a", "q"], None, "q")
    log.quality_waits = True
    log.record(0.0, {"a": 1.0, "q": 0.0})
    log.quality_waits = False
    log.record(0.05, {"a": 1.0, "q": 8.0})
    times, values = log.samples()
    assert times.tolist() == [0.05]
    assert values.tolist() == [8.0]


def test_the_signal_is_awaited_only_when_a_node_publishes_it() -> None:
    scenario = load_scenario(ROOT / "scenarios" / "scenario1.yaml")
    remote = [p for p in scenario.world.leaves if p not in ("Leader", "Follower")]
    assert awaited_signal(scenario, remote) == SIGNAL
    local_monitor = [p for p in remote if p != "MyDistanceMonitor"]
    assert awaited_signal(scenario, local_monitor) is None  # stepped in the simulator


class _Link:
    """The part of ``simulator.Link`` that ``pace`` uses: a rospy thread fills ``fresh``
    under ``cond``; ``take`` hands it to the engine."""

    def __init__(self, store: dict[str, float]) -> None:
        self.cond = threading.Condition()
        self.fresh: dict[str, Any] = {}
        self.store = store

    def pace(self, t: Fraction) -> None:
        pass

    def take(self) -> None:
        with self.cond:
            fresh, self.fresh = self.fresh, {}
        self.store.update(fresh)


def test_pacing_clears_the_wait_at_the_signals_first_message() -> None:
    store = {SIGNAL: 0.0}
    log = RunLog([SIGNAL], None, SIGNAL)
    log.quality_waits = True
    engine = SimpleNamespace(
        now=Fraction(0), hold_quality=lambda w: setattr(log, "quality_waits", w)
    )
    sim = SimpleNamespace(link=_Link(store), awaited=SIGNAL, sim=engine)
    RosSimulation.pace(sim)  # type: ignore[arg-type]
    log.record(0.0, store)
    sim.link.fresh["MyFollowerController.LeftPower"] = 3.0  # another topic: still waiting
    RosSimulation.pace(sim)  # type: ignore[arg-type]
    log.record(0.5, store)
    sim.link.fresh[SIGNAL] = 8.0  # the monitor node's first message
    RosSimulation.pace(sim)  # type: ignore[arg-type]
    log.record(1.8, store)
    assert log.samples()[0].tolist() == [1.8]
    assert log.samples()[1].tolist() == [8.0]
    assert sim.awaited is None


def test_metrics_from_the_first_measurement_match_the_in_process_run() -> None:
    """The engine with the signal awaited until 1.8 s: the samples are the in-process
    run's from 1.8 s on, so no zero reaches min_distance."""
    scenario = load_scenario(ROOT / "scenarios" / "scenario1.yaml", duration=20)
    full = Simulation.from_scenario(scenario)
    full.initialize()
    full.run()
    waited = Simulation.from_scenario(scenario)

    def first_message() -> None:
        if waited.now >= Fraction(9, 5):
            waited.hold_quality(False)

    waited.add_hook(Fraction(20), first_message, "first message")  # as RosSimulation does
    waited.initialize()
    waited.hold_quality(True)
    waited.run()
    t_all, s_all = full.result().samples_t, full.result().samples_s
    t, s = waited.result().samples_t, waited.result().samples_s
    assert t[0] >= 1.8
    np.testing.assert_array_equal(s, s_all[t_all >= t[0]])
    assert s.min() > 0
