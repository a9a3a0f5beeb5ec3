"""User templates that misbehave: a load error (exit 2) or a run fault (exit 3), never a
traceback, a silent exit or a lost sweep row / test scenario.

The runtime cases use ``tests/rogue.py`` (importable as ``rogue``); the import-time cases
write their module into the test's own directory.
"""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
import uuid
from pathlib import Path

import pytest
from deadlines import HANG_S

from amsa_phys.cli.main import main

TESTS = Path(__file__).resolve().parent.parent
ENV = {**os.environ, "PYTHONPATH": str(TESTS)}


def rogue(tmp_path: Path, mode: str, extra: str = "", name: str = "s") -> Path:
    path = tmp_path / f"{name}.yaml"
    path.write_text(
        "world:\n  components:\n"
        f"    R: {{template: 'rogue:Rogue', freq: 4, params: {{mode: {mode}}}}}\n"
        f"duration: 3\n{extra}"
    )
    return path


def one_error(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1, err
    return err


@pytest.mark.parametrize(
    ("mode", "cause"),
    [
        ("list", "do_step must return a mapping of outputs, got [1.0, 2.0]"),
        ("huge", "output u is too large for a float"),
        ("exit0", "do_step raised SystemExit(0)"),
        ("exit7", "do_step raised SystemExit(7)"),
    ],
)
def test_a_misbehaving_do_step_is_a_run_fault(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], mode: str, cause: str
) -> None:
    out = tmp_path / "o"
    assert main(["run", str(rogue(tmp_path, mode)), "--headless", "--out", str(out), "-q"]) == 3
    # a SystemExit raised in the user's own code: loop's hint says how to see its traceback
    hint = " (amsa-phys --debug shows its traceback)" if "SystemExit" in cause else ""
    assert one_error(capsys) == f"error: run fault at t=1.000 s in R (Rogue): {cause}{hint}\n"
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"] == f"fault: run fault at t=1.000 s in R (Rogue): {cause}"
    assert (out / "trace.csv").read_text().splitlines()[-1].startswith("0.95,")


def test_sys_exit_in_initialize_or_on_param_change_is_a_run_fault(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = rogue(tmp_path, "init_exit")
    assert main(["run", str(scen), "--headless", "--out", str(tmp_path / "a"), "-q"]) == 3
    assert one_error(capsys) == (
        "error: run fault at t=0.000 s in R (Rogue): initialize failed: SystemExit(0)"
        " (amsa-phys --debug shows its traceback)\n"
    )
    assert (tmp_path / "a" / "trace.csv").read_text() == "t,R.u\n"  # no instant ran
    assert (tmp_path / "a" / "trajectory.png").stat().st_size > 0  # drawn all the same
    scen = rogue(tmp_path, "param_exit", "timeline:\n  - {at: 2, set: {R.k: 2}}\n")
    assert main(["run", str(scen), "--headless", "--out", str(tmp_path / "b"), "-q"]) == 3
    assert one_error(capsys) == (
        "error: run fault at t=2.000 s in R (Rogue): rejected k=2.0: "
        "on_param_change raised SystemExit(0)\n"
    )


def test_step_many_with_the_wrong_number_of_rows_is_a_run_fault(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # 40 copies step as one group (engine/batch.MIN_GROUP is 32): step_many returns 43 rows
    scen = tmp_path / "many.yaml"
    scen.write_text(
        "world:\n  components:\n    Car:\n      count: 40\n      components:\n"
        "        R: {template: 'rogue:Rogue', freq: 4, params: {mode: rows}}\n"
        "duration: 3\n"
    )
    assert main(["run", str(scen), "--headless", "--out", str(tmp_path / "o"), "-q"]) == 3
    assert one_error(capsys) == (
        "error: run fault at t=1.000 s in Car1.R (Rogue): output u of step_many has shape "
        "(43,), expected (40,): one number per copy\n"
    )


def test_sys_exit_in_a_sweep_is_a_row_error_not_a_lost_sweep(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "sw"
    scen = rogue(tmp_path, "exit7")
    argv = ["sweep", str(scen), "--grid", "R.k=1,2", "-j", "1", "--out", str(out)]
    # one run per process, do_step's SystemExit (a batch steps Rogue's copies by step_many)
    assert main([*argv, "--executor", "local"]) == 0
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert [r["error"] for r in rows] == [
        "run fault at t=1.000 s in R (Rogue): do_step raised SystemExit(7)"
    ] * 2
    # no run completed: nothing to draw, so no summary.png
    assert not (out / "summary.png").exists()


def test_sys_exit_in_a_test_suite_is_an_error_row_serial_and_parallel(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    expect = "expect:\n  - {trace: R.u, below: 5}\n"
    bad = rogue(tmp_path, "exit0", expect, name="bad")
    good = rogue(tmp_path, "none", expect, name="good")
    assert main(["test", str(bad), str(good), "-j", "1"]) == 1
    captured = capsys.readouterr()
    assert captured.out.splitlines()[1].split() == ["bad", "load", "and", "run", "-", "-", "ERROR"]
    assert captured.out.splitlines()[-1] == "2 scenarios, 1 check: 1 passed, 0 failed, 1 error"
    assert captured.err == (
        "error: bad: run fault at t=1.000 s in R (Rogue): do_step raised SystemExit(0)\n"
    )
    # in worker processes a SystemExit used to travel back and end the whole command
    proc = subprocess.run(
        [sys.executable, "-m", "amsa_phys", "test", str(bad), str(good), "-j", "2"],
        capture_output=True,
        text=True,
        env=ENV,
        timeout=HANG_S,
        check=False,
    )
    assert proc.returncode == 1, proc.stderr
    assert proc.stdout == captured.out
    assert proc.stderr == captured.err


@pytest.mark.parametrize(
    ("source", "cause"),
    [
        ("raise RuntimeError('boom at import')\n", "importing it raised RuntimeError"),
        ("def broken(:\n", "syntax error at {module}.py:1: invalid syntax"),
        ("import sys\nsys.exit(3)\n", "importing it raised SystemExit(3)"),
    ],
    ids=["raises", "syntax-error", "sys-exit"],
)
def test_a_user_module_that_fails_to_import_is_a_load_error(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    source: str,
    cause: str,
) -> None:
    module = f"user_{uuid.uuid4().hex[:8]}"
    (tmp_path / f"{module}.py").write_text(source)
    monkeypatch.syspath_prepend(str(tmp_path))
    world = tmp_path / "w.yaml"
    world.write_text(f"components:\n  C: {{template: '{module}:T', freq: 4}}\n")
    assert main(["validate", str(world)]) == 2
    assert one_error(capsys).startswith(
        f"error: {world}:2: components.C.template: cannot import module '{module}': "
        + cause.format(module=module)
    )


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("Nope", "unknown template 'Nope'; built-in: freeRobot, controlledRobot, GPS"),
        ("gps", "unknown template 'gps' (did you mean GPS?)"),
        ("Follower", "unknown template 'Follower' (did you mean FollowerController?)"),
        (
            "nosuch.mod:X",
            "cannot import module 'nosuch.mod': No module named 'nosuch' (user templates load "
            "from sys.path: install its package, or put its folder on PYTHONPATH); built-in:",
        ),
        (":X", "':X' is not a template name nor package.module:Class"),
        (".foo:X", "'.foo:X' is not a template name nor package.module:Class"),
        ("..:X", "'..:X' is not a template name nor package.module:Class"),
    ],
)
def test_templates_with_a_bad_name_says_so_in_one_line(
    capsys: pytest.CaptureFixture[str], name: str, message: str
) -> None:
    assert main(["templates", name]) == 2
    assert one_error(capsys).startswith(f"error: templates: {message}")


def test_templates_into_a_closed_pipe_exits_quietly() -> None:
    # `amsa-phys templates | head -1`: the reader is gone before we write
    proc = subprocess.Popen(
        [sys.executable, "-m", "amsa_phys", "templates"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=ENV,
    )
    assert proc.stdout is not None
    assert proc.stderr is not None
    proc.stdout.close()
    err = proc.stderr.read()
    assert proc.wait(timeout=HANG_S) == 141  # 128 + SIGPIPE, as `yes | head -1` gives
    assert err == b""
