"""The simulator's side of ``bag:=`` (``ros/runtime/bagtail.py``) without ROS: it never gets a
window of messages ahead of the recorder, waits for every message at the end, and gives up a
silent recorder with one line; and the recorder's arguments and count messages.

A C++ Leaf's roscpp publisher drops the oldest of 1000 queued messages instead of waiting
for a slow recorder, so the window is what keeps such a topic whole. Mutation-checked: the
window compared the wrong way, never asked, or the end not waited for, fail here.
"""

from __future__ import annotations

import threading
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from amsa_phys.ros.runtime import bagrecord, bagtail
from amsa_phys.ros.runtime.bagtail import EVERY, WINDOW, BagTail


class _String:
    def __init__(self, data: str) -> None:
        self.data = data


class _Recorder:
    """The recorder at the other end: answers each request at once with the counts asked
    (one that keeps up), or never (``silent``: it died, or was stopped)."""

    def __init__(self, silent: bool = False) -> None:
        self.silent = silent
        self.asked: list[dict[str, int]] = []
        self.tail: BagTail | None = None

    def publish(self, msg: _String) -> None:
        want = bagrecord.parse_counts(msg.data)
        self.asked.append(want)
        if self.silent:
            return
        assert self.tail is not None
        answer = _String(bagrecord.format_counts(want))
        threading.Thread(target=self.tail._on_written, args=(answer,)).start()


@pytest.fixture
def make(monkeypatch: pytest.MonkeyPatch) -> Any:
    monkeypatch.setattr(bagtail.rosio, "msgs", lambda: (None, _String, None))

    def build(counts: dict[str, int], silent: bool = False, timeout: float = 30.0) -> Any:
        recorder = _Recorder(silent)
        monkeypatch.setattr(bagtail.rosio, "make_publisher", lambda *_a, **_k: recorder)
        rospy = SimpleNamespace(Subscriber=lambda *_a, **_k: None, is_shutdown=lambda: False)
        tail = BagTail(rospy, lambda: dict(counts), timeout)
        recorder.tail = tail
        return tail, recorder

    return build


def test_the_simulator_waits_once_a_topic_is_a_window_ahead(make: Any) -> None:
    counts = {"/a": 0, "/b": 0}
    tail, recorder = make(counts)
    for _ in range(EVERY * 3):
        tail.tick()
    assert recorder.asked == []  # nothing ahead: no round trip
    counts["/a"] = WINDOW - 1
    for _ in range(EVERY):
        tail.tick()
    assert recorder.asked == []  # one short of a window
    counts["/a"] = WINDOW
    for _ in range(EVERY):
        tail.tick()
    # asked for all but half a window, and the recorder's answer counts from now on
    assert recorder.asked == [{"/a": WINDOW - WINDOW // 2, "/b": 0}]
    assert tail.written["/a"] == WINDOW - WINDOW // 2
    for _ in range(EVERY):
        tail.tick()
    assert len(recorder.asked) == 1  # within a window of the last answer: no new request
    assert tail.finish()
    assert recorder.asked[-1] == {"/a": WINDOW, "/b": 0}  # the end: every message


def test_a_silent_recorder_is_given_up_with_one_line(
    make: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    counts = {"/a": 5}
    tail, recorder = make(counts, silent=True, timeout=0.05)
    assert not tail.finish()
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "had written 0 of 5 messages of /a" in err
    assert "the bag is incomplete" in err
    counts["/a"] = 10 * WINDOW
    for _ in range(EVERY):
        tail.tick()
    assert len(recorder.asked) == 1  # given up: no more waiting


def test_the_recorder_takes_rosbag_records_arguments(tmp_path: Path) -> None:
    bag = tmp_path / "run.bag"
    assert bagrecord.parse_args(["-O", str(bag), "--tcpnodelay", "/a", "/b"]) == (
        bag,
        ["/a", "/b"],
    )
    assert bagrecord.parse_args(["-O", str(tmp_path / "run"), "/a"])[0] == bag
    with pytest.raises(SystemExit, match=r"expected -O FILE\.bag TOPIC"):
        bagrecord.parse_args(["/a"])


def test_counts_round_trip_and_refuse_other_text() -> None:
    counts = {"/Leader/posX": 301, "/Scanner/ranges": 0}
    assert bagrecord.parse_counts(bagrecord.format_counts(counts)) == counts
    with pytest.raises(ValueError, match="TOPIC COUNT"):
        bagrecord.parse_counts("flush")
