"""Ctrl-C on a batched sweep: the batches running get a second to finish and keep their
rows, a batch is at most about a second of work, and nothing is drawn when nothing finished.

The sweep used to lose every batch in flight (a batch's runs all end together, so a batch cut
short gives no row), wait up to ten seconds for them, and draw a ``summary.png`` saying "no
completed runs to plot".
"""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.engine import interrupt
from amsa_phys.runs.batched import BATCH_WORK, MAX_BATCH, plan_units
from amsa_phys.runs.pool import imap_resilient
from amsa_phys.runs.sweep import Axis, SweepPlan

ROOT = Path(__file__).resolve().parents[2]
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"


def _job(item: tuple[int, str]) -> int:
    """Job 0 returns at once; the others wait for ``marker`` (made when Ctrl-C comes)."""
    index, marker = item
    while index and not os.path.exists(marker):
        time.sleep(0.01)
    return index


def _lost(item: tuple[int, str]) -> int:
    return -1


@pytest.mark.parametrize(("finish_s", "kept"), [(30.0, [0, 1, 2, 3]), (0.0, [0])])
def test_running_jobs_finish_and_keep_their_results(
    tmp_path: Path, finish_s: float, kept: list[int]
) -> None:
    marker = str(tmp_path / "go")
    items = [(i, marker) for i in range(5)]
    got: list[int] = []
    with interrupt.deferred(), pytest.raises(KeyboardInterrupt):  # noqa: PT012
        for _, value in imap_resilient(_job, items, 3, _lost, in_flight=3, finish_s=finish_s):
            got.append(value)
            if value == 0:  # jobs 1 to 3 are (or are about to be) running: Ctrl-C now
                os.kill(os.getpid(), signal.SIGINT)
                Path(marker).touch()
    assert got == kept  # job 4 never started


def _units(duration: float, runs: int) -> list[int]:
    plan = SweepPlan(
        SCENARIO1,
        [Axis("MyFollowerController.Kv", (0.1,))],
        seeds=runs,
        base_seed=1,
        duration=duration,
    )
    units, _ = plan_units(plan.jobs(), workers=1)
    return [len(u.jobs) for u in units]


def test_an_automatic_batch_is_about_a_second_of_work() -> None:
    leaves = 8  # scenario1's
    long = _units(500, 100)
    assert max(long) * 500 * leaves <= BATCH_WORK
    assert sum(long) == 100
    assert _units(60, 1000)[0] == MAX_BATCH  # short runs: as wide as before


def test_no_summary_is_drawn_when_no_run_finished(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from amsa_phys.cli import sweep

    def stopped(jobs: object, args: object) -> object:
        raise KeyboardInterrupt
        yield

    monkeypatch.setattr(sweep, "rows_from", stopped)
    out = tmp_path / "s"
    argv = ["sweep", str(SCENARIO1), "--grid", "MyFollowerController.Kv=0.1,0.2", "--out", str(out)]
    assert main(argv) == 130
    assert (out / "results.csv").exists()
    assert not (out / "summary.png").exists()


def test_a_batch_run_whole_keeps_its_rows_when_ctrl_c_came_meanwhile() -> None:
    """In-process (``-j 1``) the engine raises a Ctrl-C noted during a batch once the batch's
    last instant has run: the batch is whole, its rows are kept, and the Ctrl-C comes after."""
    from amsa_phys.runs.batched import run_batch

    plan = SweepPlan(
        SCENARIO1,
        [Axis("MyFollowerController.Kv", (0.1, 0.2))],
        seeds=2,
        base_seed=1,
        duration=5,
    )
    with interrupt.deferred():
        interrupt.request()  # as a Ctrl-C during the batch
        rows = run_batch(plan.jobs())
        assert [r["error"] for r in rows] == ["", "", "", ""]
        assert all(isinstance(r["rms_error"], float) for r in rows)
        with pytest.raises(KeyboardInterrupt):
            interrupt.check()
