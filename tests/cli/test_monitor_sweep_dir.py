"""``amsa-phys monitor`` given a sweep's directory, or a file, says which directory to give
instead, as ``view`` does: "not a run directory" teaches nothing."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main


def _sweep(tmp_path: Path, *, keep: bool) -> Path:
    sweep = tmp_path / "kv"
    sweep.mkdir()
    (sweep / "results.csv").write_text("run,seed,rms_error\n0,1,0.5\n")
    if keep:
        run = sweep / "runs" / "run-00000"
        run.mkdir(parents=True)
        (run / "trace.csv").write_text("t,a\n0,1\n0.5,2\n")
    return sweep


@pytest.mark.parametrize("keep", [True, False])
def test_a_sweep_directory_names_a_kept_run_or_how_to_keep_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], keep: bool
) -> None:
    sweep = _sweep(tmp_path, keep=keep)
    capsys.readouterr()
    assert main(["monitor", str(sweep), "always(a >= 0)"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err
    assert err.startswith(f"error: {sweep}: a sweep directory: monitor one of its kept runs")
    if keep:
        assert str(sweep / "runs" / "run-00000") in err
        # and the run it names is one monitor takes
        assert main(["monitor", str(sweep / "runs" / "run-00000"), "always(a >= 0)"]) == 0
    else:
        assert "sweep again with --keep-runs" in err


def test_a_file_given_for_the_run_directory_names_its_directory(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "trace.csv").write_text("t,a\n0,1\n0.5,2\n")
    capsys.readouterr()
    assert main(["monitor", str(tmp_path / "trace.csv"), "always(a >= 0)"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        f"error: {tmp_path / 'trace.csv'}: not a directory: give the run directory "
        f"({tmp_path}), whose trace.csv is read"
    )
    assert main(["monitor", str(tmp_path), "always(a >= 0)"]) == 0
