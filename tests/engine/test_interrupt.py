"""Ctrl-C is noted during a run and raised between instants (engine/interrupt.py)."""

from __future__ import annotations

import json
import os
import signal
import threading
from pathlib import Path
from typing import Any

import pytest

from amsa_phys.engine import interrupt
from amsa_phys.errors import Interrupted
from amsa_phys.model.scenario import load_scenario
from amsa_phys.runs.single import run_scenario

pytestmark = pytest.mark.usefixtures("python_sigint")  # these tests interrupt themselves

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"


def test_first_ctrl_c_is_noted_the_second_raises_at_once() -> None:
    with interrupt.deferred():
        os.kill(os.getpid(), signal.SIGINT)
        assert interrupt.requested()
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGINT)
    assert not interrupt.requested()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_handler_somebody_else_installed_is_left_alone() -> None:
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)  # as in a sweep worker
    try:
        with interrupt.deferred():
            assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
            os.kill(os.getpid(), signal.SIGINT)
            assert not interrupt.requested()
    finally:
        signal.signal(signal.SIGINT, previous)


def test_sigterm_is_deferred_even_when_sigint_is_ignored() -> None:
    """``amsa-phys run ... &`` from a script starts with SIGINT ignored: the CLI's SIGTERM
    still only requests a stop while a run defers (it used to raise wherever the run was)."""
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with interrupt.sigterm_as_ctrl_c(), interrupt.deferred():
            assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN  # still left alone
            os.kill(os.getpid(), signal.SIGTERM)
            assert interrupt.requested()
            with pytest.raises(KeyboardInterrupt):  # a second one: at once
                os.kill(os.getpid(), signal.SIGTERM)
        assert not interrupt.requested()
    finally:
        signal.signal(signal.SIGINT, previous)


def test_outside_the_main_thread_nothing_is_installed() -> None:
    seen: list[Any] = []

    def worker() -> None:
        with interrupt.deferred():
            seen.append(signal.getsignal(signal.SIGINT))

    t = threading.Thread(target=worker)
    t.start()
    t.join()
    assert seen == [signal.default_int_handler]


class CtrlCWhilePlotting:
    """A plotter that receives Ctrl-C after the last instant, while drawing."""

    def begin(self, *args: Any) -> None:
        pass  # handed over; the files are written while the plots are drawn

    def finish(self) -> None:
        os.kill(os.getpid(), signal.SIGINT)

    def close(self) -> None:
        pass


def test_ctrl_c_after_the_last_instant_keeps_complete_outputs(tmp_path: Path) -> None:
    scenario = load_scenario(SCENARIO, duration=3)
    with pytest.raises(Interrupted, match=r"after the run ended at t=3\.00 s; its outputs are"):
        run_scenario(scenario, tmp_path, plotter=CtrlCWhilePlotting())  # type: ignore[arg-type]
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert (metrics["status"], metrics["simulated"]) == ("completed", 3.0)
    assert (tmp_path / "scenario.yaml").exists()


def test_a_request_after_the_blocks_last_look_is_raised_at_its_end() -> None:
    """A Ctrl-C noted after the deferring block last looked (while a progress bar closes)
    is raised when the block ends, not dropped: the command stops as the user asked."""
    with pytest.raises(KeyboardInterrupt), interrupt.deferred():
        os.kill(os.getpid(), signal.SIGINT)  # noted; nobody reads it before the end
    assert not interrupt.requested()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_request_read_in_the_block_is_the_readers_to_act_on() -> None:
    """A request the block read (and acted on: a run that ends its outputs, say) is not
    raised again at its end; nor does it replace an exception the block raised."""
    with interrupt.deferred():
        with interrupt.deferred():  # nested: the outermost end decides
            os.kill(os.getpid(), signal.SIGINT)
        assert interrupt.requested()

    def fails() -> None:
        with interrupt.deferred():
            os.kill(os.getpid(), signal.SIGINT)
            raise ValueError("the block's own")

    with pytest.raises(ValueError, match="the block's own"):
        fails()
    assert not interrupt.requested()
