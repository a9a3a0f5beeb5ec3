"""Runtime faults and kills: exit 3 naming component and time, outputs kept, no torn files."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import sigint
from deadlines import HANG_S
from longrun import start_long_run

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
TESTS = ROOT / "tests"
ENV = {**os.environ, "PYTHONPATH": str(TESTS)}


def scenario(tmp_path: Path, components: str, extra: str = "", duration: float = 5) -> Path:
    path = tmp_path / "s.yaml"
    path.write_text(f"world:\n  components:\n{components}\nduration: {duration}\n{extra}")
    return path


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "amsa_phys", *args],
        capture_output=True,
        text=True,
        env=ENV,
        check=False,
        preexec_fn=sigint.at_default,  # some runs here interrupt themselves (toys:CtrlC)
    )


@pytest.mark.parametrize(
    ("boom", "cause"),
    [
        ("false", "output u is nan"),
        (  # a user template's own exception: --debug would show where it was raised
            "true",
            "do_step raised ZeroDivisionError('division by zero') "
            "(amsa-phys --debug shows its traceback)",
        ),
    ],
)
def test_controller_nan_or_exception_is_exit_3_with_trace_kept(
    tmp_path: Path, boom: str, cause: str
) -> None:
    scen = scenario(tmp_path, f"    B: {{template: 'toys:Bad', freq: 4, params: {{boom: {boom}}}}}")
    proc = run_cli("run", str(scen), "--headless", "--out", str(tmp_path / "o"), "-q")
    assert proc.returncode == 3
    assert proc.stderr == f"error: run fault at t=1.000 s in B (Bad): {cause}\n"
    trace = (tmp_path / "o" / "trace.csv").read_text().splitlines()
    assert trace[-1].startswith("0.95,")  # every row before the fault, nothing after
    metrics = json.loads((tmp_path / "o" / "metrics.json").read_text())
    assert metrics["status"].startswith("fault: run fault at t=1.000 s in B")


def test_absurd_speed_is_a_physics_blow_up_fault(tmp_path: Path) -> None:
    rover = """    Ctl: {template: ConstantPower, freq: 10, params: {left: 100, right: 100}}
    N: {template: NormalizePower, freq: 10,
        inputs: {powerL: Ctl.LeftPower, powerR: Ctl.RightPower}}
    R: {template: controlledRobot, freq: 10,
        params: {stallForce: 90000, freeSpeed: 100, tractionCoef: 5},
        inputs: {powerL: N.normalizedPowerL, powerR: N.normalizedPowerR}}"""
    scen = scenario(tmp_path, rover, "", 20)
    (tmp_path / "s.yaml").write_text(
        (tmp_path / "s.yaml")
        .read_text()
        .replace("world:\n", "world:\n  physics: {max_speed: 30}\n")
    )
    assert main(["run", str(scen), "--headless", "--out", str(tmp_path / "o"), "-q"]) == 3
    metrics = json.loads((tmp_path / "o" / "metrics.json").read_text())
    assert "in R: body speed" in metrics["status"]
    assert "exceeds physics.max_speed 30 m/s" in metrics["status"]


def test_leaving_the_world_is_a_fault(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    leader = "    L: {template: freeRobot, freq: 10, params: {cruisePower: 100}}"
    scen = scenario(tmp_path, leader, "", 60)
    (tmp_path / "s.yaml").write_text(
        (tmp_path / "s.yaml").read_text().replace("world:\n", "world:\n  physics: {extent: 50}\n")
    )
    assert main(["run", str(scen), "--headless", "--out", str(tmp_path / "o"), "-q"]) == 3
    err = capsys.readouterr().err
    assert "in L: body left the world at (50" in err
    assert "(physics.extent is 50 m)" in err


def test_a_timeline_that_breaks_a_rule_is_refused_before_running(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # each value is in range, the pair is not: found at load time, not 2 s into the run
    comps = """    Ctl: {template: ConstantPower, freq: 4}
    N: {template: NormalizePower, freq: 4,
        inputs: {powerL: Ctl.LeftPower, powerR: Ctl.RightPower}}"""
    scen = scenario(
        tmp_path, comps, "timeline:\n  - {at: 2, set: {N.powerMin: 50, N.powerMax: 10}}\n"
    )
    assert main(["run", str(scen), "--headless", "--out", str(tmp_path / "o"), "-q"]) == 2
    assert capsys.readouterr().err == (
        f"error: {scen}:8: timeline[0].set.N.powerMax: powerMin 50 is above powerMax 10\n"
    )
    assert not (tmp_path / "o").exists()


def test_a_change_a_component_rejects_mid_run_is_exit_3(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a rule that depends on the run's state can only be checked when the change lands
    comps = "    P: {template: 'toys:Picky', freq: 4}"
    scen = scenario(tmp_path, comps, "timeline:\n  - {at: 2, set: {P.gain: 2}}\n")
    proc = run_cli("run", str(scen), "--headless", "--out", str(tmp_path / "o"), "-q")
    assert proc.returncode == 3
    assert proc.stderr == (
        "error: run fault at t=2.000 s in P (Picky): rejected gain=2.0: "
        "too late to change gain after 4 steps\n"
    )
    assert (tmp_path / "o" / "trace.csv").read_text().splitlines()[-1].startswith("1.95,")


def test_sigterm_finalises_like_ctrl_c(tmp_path: Path) -> None:
    out = tmp_path / "t"
    proc = start_long_run(out, stderr=subprocess.PIPE)
    proc.terminate()
    _, err = proc.communicate(timeout=HANG_S)
    assert proc.returncode == 130
    assert "interrupted at t=" in err
    assert json.loads((out / "metrics.json").read_text())["status"] == "interrupted"


@pytest.mark.parametrize("term", ["false", "true"], ids=["ctrl-c", "sigterm"])
def test_interrupt_inside_an_instant_stops_after_whole_instants(tmp_path: Path, term: str) -> None:
    # the signal arrives inside a component's doStep at t=2.5; the run ends at the end of that
    # simulated second, every instant up to it whole (CI once caught a Ctrl-C between the
    # quality sample's time and value: IndexError and a traceback instead of exit 130)
    comps = f"    K: {{template: 'toys:CtrlC', freq: 4, params: {{term: {term}}}}}"
    quality = "quality: {signal: K.u, reference: 0}\n"
    scen = scenario(tmp_path, comps, quality, duration=100)
    proc = run_cli("run", str(scen), "--headless", "--out", str(tmp_path / "o"), "-q")
    assert proc.returncode == 130
    assert proc.stderr.startswith("error: interrupted at t=3.00 s; outputs so far are in ")
    trace = (tmp_path / "o" / "trace.csv").read_text().splitlines()
    assert trace[-1] == "3.0,13.0"  # K ran at 0, 0.25, ..., 3.0: 13 steps, all logged
    metrics = json.loads((tmp_path / "o" / "metrics.json").read_text())
    assert (metrics["status"], metrics["simulated"]) == ("interrupted", 3.0)
    assert metrics["overall"]["max_distance"] == 13.0  # the quality samples are whole too


def test_second_ctrl_c_stops_at_once_and_still_finalises(tmp_path: Path) -> None:
    comps = "    K: {template: 'toys:CtrlC', freq: 4, params: {signals: 2}}"
    scen = scenario(tmp_path, comps, "quality: {signal: K.u, reference: 0}\n", duration=100)
    proc = run_cli("run", str(scen), "--headless", "--out", str(tmp_path / "o"), "-q")
    assert proc.returncode == 130
    assert proc.stderr.startswith("error: interrupted at t=2.50 s; outputs so far are in ")
    metrics = json.loads((tmp_path / "o" / "metrics.json").read_text())
    assert (metrics["status"], metrics["simulated"]) == ("interrupted", 2.5)
    assert (tmp_path / "o" / "trace.csv").read_text().splitlines()[-1].startswith("2.45,")


def test_sigkill_never_leaves_a_partial_file_under_a_final_name(tmp_path: Path) -> None:
    out = tmp_path / "k"
    proc = start_long_run(out)
    proc.kill()
    proc.wait(timeout=HANG_S)
    names = sorted(p.name for p in out.iterdir())
    assert names == [".amsa-phys-run", "trace.csv.tmp"]  # no output under a final name


def test_unwritable_output_directory_is_refused_before_the_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    code = main(
        [
            "run",
            str(TESTS / "fixtures" / "mde_short.yaml"),
            "--headless",
            "--out",
            str(blocker / "sub"),
            "-q",
        ]
    )
    assert code == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {blocker / 'sub'}: --out: cannot create directory")
