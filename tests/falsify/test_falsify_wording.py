"""A falsification's printed line counts its runs in the right number ("1 run")."""

from __future__ import annotations

from amsa_phys.falsify.objective import Objective, Verdict
from amsa_phys.falsify.outputs import headline
from amsa_phys.falsify.search import Progress


def test_one_run_is_singular() -> None:
    progress = Progress()
    row = {"run": 0, "Leader.changePeriod": 14.0, "generation": 0, "rms_error": 1.4}
    progress.add(row, Verdict(1.4, -1.4, False), (("Leader.changePeriod", 14.0),))
    line = headline(progress, 0, ["Leader.changePeriod"], Objective("rms_error", ()), 1)
    assert line.startswith("worst of 1 run: Leader.changePeriod=14.0")
    assert "1 runs" not in line
