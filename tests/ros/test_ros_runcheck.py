"""``run_lockstep``'s verdict on a run directory, without ROS: the exit code a CI reads.

The run directories are ``amsa-phys run``'s own (the ROS simulator writes the same files);
the e2e test (``tests/ros/test_ros.py``) launches the script for real.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.ros.runtime.launchout import Seen
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


def test_a_run_that_did_not_start_names_the_error_above(tmp_path: Path) -> None:
    seen = Seen()
    seen.note("error: /MyFollowerController: /MyFollowerController/Kv: -5 is below the minimum 0")
    code, lines = judge(tmp_path, seen)
    assert code == 2
    assert lines == [
        f"run_lockstep: no run in {tmp_path} (metrics.json missing): the run did not start: "
        "see the error above (/MyFollowerController: /MyFollowerController/Kv: -5 is below "
        "the minimum 0)"
    ]


FAKE_ROSLAUNCH = """#!{python}
import sys
print("... logging to /tmp/x", flush=True)
print("error: /Leaf: {error}", file=sys.stderr, flush=True)
print("REQUIRED process [amsa_leaves-4] has died!", flush=True)
sys.exit({code})
"""


@pytest.mark.parametrize("code", [0, 1])
def test_run_lockstep_last_line_is_the_cause(tmp_path: Path, code: int) -> None:
    """The script itself, with a stand-in for roslaunch that fails the way a Leaf that
    refuses its parameters makes it fail: exit 2, and the last line names the Leaf's error
    (roslaunch's own exit code, if not 0, the line before)."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    fake = bin_dir / "roslaunch"
    fake.write_text(
        FAKE_ROSLAUNCH.format(python=sys.executable, error="Kv out of range", code=code)
    )
    fake.chmod(0o755)
    out = tmp_path / "out"
    script = "from amsa_phys.ros.runtime.runcheck import main; main('pkg')"
    done = subprocess.run(
        [sys.executable, "-c", script, "s1.launch", f"out:={out}"],
        capture_output=True,
        text=True,
        env={**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}"},
    )
    assert done.returncode == 2, done.stderr
    assert "... logging to /tmp/x" in done.stdout  # roslaunch's output passed through
    lines = done.stderr.splitlines()
    assert lines[0] == "error: /Leaf: Kv out of range"
    assert lines[-1] == (
        f"run_lockstep: no run in {out} (metrics.json missing): the run did not start: "
        "see the error above (/Leaf: Kv out of range)"
    )
    assert (lines[-2] == "run_lockstep: roslaunch exited with 1") == (code == 1)


def test_a_cut_run_says_how_many_checks_it_left_out(tmp_path: Path) -> None:
    """``duration:=`` cuts a run short: the checks it could not judge are skipped, said in
    the last line (the simulator's ``done:`` line says the same), not counted as passed."""
    scenario1 = SCENARIO.parent.parent.parent / "scenarios" / "scenario1.yaml"
    out = tmp_path / "cut"
    argv = ["run", str(scenario1), "--headless", "--out", str(out), "-q", "--no-plot"]
    main([*argv, "--duration", "100"])
    code, lines = judge(out)
    assert code == 0
    assert lines[-1] == (
        # "never closer than 3 m" is judged on the 100 s that ran; the rest reads later phases
        "run_lockstep: pass: 1 expectation passed, 5 skipped (not judged by this run: see "
        f"scenario.yaml) ({out})"
    )


def test_the_simulators_done_line_counts_skipped_checks_apart(tmp_path: Path) -> None:
    from amsa_phys.ros.runtime.ending import done_line
    from amsa_phys.runs.expect import Check

    checks = [Check(None, 1.0, True), Check(None, None, True, skipped=True, why="cut")]
    assert done_line(checks, tmp_path) == (
        f"amsa_simulator: done: 1 expectation passed, 1 skipped (not judged by this run); "
        f"outputs in {tmp_path}"
    )
