"""A user's own rclpy controller node stepping a Leaf of a run (``run --ros2``, ``ros2:``).

The node (``follower_node.py``) is the paper's follower law written by hand, as a user would:
amsa-phys publishes its inputs on ``/clock`` and the producers' topics, awaits its outputs,
and the run must be the in-process run byte for byte. A node that breaks the contract ends
the run with one line naming it and the topic, exit 2, the trace so far kept, nothing left
running. Runs inside ``unshare -n`` with a domain of the test's own (``ros2net.py``).
"""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from ros2net import ROOT, ros2_missing, run_with_nodes, without_rclpy_task_noise

pytestmark = pytest.mark.ros2
MISSING = ros2_missing()
if MISSING:
    pytest.skip(MISSING, allow_module_level=True)

SCENARIO = ROOT / "scenarios" / "scenario1.yaml"
LEAF = "MyFollowerController"


def in_process(tmp: Path, *extra: str) -> Path:
    """The reference: the same scenario run by the engine alone (this venv, no ROS)."""
    out = tmp / "ref"
    subprocess.run(
        [
            sys.executable,
            "-m",
            "amsa_phys",
            "run",
            str(SCENARIO),
            "--headless",
            "--no-plot",
            "-q",
            "--out",
            str(out),
            *extra,
        ],
        check=True,
        capture_output=True,
        env={"SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"},
    )
    return out / "trace.csv"


def test_a_users_node_gives_the_in_process_trace_and_passes_the_expectations(
    tmp_path: Path,
) -> None:
    ref = in_process(tmp_path)
    out = tmp_path / "ros2"
    args = ["run", str(SCENARIO), "--headless", "--no-plot", "--out", str(out)]
    res = run_with_nodes(tmp_path, [*args, "--ros2", LEAF], [[]])
    assert res.rc == 0, res.stderr + res.node_log
    assert (out / "trace.csv").read_bytes() == ref.read_bytes()
    verdicts = [line for line in res.stdout.splitlines() if line.startswith("expect ")]
    # every expectation of the scenario, its STL requirements included, judged and passed
    assert len(verdicts) == len(yaml.safe_load(SCENARIO.read_text())["expect"]), verdicts
    assert all(v.endswith(": pass") for v in verdicts), verdicts
    # every step asked was answered; every parameter (7 at the start, Kv at 3 instants) set
    counts = json.loads((out / "metrics.json").read_text())["ros2"]["/" + LEAF]
    assert counts["steps"] == counts["answers"] == 2001  # 4 Hz over [0, 500] s
    assert counts["params_set"] == 7 + 3
    assert res.leftovers == []


def test_a_node_with_a_wrong_sign_fails_amsa_phys_test(tmp_path: Path) -> None:
    data = yaml.safe_load(SCENARIO.read_text())
    data["world"] = str((SCENARIO.parent / data["world"]).resolve())
    data["ros2"] = [LEAF]  # the scenario's own key: what test, sweep and falsify read
    scenario = tmp_path / "buggy.yaml"
    scenario.write_text(yaml.safe_dump(data))
    res = run_with_nodes(tmp_path, ["test", str(scenario), "-j", "1"], [["--mode", "sign"]])
    assert res.rc == 1, res.stdout + res.stderr + res.node_log
    assert "FAIL" in res.stdout, res.stdout
    assert "ERROR" not in res.stdout, res.stdout
    assert res.leftovers == []


FAULTS = {
    # mode: (what the one line must say, whether steps ran before the fault)
    "never": ("no message on /MyFollowerController/", False),
    "late": ("no message on /MyFollowerController/", True),
    "nan": ("published nan on /MyFollowerController/LeftPower", True),
    "wrongtype": (
        "publishes std_msgs/msg/Float32 on /MyFollowerController/LeftPower, "
        "expected std_msgs/msg/Float64",
        False,
    ),
    "besteffort": (
        "publishes on /MyFollowerController/LeftPower with a QoS that cannot match the run's "
        "(RELIABLE, VOLATILE): BEST_EFFORT",
        False,
    ),
    "die": ("/MyFollowerController/", True),
    "refuse": ("refused parameter Kv=0.05 (Kv below 0.1)", False),
    # rclpy's own reason names no parameter ("undeclared parameter(s): []"): the line does
    "undeclared": (
        "refused parameter Kw=0.04: the node has not declared Kw (declare every parameter "
        "describe --ros2 lists, with its type)",
        False,
    ),
}


@pytest.mark.parametrize("mode", sorted(FAULTS))
def test_a_node_breaking_the_contract_is_one_line_exit_2_trace_kept(
    tmp_path: Path, mode: str
) -> None:
    said, stepped = FAULTS[mode]
    extra = ["--set", f"{LEAF}.Kv=0.05"] if mode == "refuse" else []
    out = tmp_path / "ros2"
    args = ["run", str(SCENARIO), "--headless", "--no-plot", "-q", "--duration", "10"]
    args += ["--out", str(out), "--ros2", LEAF, "--ros2-timeout", "3", *extra]
    res = run_with_nodes(tmp_path, args, [["--mode", mode]])
    assert res.rc == 2, res.stdout + res.stderr + res.node_log
    errors = [line for line in res.stderr.splitlines() if line.strip()]
    assert len(errors) == 1, errors
    assert "ROS 2 node /MyFollowerController" in errors[0], errors
    assert said in errors[0], errors
    assert "Traceback" not in without_rclpy_task_noise(res.stderr)
    # the outputs written so far are kept: the trace up to the fault is the reference's
    trace = (out / "trace.csv").read_bytes()
    rows = trace.count(b"\n") - 1
    assert (rows > 1) == stepped, rows
    ref = in_process(tmp_path, "--duration", "10", *extra).read_bytes()
    assert ref.startswith(trace)
    assert (out / "metrics.json").exists()
    assert res.leftovers == []


def test_falsify_over_a_users_node_accounts_for_every_answer(tmp_path: Path) -> None:
    data = yaml.safe_load(SCENARIO.read_text())
    data["world"] = str((SCENARIO.parent / data["world"]).resolve())
    data["ros2"] = [LEAF]
    scenario = tmp_path / "ctx.yaml"
    scenario.write_text(yaml.safe_dump(data))
    out = tmp_path / "falsify"
    budget, duration = 4, 20
    args = ["falsify", str(scenario), "--range", "Leader.cruisePower=5:9"]
    args += ["--range", "MyNormalizePower.motorCoef=70:100", "--budget", str(budget)]
    args += ["--metric", "rms_error", "--duration", str(duration), "--out", str(out)]
    res = run_with_nodes(tmp_path, args, [[]])
    assert res.rc in (0, 1), res.stdout + res.stderr + res.node_log
    with (out / "results.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == budget
    assert all(not r["error"] for r in rows), [r["error"] for r in rows]
    # the node served every run, each from t = 0, and answered every step of each:
    # 4 Hz over [0, 20] s is 81 steps a run
    assert f"FOLLOWER runs={budget} steps={budget * (4 * duration + 1)}" in res.node_log
    assert res.leftovers == []


def test_sweep_over_two_domains_gives_the_in_process_sweep(tmp_path: Path) -> None:
    data = yaml.safe_load(SCENARIO.read_text())
    data["world"] = str((SCENARIO.parent / data["world"]).resolve())
    plain = tmp_path / "plain.yaml"
    plain.write_text(yaml.safe_dump(data))
    data["ros2"] = [LEAF]
    external = tmp_path / "ctx.yaml"
    external.write_text(yaml.safe_dump(data))
    grid = ["--grid", "Leader.cruisePower=5,6,7,8", "--duration", "20", "--executor", "local"]
    ref = tmp_path / "ref"
    subprocess.run(
        [sys.executable, "-m", "amsa_phys", "sweep", str(plain), *grid, "--out", str(ref)],
        check=True,
        capture_output=True,
        env={"SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"},
    )
    out = tmp_path / "ros2"
    args = ["sweep", str(external), *grid, "-j", "2", "--out", str(out)]
    # -j 2: two domains, the test's own and the next, a copy of the node in each
    res = run_with_nodes(tmp_path, args, [[], []], domains=[0, 1])
    assert res.rc == 0, res.stdout + res.stderr + res.node_log

    def rows(d: Path) -> list[dict[str, str]]:
        with (d / "results.csv").open() as f:
            return sorted(csv.DictReader(f), key=lambda r: int(r["run"]))

    got, want = rows(out), rows(ref)
    assert len(got) == 4
    assert all(not r["error"] for r in got), [r["error"] for r in got]
    assert got == want
    # each node served its domain's two runs, 81 steps each
    assert res.node_log.count("FOLLOWER runs=2 steps=162") == 2, res.node_log
    assert res.leftovers == []
