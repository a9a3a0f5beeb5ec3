"""``amsa-phys test`` and the pytest plugin on the shipped and a failing scenario."""

from __future__ import annotations

import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import sigint
from deadlines import HANG_S

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
FAILING = ROOT / "tests" / "fixtures" / "failing_expect.yaml"


def test_shipped_scenarios_pass(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["test", str(ROOT / "scenarios"), "-j", "2"]) == 0
    out = capsys.readouterr().out
    assert "20 scenarios, 58 checks: 58 passed, 0 failed" in out


def test_failing_scenario_gives_exit_1_a_table_and_junit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    junit = tmp_path / "report.xml"
    assert main(["test", str(FAILING), "--junit", str(junit), "-j", "1"]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split() == ["scenario", "check", "measured", "bound", "result"]
    assert any(
        line.split()[:2] == ["failing_expect", "max_distance"] and line.endswith("FAIL")
        for line in lines
    )
    assert any("collisions" in line and line.endswith("pass") for line in lines)
    assert lines[-1] == "1 scenario, 3 checks: 1 passed, 2 failed"
    root = ET.parse(junit).getroot()
    suite = root.find("testsuite")
    assert suite is not None
    assert suite.get("tests") == "3"
    assert suite.get("failures") == "2"
    failures = [f.get("message") for f in root.iter("failure")]
    assert failures[0].startswith("max_distance = ")
    assert failures[0].endswith("below 16: FAIL")


def test_a_folder_without_scenario_tests_is_a_usage_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["test", str(tmp_path)]) == 2
    assert "no scenario with an expect: section found" in capsys.readouterr().err


def test_pytest_collects_scenarios_in_a_users_project(tmp_path: Path) -> None:
    project = tmp_path / "proj" / "scenarios"
    project.mkdir(parents=True)
    for name in ("scenario2.yaml",):
        text = (
            (ROOT / "scenarios" / name)
            .read_text()
            .replace("../worlds/mde_challenge.yaml", str(ROOT / "worlds" / "mde_challenge.yaml"))
        )
        (project / name).write_text(text)
    failing = FAILING.read_text().replace(
        "../../worlds/mde_challenge.yaml", str(ROOT / "worlds" / "mde_challenge.yaml")
    )
    (project / "failing.yaml").write_text(failing)
    shutil.copy(ROOT / "worlds" / "mde_challenge.yaml", project / "not_a_scenario.yaml")
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "scenarios"],
        cwd=project.parent,
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 1, proc.stdout
    assert "1 failed, 1 passed" in proc.stdout
    assert "max_distance = 27.38, below 16: FAIL" in proc.stdout
    assert "Traceback" not in proc.stdout


@pytest.mark.usefixtures("python_sigint")  # toys:CtrlC interrupts this process
def test_ctrl_c_stops_the_whole_suite_not_just_one_scenario(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # an interrupted scenario is not a failed one: the suite must not go on to the next file
    text = (
        "world:\n  components:\n    K: {template: 'toys:CtrlC', freq: 4}\n"
        "duration: 100\nquality: {signal: K.u, reference: 0}\n"
        "expect:\n  - {metric: max_distance, below: 1000}\n"
    )
    (tmp_path / "a.yaml").write_text(text)
    (tmp_path / "b.yaml").write_text(text)
    assert main(["test", str(tmp_path), "-j", "1"]) == 130
    captured = capsys.readouterr()
    assert captured.err == "error: test interrupted after 0 of 2 scenarios; nothing reported\n"
    assert "scenarios," not in captured.out  # no table: nothing was reported as run


@pytest.mark.parametrize("how", ["ctrl-c", "kill-int-parent", "kill-term-parent"])
def test_ctrl_c_stops_a_parallel_suite_promptly(tmp_path: Path, how: str) -> None:
    # a terminal's Ctrl-C reaches every process; kill reaches the parent only, which must
    # stop its workers itself
    import os
    import signal

    from longrun import wait_until

    suite = tmp_path / "suite"
    suite.mkdir()
    text = (ROOT / "tests" / "fixtures" / "mde_short.yaml").read_text()
    text = text.replace("../../worlds/", f"{ROOT}/worlds/").replace("duration: 500", "")
    for name in "abcd":  # four runs of 100,000 s: finishing any would take minutes
        (suite / f"{name}.yaml").write_text(
            f"{text}duration: 100000\nexpect:\n  - {{metric: collisions, below: 1}}\n"
        )
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-m", "amsa_phys", "test", str(suite), "-j", "2", "--out", str(out)],
        stderr=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=sigint.at_default,
    )
    try:
        wait_until(  # both workers running, however loaded the machine
            "two scenarios are writing traces",
            lambda: len(list(out.glob("*/trace.csv.tmp"))) >= 2,
            proc,
        )
        if how == "ctrl-c":
            os.killpg(proc.pid, signal.SIGINT)  # the whole group
        else:
            proc.send_signal(signal.SIGINT if how == "kill-int-parent" else signal.SIGTERM)
        stdout, err = proc.communicate(timeout=HANG_S)
    finally:  # a suite that ignored Ctrl-C must not outlive the test with its workers
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 130, err
    assert err == "error: test interrupted after 0 of 4 scenarios; nothing reported\n"
    assert stdout == ""
    assert sorted(p.name for p in out.iterdir()) == ["a", "b"]  # c and d never started


def test_a_scenario_that_kills_its_worker_is_an_error_row(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for name, gain in (("a", 1), ("b", 2), ("c", 3)):
        (tmp_path / f"{name}.yaml").write_text(
            f"world:\n  components:\n    D: {{template: 'toys:Die', freq: 4, params: "
            f"{{gain: {gain}}}}}\nduration: 1\nexpect:\n  - {{trace: D.u, below: 5}}\n"
        )
    assert main(["test", str(tmp_path), "-j", "2"]) == 1
    captured = capsys.readouterr()
    rows = [line.split() for line in captured.out.splitlines()[1:-1]]
    assert [(r[0], r[-1]) for r in rows] == [("a", "pass"), ("b", "ERROR"), ("c", "pass")]
    assert captured.out.splitlines()[-1].endswith("1 error")
    assert (
        "b: a worker process died (killed, out of memory, or a crash in native code), twice"
        in captured.err
    )
