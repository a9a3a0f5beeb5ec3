"""A generated ROS node stopped while it starts ends quietly, and hands its signals back
once it runs (``amsa_phys/ros/runtime/startup.py``).

Without ROS: the package's own node scripts run against a stand-in ``rospy`` whose import
holds until the test has sent its SIGINT, as roslaunch's reaches a node still importing
when a C++ Leaf has failed. The script must end with 130 and print nothing (it used to print
a ``KeyboardInterrupt`` traceback of 20–30 lines). Mutation-checked: without the script's
handler (``files/node.py.in``) each case fails with the traceback; without
:func:`startup.started` restoring the handlers, the hand-back test fails (and the
simulator's Ctrl-C during a run, ``tests/ros/test_ros.py``, would lose its outputs).
"""

from __future__ import annotations

import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import pytest
import sigint
from deadlines import HANG_S

from amsa_phys.cli.main import main
from amsa_phys.ros.runtime import startup

SCENARIO = Path(__file__).resolve().parent.parent / "fixtures" / "ros_short.yaml"
#: a ``rospy`` that says it is being imported, then waits (for the test's signal)
FAKE_ROSPY = "import os, sys\nos.write(1, b'importing rospy\\n')\nsys.stdin.read()\n"


@pytest.fixture(scope="module")
def package(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The exported package's node scripts; a directory holding the stand-in ``rospy``."""
    out = tmp_path_factory.mktemp("pkg") / "mdeChallenge"
    assert main(["export", "ros", str(SCENARIO), "-o", str(out)]) == 0
    fake = tmp_path_factory.mktemp("fake")
    (fake / "rospy").mkdir()
    (fake / "rospy" / "__init__.py").write_text(FAKE_ROSPY)
    return out / "nodes", fake


@pytest.mark.parametrize("script", ["amsa_simulator", "amsa_scenario", "MyFollowerController"])
def test_a_node_stopped_while_it_starts_says_nothing(
    package: tuple[Path, Path], script: str
) -> None:
    nodes, fake = package
    proc = subprocess.Popen(
        [sys.executable, str(nodes / f"{script}.py")],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={"PATH": "/usr/bin:/bin", "PYTHONPATH": str(fake)},
        preexec_fn=sigint.at_default,
    )
    try:
        assert proc.stdout is not None
        assert proc.stdout.readline() == b"importing rospy\n"  # the node is starting
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=HANG_S)
    finally:
        proc.kill()
    assert err == b""
    assert out == b""
    assert proc.returncode == 128 + signal.SIGINT


@pytest.fixture
def signals() -> Iterator[None]:
    """The test's own handlers put back afterwards."""
    kept = {s: signal.getsignal(s) for s in startup.SIGNALS}
    yield
    for sig, handler in kept.items():
        signal.signal(sig, handler)


def test_a_running_node_gets_its_signals_back(signals: None) -> None:
    """Once started, SIGINT raises KeyboardInterrupt again (the engine's Ctrl-C in the
    simulator takes only that handler) and SIGTERM is the default, with rospy's handlers
    installed on top for a rospy node; a signal the parent ignored stays ignored."""

    def starting(*_: object) -> None:
        raise AssertionError("not during a run")

    starting.amsa_previous = {  # type: ignore[attr-defined]
        signal.SIGINT: signal.default_int_handler,
        signal.SIGTERM: signal.SIG_DFL,
    }
    for sig in startup.SIGNALS:
        signal.signal(sig, starting)
    calls: list[str] = []
    rospy = SimpleNamespace(core=SimpleNamespace(register_signals=lambda: calls.append("ros")))
    startup.started(rospy)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL
    assert calls == ["ros"]
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    startup.started()
    assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN
