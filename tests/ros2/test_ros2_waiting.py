"""A ROS 2 run says at once which node it waits for; ``-q`` leaves the line out.

No node runs here: the run waits for ``/MyFollowerController`` and ends with the start
fault. The start wait (``external.START_TIMEOUT_S``, 60 s) is made 1 s for the test, so the
fault comes soon; the line must come before it either way. In ``unshare -n`` with the ROS 2
venv (``ros2net.py``).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from ros2net import PY, ROOT, in_private_network, ros2_missing

pytestmark = pytest.mark.ros2
MISSING = ros2_missing()
if MISSING:
    pytest.skip(MISSING, allow_module_level=True)

ENV = {"SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"}
SCENARIO = ROOT / "scenarios" / "scenario1.yaml"


def _run(tmp_path: Path, *extra: str) -> tuple[int, list[str], str]:
    argv = ["run", str(SCENARIO), "--headless", "--no-plot", "--duration", "1"]
    argv += ["--out", str(tmp_path / "r"), "--ros2", "MyFollowerController"]
    argv += ["--ros2-timeout", "1", *extra]
    code = (
        "import sys, amsa_phys.ros.external as e; e.START_TIMEOUT_S = 1.0; "
        "from amsa_phys.cli.main import main; sys.exit(main(sys.argv[1:]))"
    )
    err, domain = tmp_path / "err", tmp_path / "domain"
    script = tmp_path / "netns.sh"
    script.write_text(
        "ip link set lo up\n"
        f"echo $ROS_DOMAIN_ID > {domain}\n"
        f"{PY} -c '{code}' {' '.join(argv)} 2> {err}\n"
    )
    rc, left = in_private_network(script, ENV, tmp_path / "log")
    assert left == []
    return rc, err.read_text().splitlines(), domain.read_text().strip()


def test_the_wait_for_a_node_is_said_at_once_then_the_fault(tmp_path: Path) -> None:
    rc, lines, domain = _run(tmp_path)
    assert rc == 2, lines
    assert lines[0] == (
        f"waiting up to 1 s for ROS 2 node /MyFollowerController (ROS_DOMAIN_ID={domain})"
    )
    assert lines[-1].startswith("error: run fault at t=0.000 s in ROS 2 node /MyFollowerController")
    assert "no subscriber on /clock within 1 s" in lines[-1]  # as docs/ros2.md's table says


def test_quiet_leaves_the_waiting_line_out(tmp_path: Path) -> None:
    rc, lines, _ = _run(tmp_path, "-q")
    assert rc == 2, lines
    assert not any(line.startswith("waiting") for line in lines)
    assert "no subscriber on /clock" in lines[-1]
