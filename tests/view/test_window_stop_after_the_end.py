"""Ctrl-C or SIGTERM once the run has ended in the window closes it like ``q``: the run is
whole, so it is not reported as cut short; while the run goes on, the same signal interrupts
it as before."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.engine import interrupt
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.view.window import Window

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"


def _window() -> tuple[Simulation, Window]:
    scenario = load_scenario(SCENARIO, duration=2)
    sim = Simulation.from_scenario(scenario)
    sim.initialize()
    return sim, Window(sim, scenario.quality, size=(320, 240))


def test_a_stop_after_the_end_closes_the_window_without_an_interruption() -> None:
    sim, w = _window()
    with interrupt.deferred():
        while not w.finished:
            assert w.frame(1.0)
        assert w.frame(1.0)  # finished: the window stays open for a look
        interrupt.request()
        try:
            closed = not w.frame(1.0)
        except KeyboardInterrupt:  # caught here: left to pytest, it would end the session
            pytest.fail("the ended run was interrupted instead of its window closed")
        assert closed  # as `q` closes it
    assert not w.running
    assert sim.now == 2


def test_a_stop_while_the_run_goes_on_still_interrupts_it() -> None:
    _sim, w = _window()
    with interrupt.deferred():
        w.frame(0.1)
        interrupt.request()
        with pytest.raises(KeyboardInterrupt):
            w.frame(0.1)
