"""A ROS_DOMAIN_ID ROS 2 cannot use is one line before anything starts, not a crash.

``rcl`` refuses a value that is not a number with a traceback of rclpy's, and FastDDS ends
the process (exit 1, its own log lines) for a domain over 232, its ports out of range,
leaving a half-made run directory behind. amsa-phys reads the variable first: one line
naming it and what it may be, exit 2, no run directory. In ``unshare -n`` with the ROS 2
venv (``ros2net.py``).
"""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from ros2net import PY, ROOT, in_private_network, ros2_missing

pytestmark = pytest.mark.ros2
MISSING = ros2_missing()
if MISSING:
    pytest.skip(MISSING, allow_module_level=True)

ENV = {"SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"}
SCENARIO = ROOT / "scenarios" / "scenario1.yaml"


def _in_domain(tmp_path: Path, domain: str, argv: list[str]) -> list[str]:
    """``python ARGV`` with ``ROS_DOMAIN_ID=domain`` in a private network: its stderr lines,
    once it exited 2 and left no process behind."""
    err = tmp_path / "err"
    script = tmp_path / "netns.sh"
    script.write_text(
        f"ip link set lo up\nROS_DOMAIN_ID='{domain}' {PY} {' '.join(argv)} 2> {err}\n"
    )
    rc, left = in_private_network(script, ENV, tmp_path / "log")
    lines = err.read_text().splitlines()
    assert left == []
    assert rc == 2, lines
    return lines


@pytest.mark.parametrize("domain", ["abc", "300", "-1"])
def test_an_unusable_domain_id_is_one_line_before_the_run(tmp_path: Path, domain: str) -> None:
    out = tmp_path / "r"
    argv = ["-m", "amsa_phys", "run", str(SCENARIO), "--headless", "--no-plot", "-q"]
    argv += ["--duration", "1", "--out", str(out), "--ros2", "MyFollowerController"]
    assert _in_domain(tmp_path, domain, argv) == [
        f"error: --ros2: ROS_DOMAIN_ID={domain!r} is not a ROS 2 domain: an integer from 0 "
        "to 232 (unset: 0)"
    ]
    assert not out.exists()


def test_the_usual_domain_ids_are_taken() -> None:
    from amsa_phys.ros.ros2.env import domain_problem

    assert all(domain_problem(v) is None for v in (None, "", "0", "42", "232"))
    assert all(domain_problem(v) for v in ("abc", "233", "-1", "1.5", " 7"))


@pytest.mark.parametrize(
    ("domain", "said"),
    [
        ("abc", "error: sweep: ROS_DOMAIN_ID='abc' is not a ROS 2 domain"),
        ("231", "error: sweep: -j 3 runs in ROS_DOMAIN_ID=231 and the 2 after it, past 232"),
    ],
)
def test_a_sweep_over_domains_refuses_an_unusable_one(
    tmp_path: Path, domain: str, said: str
) -> None:
    data = yaml.safe_load(SCENARIO.read_text())
    data["world"] = str((SCENARIO.parent / data["world"]).resolve())
    data["ros2"] = ["MyFollowerController"]
    scenario = tmp_path / "s.yaml"
    scenario.write_text(yaml.safe_dump(data))
    argv = ["-m", "amsa_phys", "sweep", str(scenario), "--duration", "1", "-j", "3"]
    argv += ["--grid", "MyFollowerController.Kv=0.1,0.2,0.3", "--out", str(tmp_path / "sw")]
    lines = _in_domain(tmp_path, domain, argv)
    assert lines[-1].startswith(said), lines
    assert not any(line.startswith(("Traceback", "error")) for line in lines[:-1]), lines
    assert not (tmp_path / "sw").exists()  # refused before --out is made
