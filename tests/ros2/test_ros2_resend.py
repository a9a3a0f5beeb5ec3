"""A parameter request whose answer is lost is sent again, not reported as a silent node.

A service's first answer can be lost while DDS discovery of the caller's reply reader is
still under way: the node answered, the answer went nowhere, and a run used to end with
"set_parameters did not answer within 10 s" against a correct node. ``Bridge._call`` sends
the request again every ``_RESEND_S`` until an answer comes or the timeout passes. Stand-in
client and executor (no rclpy: the quick tier); a real node answers in
``test_ros2_loop.py``.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest

from amsa_phys.ros.ros2 import bridge
from amsa_phys.ros.ros2.bridge import Bridge


class Clock:
    """Monotonic time that moves only when the executor waits."""

    def __init__(self) -> None:
        self.now = 0.0

    def monotonic(self) -> float:
        return self.now


class Future:
    def __init__(self) -> None:
        self.answer: Any = None

    def done(self) -> bool:
        return self.answer is not None


class Client:
    """Answers only the requests numbered in ``answered`` (1-based), one wait after sending."""

    def __init__(self, answered: set[int]) -> None:
        self.answered, self.sent, self.removed = answered, [], []

    def call_async(self, req: Any) -> Future:
        self.sent.append(Future())
        return self.sent[-1]

    def remove_pending_request(self, future: Future) -> None:
        self.removed.append(future)


def bridge_with(client: Client, clock: Clock, timeout_s: float) -> Any:
    def spin_once(timeout_sec: float) -> None:
        clock.now += timeout_sec
        for n, f in enumerate(client.sent, start=1):
            if n in client.answered and f.answer is None:
                f.answer = f"answer {n}"

    return SimpleNamespace(timeout_s=timeout_s, executor=SimpleNamespace(spin_once=spin_once))


@pytest.fixture
def clock(monkeypatch: pytest.MonkeyPatch) -> Clock:
    c = Clock()
    monkeypatch.setattr(bridge.time, "monotonic", c.monotonic)
    return c


def test_a_lost_answer_is_asked_again_and_the_second_taken(clock: Clock) -> None:
    client = Client(answered={2})  # the first answer lost
    got = Bridge._call(bridge_with(client, clock, timeout_s=10), client, "req")
    assert got is not None
    assert got.answer == "answer 2"
    assert len(client.sent) == 2
    assert client.removed == [client.sent[0]]  # the unanswered one is not kept pending
    assert clock.now < 10


def test_a_first_answer_sends_nothing_more(clock: Clock) -> None:
    client = Client(answered={1})
    got = Bridge._call(bridge_with(client, clock, timeout_s=10), client, "req")
    assert got is client.sent[0]
    assert len(client.sent) == 1
    assert client.removed == []


def test_no_answer_at_all_is_none_at_the_timeout(clock: Clock) -> None:
    client = Client(answered=set())
    got = Bridge._call(bridge_with(client, clock, timeout_s=3), client, "req")
    assert got is None
    assert clock.now == pytest.approx(3)
    assert len(client.sent) == pytest.approx(3 / bridge._RESEND_S)
    assert client.removed == client.sent
