"""A user template that breaks the run's contract: a fault of that component (exit 3, naming
it), never a clean run nor the user's Ctrl-C; and one that never returns still stops on the
first SIGTERM or Ctrl-C, with the outputs kept."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from deadlines import HANG_S

from amsa_phys.cli.main import main

TESTS = Path(__file__).resolve().parent.parent
ARGS = ("--no-plot", "--out")
PLUGIN = '''
from amsa_phys.model.params import Param
from amsa_phys.model.template import Kind, Port, Template


def _interrupt():
    raise KeyboardInterrupt


RETURNS = {
    "text": lambda: "10",
    "none": lambda: None,
    "zero": lambda: 0,
    "text-value": lambda: {"u": "10"},
    "bytes-value": lambda: {"u": b"1"},
    "kbint": _interrupt,
}
HOWS = ("ok", *RETURNS)


class Bad(Template):
    """Publishes u = 1 until t = 1 s, then returns what ``how`` says."""

    kind = Kind.CONTROLLER
    outputs = (Port("u"),)
    params = (Param("how", "enum", "what to return", "ok", choices=HOWS),)

    def do_step(self, t, inp):
        if t < 1 or self.p.how == "ok":
            return {"u": 1.0}
        return RETURNS[self.p.how]()
'''


def scenario(tmp_path: Path, how: str, extra: str = "") -> Path:
    (tmp_path / "badplugin.py").write_text(PLUGIN)
    path = tmp_path / "s.yaml"
    path.write_text(
        "world:\n  components:\n"
        f"    R: {{template: 'badplugin:Bad', freq: 4, params: {{how: {how}}}{extra}}}\n"
        "duration: 3\n"
    )
    return path


CASES = {
    "text": "do_step must return a mapping of outputs, got '10'",
    "none": "do_step must return a mapping of outputs, got None",
    "zero": "do_step must return a mapping of outputs, got 0",
    "text-value": "output u is not a number: '10'",
    "bytes-value": "output u is not a number: b'1'",
    "kbint": "raised KeyboardInterrupt() itself (not a Ctrl-C: a fault)",
}


@pytest.mark.parametrize("how", CASES, ids=list(CASES))
@pytest.mark.parametrize("delayed", [False, True], ids=["lean", "latency"])
def test_a_broken_return_is_a_fault_of_the_component(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    how: str,
    delayed: bool,
) -> None:
    monkeypatch.syspath_prepend(str(tmp_path))
    sys.modules.pop("badplugin", None)
    scen = scenario(tmp_path, how, ", latency: 0.1" if delayed else "")
    out = tmp_path / "o"
    assert main(["run", str(scen), "--headless", "-q", "--no-plot", "--out", str(out)]) == 3
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1, err
    assert err.startswith("error: run fault at t=1.000 s in R (Bad): ")
    assert CASES[how] in err
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"].startswith("fault: run fault at t=1.000 s in R (Bad)")


def _wait_for(what: str, found: callable) -> None:  # type: ignore[valid-type]
    deadline = time.monotonic() + HANG_S  # generous on a loaded machine: never the assertion
    while not found():
        if time.monotonic() > deadline:
            pytest.fail(f"never saw {what}")
        time.sleep(0.02)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["sigterm", "ctrl-c"])
def test_one_signal_stops_a_step_that_never_returns_and_keeps_the_outputs(
    tmp_path: Path, sig: signal.Signals
) -> None:
    scen = tmp_path / "s.yaml"
    scen.write_text(
        "world:\n  components:\n"
        "    R: {template: 'rogue:Rogue', freq: 4, params: {mode: stuck, at: 2}}\n"
        "duration: 100\nquality: {signal: R.u, reference: 0}\n"
    )
    mark = tmp_path / "stuck"
    env = {**os.environ, "PYTHONPATH": str(TESTS), "ROGUE_MARK": str(mark), "MPLBACKEND": "Agg"}
    out = tmp_path / "o"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "amsa_phys",
            "run",
            str(scen),
            *("--headless", "-q"),
            *ARGS,
            str(out),
        ],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        _wait_for("the component stuck", lambda: any(tmp_path.glob("stuck.*")))
        proc.send_signal(sig)  # once
        _, err = proc.communicate(timeout=HANG_S)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert err.startswith("error: interrupted at t="), err
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"] == "interrupted"
    rows = (out / "trace.csv").read_text().splitlines()
    assert rows[0] == "t,R.u"
    assert float(rows[-1].split(",")[0]) >= 1.75  # the whole instants before it got stuck
    assert (out / "scenario.yaml").is_file()
