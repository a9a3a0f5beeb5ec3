"""Ctrl-C (or SIGTERM) while a run waits for its node stops the run, as it does mid-run.

No node runs: the run waits up to a minute for ``/MyFollowerController``. The user, who
forgot to start it, presses Ctrl-C: the run must end as an interrupted run (exit 130, the
outputs so far kept), not carry on waiting and end a minute later with the start fault.
The same while the node's ``set_parameters`` service does not answer (``--ros2-timeout``). In
``unshare -n`` with the ROS 2 venv (``ros2net.py``); ``set -m`` so that the run started
with ``&`` takes SIGINT (a script's background job ignores it otherwise).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from ros2net import NODE, PY, ROOT, in_private_network, ros2_missing

pytestmark = pytest.mark.ros2
MISSING = ros2_missing()
if MISSING:
    pytest.skip(MISSING, allow_module_level=True)

ENV = {"SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"}
SCENARIO = ROOT / "scenarios" / "scenario1.yaml"


@pytest.mark.parametrize("signal", ["INT", "TERM"])
def test_a_signal_while_waiting_for_the_node_interrupts_the_run(
    tmp_path: Path, signal: str
) -> None:
    out, err = tmp_path / "r", tmp_path / "err"
    argv = ["-m", "amsa_phys", "run", str(SCENARIO), "--headless", "--no-plot"]
    argv += ["--duration", "5", "--out", str(out), "--ros2", "MyFollowerController"]
    script = tmp_path / "netns.sh"
    script.write_text(
        "set -m\nip link set lo up\n"
        f"{PY} {' '.join(argv)} 2> {err} & RUN=$!\n"
        # the signal once the run says it waits (the node is missing)
        f"until grep -q '^waiting' {err} 2>/dev/null; do sleep 0.1; done\n"
        f"kill -{signal} $RUN; wait $RUN\n"
    )
    rc, left = in_private_network(script, ENV, tmp_path / "log")
    lines = err.read_text().splitlines()
    assert left == []
    assert rc == 130, lines
    assert lines[-1].startswith("error: interrupted at t=0"), lines
    assert (out / "metrics.json").exists()


def test_a_signal_while_the_parameter_service_is_silent_interrupts_the_run(
    tmp_path: Path,
) -> None:
    out, err = tmp_path / "r", tmp_path / "err"
    argv = ["-m", "amsa_phys", "run", str(SCENARIO), "--headless", "--no-plot"]
    argv += ["--duration", "5", "--out", str(out), "--ros2", "MyFollowerController"]
    argv += ["--ros2-timeout", "300"]
    script = tmp_path / "netns.sh"
    script.write_text(
        "set -m\nip link set lo up\n"
        f"{PY} {NODE} --mode mute > {tmp_path / 'node.log'} 2>&1 & NODE=$!\n"
        f"{PY} {' '.join(argv)} 2> {err} & RUN=$!\n"
        # the signal once the service was asked (the node blocks in its callback)
        f"until grep -q '^waiting' {err} 2>/dev/null; do sleep 0.1; done\n"
        "sleep 3\n"
        "kill -INT $RUN; wait $RUN; rc=$?\n"
        "kill -9 $NODE; wait $NODE\nexit $rc\n"
    )
    rc, left = in_private_network(script, ENV, tmp_path / "log")
    lines = err.read_text().splitlines()
    assert left == []
    assert rc == 130, lines
    assert lines[-1].startswith("error: interrupted at t=0"), lines
