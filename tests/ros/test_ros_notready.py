"""A node that gives up waiting for its readers says which, after how long, and why."""

from __future__ import annotations

import time

from amsa_phys.ros.runtime.notready import message


class _Pub:
    def __init__(self, n: int) -> None:
        self.n = n

    def get_num_connections(self) -> int:
        return self.n


class _Gate:
    def __init__(self, *pubs: tuple[int, int, str]) -> None:
        self.pubs = [(_Pub(has), want, topic) for has, want, topic in pubs]


def test_the_message_names_each_topic_short_of_readers_and_the_simulator() -> None:
    gate = _Gate((2, 2, "/A/out"), (1, 3, "/B/out"), (0, 1, "/amsa/ready"))
    text = message("B", gate, time.monotonic() - 2.5)
    assert text.startswith("B: gave up after 2.5 s waiting for the readers of ")
    assert "/B/out (1 of 3 subscribers), /amsa/ready (0 of 1 subscribers);" in text
    assert "/A/out" not in text  # it has its readers
    assert "amsa_simulator reads each of them: if it did not start, its own error" in text
