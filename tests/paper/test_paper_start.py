"""Fig. 5 against the initial gap: which starts give the paper's ordering (issue 31, 6).

The paper gives no initial conditions. Its ordering (the maxima falling from Kv 0.15 through
0.1 to 0.05, Kv 0.05 best) holds from the project's start (the follower 1 m behind); from
the reference distance (15 m) Kv 0.15 is best by its maximum and its rms error. These tests
hold the orderings and the trend, not the numbers, so the dynamics may be retuned: a
physics change that moved where the ordering breaks would show here and in
``amsa-phys plot --paper fig5-start``.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import pytest

import amsa_phys as ap
from amsa_phys.cli.main import main
from amsa_phys.plots.paperstart import best_kv, ordering_holds

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
KVS = {"015": 0.15, "01": 0.1, "005": 0.05}
GAPS = (1.0, 4.0, 8.0, 15.0)
LEADER_X = 15.0  # the Fig. 5 scenarios' leader starts at (15, 0)


@pytest.fixture(scope="module")
def table() -> dict[tuple[float, float], dict[str, Any]]:
    out = {}
    for name, kv in KVS.items():
        for gap in GAPS:
            run = ap.run(
                SCENARIOS / f"paper_fig5_kv{name}.yaml", set={"Follower.x": LEADER_X - gap}
            )
            out[(gap, kv)] = run.metrics["overall"]
    return out


def test_the_shipped_start_gives_the_papers_ordering(table: Any) -> None:
    assert ordering_holds(table, 1.0)
    assert best_kv(table, 1.0, "max_after_approach") == 0.05
    assert best_kv(table, 1.0, "rms_error") == 0.05


def test_from_the_reference_distance_kv_015_is_best(table: Any) -> None:
    assert not ordering_holds(table, 15.0)
    assert best_kv(table, 15.0, "max_after_approach") == 0.15
    assert best_kv(table, 15.0, "rms_error") == 0.15


@pytest.mark.parametrize("kv", list(KVS.values()))
def test_the_maximum_falls_as_the_start_gap_grows(table: Any, kv: float) -> None:
    """A follower starting further back has less ground to lose: each maximum after the
    first approach falls with the gap (measured by 1.5 to 10 m from 1 m to 15 m)."""
    maxima = [table[(gap, kv)]["max_after_approach"] for gap in GAPS]
    assert all(a > b for a, b in itertools.pairwise(maxima)), maxima


def test_kv_015_maximum_is_highest_from_the_closest_start(table: Any) -> None:
    """Why 32 m is out of reach by the start alone: the closest start without the chassis
    (0.8 m long) touching is ~1 m, and there the maximum is the largest of any gap."""
    maxima = {gap: table[(gap, 0.15)]["max_after_approach"] for gap in GAPS}
    assert max(maxima, key=maxima.__getitem__) == 1.0
    assert maxima[1.0] < 32 * 0.85  # the paper's 32 m -15 %: not reached (README)


@pytest.mark.parametrize(
    ("values", "holds"),
    [
        ((32.0, 29.0, 25.0), True),
        ((29.0, 29.0, 25.0), False),  # a tie is not the paper's ordering
        ((25.0, 29.0, 32.0), False),
        ((32.0, None, 25.0), False),  # a gain that never approached
    ],
)
def test_ordering_holds_is_strict(values: tuple[float | None, ...], holds: bool) -> None:
    table = {
        (1.0, kv): {"max_after_approach": v}
        for kv, v in zip((0.15, 0.1, 0.05), values, strict=True)
    }
    assert ordering_holds(table, 1.0) is holds


def test_plot_fig5_start_draws_and_reports_each_gap(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "start.png"
    sources = [str(SCENARIOS / f"paper_fig5_kv{n}.yaml") for n in KVS]
    assert main(["plot", "--paper", "fig5-start", *sources, "-o", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert (
        lines[0] == "gap 1 m: paper's ordering of the maxima yes; best Kv by max 0.05, by rms 0.05"
    )
    assert (
        lines[-2] == "gap 15 m: paper's ordering of the maxima no; best Kv by max 0.15, by rms 0.15"
    )
    assert lines[-1] == f"wrote {out} (24 runs)"
    assert out.read_bytes()[:4] == b"\x89PNG"
