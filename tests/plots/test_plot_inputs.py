"""``amsa-phys plot`` on damaged run and sweep directories: one line naming the file (and the
line), exit 2 -- never a traceback, never a torn trace plotted as if it were whole; and
``summary.png`` is drawn even when the seeds' mean sits an ulp outside their range."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.plots.summary import plot_summary

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


@pytest.fixture(scope="module")
def made(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """One real run directory and one real sweep directory, shared (copied per case)."""
    root = tmp_path_factory.mktemp("made")
    scen = root / "s.yaml"
    scen.write_text(
        f"world: {WORLD}\nduration: 2\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
    )
    run, sweep = root / "run", root / "sweep"
    assert main(["run", str(scen), "--headless", "--out", str(run), "-q", "--no-plot"]) == 0
    grid = ["--grid", "MyFollowerController.Kv=0.1,0.2", "-j", "1"]
    assert main(["sweep", str(scen), *grid, "--out", str(sweep)]) == 0
    return run, sweep


def _replace(name: str, data: bytes) -> Callable[[Path], None]:
    return lambda d: (d / name).write_bytes(data)


def _edit(name: str, change: Callable[[str], str]) -> Callable[[Path], None]:
    return lambda d: (d / name).write_text(change((d / name).read_text()))


def _wide(text: str) -> str:
    lines = text.splitlines()
    return "\n".join([lines[0]] + [line + ",1" for line in lines[1:]]) + "\n"


def _text_cell(text: str) -> str:
    lines = text.splitlines()
    lines[2] = lines[2].rsplit(",", 1)[0] + ",abc"
    return "\n".join(lines) + "\n"


RUN_CASES = {
    "metrics-a-list": (
        _replace("metrics.json", b"[1, 2]"),
        "metrics.json: not a run's metrics: expected an object, got list",
    ),
    "metrics-bad-phases": (
        _replace("metrics.json", b'{"phases": [{"start": "x"}]}'),
        "metrics.json: not a run's metrics: phases[0].start is not a number",
    ),
    "trace-binary": (
        _replace("trace.csv", bytes(range(256)) * 8),
        "trace.csv:1: not a whole trace: no header line starting with t",
    ),
    "trace-binary-rows": (
        lambda d: (d / "trace.csv").write_bytes(
            (d / "trace.csv").read_bytes().split(b"\n")[0] + b"\n" + bytes(range(128, 256)) + b"\n"
        ),
        "trace.csv:2: not a whole trace: not UTF-8 text",
    ),
    "trace-torn-row": (
        _edit("trace.csv", lambda t: t[:-7]),
        "trace.csv:42: not a whole trace: cut short",
    ),
    "trace-extra-column": (
        _edit("trace.csv", _wide),
        "trace.csv:2: not a whole trace: 27 values where the header names 26",
    ),
    "trace-text-cell": (
        _edit("trace.csv", lambda t: t.replace("\n0.05,", "\nabc,", 1)),
        "trace.csv:3: not a whole trace: 'abc' is not a number",
    ),
}


@pytest.mark.parametrize("case", list(RUN_CASES))
def test_a_damaged_run_directory_is_refused_in_one_line(
    made: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str], case: str
) -> None:
    damage, message = RUN_CASES[case]
    rundir = tmp_path / "run"
    shutil.copytree(made[0], rundir)
    damage(rundir)
    assert main(["plot", str(rundir)]) == 2
    assert capsys.readouterr().err == f"error: {rundir}/{message}\n"
    assert not (rundir / "distance.png").exists()


SWEEP_CASES = {
    "lacks-a-column": (
        _edit("results.csv", lambda t: t.replace("seed_index,", "", 1)),
        "results.csv:1: not a sweep's results.csv: no seed_index column",
    ),
    "short-row": (
        _edit("results.csv", lambda t: t.rsplit(",", 1)[0] + "\n"),
        "results.csv:3: not a sweep's results.csv: 20 cells where the header has 21",
    ),
    "text-cell": (
        _edit("results.csv", _text_cell),
        "results.csv:3: not a sweep's results.csv: phase0.collisions is 'abc', not a number",
    ),
    "binary": (
        _replace("results.csv", bytes(range(128, 256)) * 8),
        "results.csv: not a results.csv: not UTF-8 text (byte 0)",
    ),
}


@pytest.mark.parametrize("case", list(SWEEP_CASES))
def test_a_damaged_sweep_directory_is_refused_in_one_line(
    made: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str], case: str
) -> None:
    damage, message = SWEEP_CASES[case]
    sweepdir = tmp_path / "sweep"
    shutil.copytree(made[1], sweepdir)
    (sweepdir / "summary.png").unlink()
    damage(sweepdir)
    assert main(["plot", str(sweepdir)]) == 2
    assert capsys.readouterr().err == f"error: {sweepdir}/{message}\n"
    assert not (sweepdir / "summary.png").exists()


def test_plot_output_onto_a_directory_is_refused(
    made: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "d.png").mkdir()
    assert main(["plot", str(made[0]), "-o", str(tmp_path / "d.png")]) == 2
    assert capsys.readouterr().err == (
        f"error: {tmp_path / 'd.png'}: --output: is a directory; give a file name\n"
    )


def test_summary_is_drawn_when_the_seed_mean_is_an_ulp_outside_the_seeds(
    tmp_path: Path,
) -> None:
    # mean([0.1] * 3) is 0.1 + 1.4e-17: a negative upper bar, which matplotlib refused
    assert sum([0.1] * 3) / 3 > 0.1
    rows = [
        {"run": i, "K": k, "seed_index": s, "error": "", "rms_error": value}
        for i, (k, s, value) in enumerate(
            [(k, s, 0.1 if k == 1.0 else 0.7) for k in (1.0, 2.0) for s in range(3)]
        )
    ]
    out = plot_summary(rows, ["K"], "rms_error", tmp_path / "summary.png", "same seeds")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
