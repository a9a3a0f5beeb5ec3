"""``run_lockstep``'s verdict on a run directory, without ROS: the exit code a CI reads.

The run directories are ``amsa-phys run``'s own (the ROS simulator writes the same files);
the e2e test (``tests/e2e/test_ros.py``) launches the script for real.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.ros.runtime.runcheck import judge, launch_args

SCENARIO = Path(__file__).resolve().parent.parent / "fixtures" / "ros_short.yaml"


def _run(out: Path, *extra: str) -> Path:
    argv = ["run", str(SCENARIO), "--headless", "--out", str(out), "-q", "--no-plot"]
    main([*argv, "--duration", "10", *extra])
    return out


@pytest.fixture(scope="module")
def passing(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _run(tmp_path_factory.mktemp("pass") / "run")


def test_every_check_passed_is_0(passing: Path) -> None:
    code, lines = judge(passing)
    assert code == 0
    assert lines[-1].startswith("run_lockstep: pass: 1 expectation passed")


def test_a_failed_check_is_1(tmp_path: Path) -> None:
    out = _run(tmp_path / "run", "--set", "Leader.cruisePower=70")  # the follower falls behind
    code, lines = judge(out)
    assert code == 1
    assert "expect max_distance (phase 0) = 25.28, below 17: FAIL" in lines


def test_a_fault_or_no_run_is_2_and_an_interrupt_130(passing: Path, tmp_path: Path) -> None:
    assert judge(tmp_path)[0] == 2  # the simulator never wrote metrics.json
    for status, code in (("fault: run fault at t=1.000 s in X: boom", 2), ("interrupted", 130)):
        out = tmp_path / status.split(":")[0]
        out.mkdir()
        metrics = json.loads((passing / "metrics.json").read_text())
        (out / "metrics.json").write_text(json.dumps({**metrics, "status": status}))
        assert judge(out)[0] == code, status


def test_launch_arguments_default_to_lockstep_and_an_absolute_out(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    args, out = launch_args("s1.launch", ["plots:=false"])
    assert args[:2] == ["plots:=false", "mode:=lockstep"]
    assert out.parent == tmp_path / "runs"
    assert out.name.startswith("s1-")
    assert args[-1] == f"out:={out}"
    args, out = launch_args("s1.launch", ["mode:=free", "out:=rel"])
    assert args == ["mode:=free", f"out:={tmp_path / 'rel'}"]  # the node runs in ROS_HOME
