"""The benchmarks that need more than the package write rows too, and the suite's figures.

Every figure the manual shows comes from ``benchmarks/results/perf.json``: a row without an aim
is shown as INFO (not a MISS), a figure that cannot be measured here (IR-SIM, ROS, PSY-TaLiRo
missing) is a SKIP row that says why, and the test suite's duration and memory are read from
the pytest run itself (its JUnit XML, the kernel's accounting of its processes).
"""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks"))

import bench_suite  # noqa: E402  (benchmarks/bench_suite.py)
import results  # noqa: E402  (benchmarks/results.py)


def _rows(calls: list[tuple[Any, ...]]) -> list[dict[str, Any]]:
    """The rows a sitting would write for these ``report`` calls."""
    recorder = results.Recorder(reps=1)
    recorder.start("t")
    for name, measured, aim, ok, *skipped in calls:
        recorder.add(name, measured, aim, ok, *skipped)
    return [r.__dict__ for r in recorder.rows]


def test_a_figure_without_an_aim_is_info_and_one_not_measured_says_why() -> None:
    info, skip, miss = _rows(
        [
            ("bag size / trace.csv size", "1.42; bag 5.3 MiB", "", None),
            ("IR-SIM ratio", "not measured: IR-SIM is not installed here", "", None, True),
            ("frame, ms", "20.5 (min 19, max 22)", "<= 16.7", False),
        ]
    )
    assert (info["verdict"], info["value"], info["detail"]) == ("INFO", 1.42, "bag 5.3 MiB")
    assert (skip["verdict"], skip["value"]) == ("SKIP", None)
    assert "not installed" in skip["detail"]
    assert (miss["verdict"], miss["spread"]) == ("MISS", [19.0, 22.0])
    table = results.render(["t"], [info, skip, miss])
    assert "| SKIP |" in table
    assert "IR-SIM is not installed here" in table
    assert "| INFO |" in table


def test_irsim_missing_gives_skip_rows_not_a_crash(monkeypatch: Any) -> None:
    import bench_irsim

    monkeypatch.setattr(bench_irsim.importlib.util, "find_spec", lambda name: None)
    calls: list[tuple[Any, ...]] = []
    bench_irsim.perf(1, lambda *a, **k: calls.append((*a, k.get("skipped", False))))
    assert len(calls) == 2  # 10 Hz and 100 Hz
    assert all(c[-1] and "pip install ir-sim" in c[1] for c in calls)


def test_peak_memory_and_cpu_are_the_measured_commands() -> None:
    """The launcher reports the child's own peak and exit code, not the benchmark's pages."""
    code = "import time; x = bytearray(120 * 2**20); x[::4096] = b'1' * len(x[::4096]); exit(3)"
    wall, cpu, rss, status = bench_suite.measure([sys.executable, "-c", code])
    assert status == 3
    assert rss >= 120
    assert 0 < cpu <= wall * 2 + 1  # two cores at most, and some slack for the clock's grain
    _, _, small, _ = bench_suite.measure([sys.executable, "-c", "pass"])
    assert small < 100  # a bare interpreter: the benchmark process's memory is not counted


def test_a_tier_reports_its_counts_from_the_run(tmp_path: Path) -> None:
    tests = tmp_path / "test_sample.py"
    tests.write_text(
        textwrap.dedent(
            """
            import pytest

            def test_a(): pass
            def test_b(): assert False
            @pytest.mark.skip(reason="x")
            def test_c(): pass
            @pytest.mark.ros
            def test_d(): pass
            """
        )
    )
    calls: list[tuple[Any, ...]] = []
    bench_suite.tier("quick", [str(tests)], tmp_path, lambda *a, **k: calls.append(a))
    wall, cpu, rss = calls
    assert "the quick tier (only " in wall[0]
    # the quick tier deselects the ros test: three run, one skipped, one failed
    assert "3 tests, 1 skipped, 1 failed; pytest exit 1" in wall[1]
    assert float(wall[1].split(";")[0]) > 0
    assert wall[3] is None  # failed tests still give the time: no aim, not a MISS
    assert "CPU of pytest and its children" in cpu[0]
    assert "peak RSS" in rss[0]


def test_a_tier_already_run_is_read_from_its_junit_report(tmp_path: Path) -> None:
    """``--suite-junit full=FILE``: the time and counts of the user's run, and rows saying the
    CPU and memory were not measured (a figure is never made up where nothing measured it)."""
    report_xml = tmp_path / "full.xml"
    report_xml.write_text(
        '<testsuites><testsuite name="pytest" tests="10" failures="1" errors="0" '
        'skipped="2" time="90.0" timestamp="2026-11-28T12:00:00"/></testsuites>'
    )
    rows = []
    took = bench_suite.from_junit(
        "full", report_xml, lambda *a, **k: rows.append((*a, k.get("skipped", False)))
    )
    assert took == 90.0
    wall, cpu, rss = rows
    assert wall[1].startswith("1.5; 10 tests, 2 skipped, 1 failed")
    assert not wall[-1]
    assert cpu[-1]
    assert rss[-1]
    assert "not measured" in cpu[1]


def test_a_file_that_is_no_junit_report_is_named(tmp_path: Path) -> None:
    path = tmp_path / "report.xml"
    for text in ("<x/>", "not xml", '<testsuite time="soon"/>'):
        path.write_text(text)
        with pytest.raises(ValueError, match=r"report\.xml"):
            bench_suite.junit_time(path)
    with pytest.raises(ValueError, match=r"missing\.xml"):
        bench_suite.junit_time(tmp_path / "missing.xml")


def test_the_bag_target_measures_rows_a_table_can_show() -> None:
    """The cheapest of the new targets, run end to end on a short scenario: each figure is a
    number the results file can hold (a rotten benchmark fails here, not in the lead's
    sitting)."""
    import bench_bag

    calls: list[tuple[Any, ...]] = []
    bench_bag.perf(1, lambda *a, **k: calls.append(a), duration=5.0)
    rows = _rows(calls)
    assert [r["figure"].split(",")[0].split(" (")[0] for r in rows] == [
        "run with --bag CPU / without",
        "bag: CPU a message",
        "bag size / trace.csv size",
    ]
    assert all(r["value"] is not None for r in rows)
    assert rows[0]["value"] > 0  # a ratio of CPU times
    assert rows[2]["value"] > 0  # a ratio of file sizes
    assert rows[0]["ratio_to"].startswith("without")


def test_a_benchmark_that_raises_is_a_row_and_the_others_are_kept(monkeypatch: Any) -> None:
    """A sitting of hours: each target's rows are saved as it ends, and a benchmark that raises
    is one MISS row saying why (no number read from its message), the sitting going on."""
    import perf

    recorder = results.Recorder(reps=1)
    saved: list[list[str]] = []
    monkeypatch.setattr(
        recorder, "save", lambda *a: saved.append([r.target for r in recorder.rows])
    )
    monkeypatch.setattr(perf, "RECORDER", recorder)

    def boom(reps: int) -> None:
        raise RuntimeError("catkin_make failed: 2 errors")

    def fine(reps: int) -> None:
        perf.report("a figure", "1.5 (min 1, max 2)", "<= 2", True)

    monkeypatch.setitem(perf.TARGETS, "boom", boom)
    monkeypatch.setitem(perf.TARGETS, "fine", fine)
    assert perf._measure("boom", 1) is False
    assert perf._measure("fine", 1) is True
    failed, ok = recorder.rows
    assert (failed.figure, failed.value, failed.verdict) == (
        "boom: the benchmark stopped",
        None,
        "MISS",
    )
    assert failed.detail == "RuntimeError: catkin_make failed: 2 errors"
    assert (ok.target, ok.value, ok.verdict) == ("fine", 1.5, "PASS")
    assert saved == [["boom"], ["boom", "fine"]]
