"""``amsa-phys monitor`` judges a trace.csv as ``plot`` and ``view`` do: a file that is not a
whole trace is refused in one line naming the file's own line, never judged as a run's."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main

FORMULA = "always(a >= 0)"


def _trace(tmp_path: Path, body: str) -> Path:
    (tmp_path / "trace.csv").write_text("t,a\n" + body)
    return tmp_path


def _refused(rundir: Path, capsys: pytest.CaptureFixture[str]) -> str:
    capsys.readouterr()
    assert main(["monitor", str(rundir), FORMULA]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    err = captured.err.strip()
    assert "\n" not in err, err  # one line: no library warning above it
    assert "Traceback" not in err
    return err


def test_a_row_wider_than_the_header_is_refused_not_judged(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # line 4 holds a third value: a column the header does not name is no run's sample
    rundir = _trace(tmp_path, "0,1\n0.5,2\n1,-5,7\n1.5,3\n")
    err = _refused(rundir, capsys)
    assert f"{rundir / 'trace.csv'}:4:" in err
    assert "3 values where the header names 2" in err


def test_a_bad_cell_is_named_by_the_files_own_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rundir = _trace(tmp_path, "0,1\n0.5,2\n1,0x10\n1.5,3\n")
    err = _refused(rundir, capsys)
    assert f"{rundir / 'trace.csv'}:4:" in err
    assert "'0x10' is not a number" in err


@pytest.mark.filterwarnings("error")  # a library's warning would be a second line
def test_a_trace_with_only_its_header_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    err = _refused(_trace(tmp_path, ""), capsys)
    assert "fewer than two samples" in err


def test_a_whole_trace_is_still_judged_on_every_row(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # one bad sample among many: a reader that skipped rows would miss it
    rows = "".join(f"{i / 4},{-1 if i == 2002 else 1}\n" for i in range(4001))
    rundir = _trace(tmp_path, rows)
    capsys.readouterr()
    assert main(["monitor", str(rundir), FORMULA, "--json"]) == 1
    assert '"instant": 500.5' in capsys.readouterr().out


def test_a_column_named_twice_is_refused_not_chosen(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``t,a,a``: the formula read the second ``a`` (it passed where the first failed); no
    run writes a column twice, so the file is not a trace."""
    (tmp_path / "trace.csv").write_text("t,a,a\n0,-1,1\n1,-1,1\n")
    err = _refused(tmp_path, capsys)
    assert err == f"error: {tmp_path / 'trace.csv'}:1: not a trace: the column 'a' is named twice"


def test_instants_closer_than_any_run_logs_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Samples 1e-300 s apart: the period rounded to 0 and dividing by it was a traceback."""
    rundir = _trace(tmp_path, "0,1\n1e-300,1\n2e-300,1\n")
    err = _refused(rundir, capsys)
    assert err == (
        f"error: {rundir / 'trace.csv'}: the trace's instants are 1e-300 s apart: no run "
        "logs faster than 10,000 Hz"
    )


def test_a_trace_at_the_fastest_log_rate_is_judged(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rundir = _trace(tmp_path, "".join(f"{i / 10_000!r},1\n" for i in range(50)))
    assert main(["monitor", str(rundir), FORMULA]) == 0
