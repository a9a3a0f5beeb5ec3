"""The "Where the time goes" table: ``benchmarks/profile_loop.perf`` reports, for the single
env and for ``amsa_phys.run``, the CPU per step (per run) and each part's share of it, rows
the results file keeps and the manual's generated block shows."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks"))

import profile_loop  # noqa: E402  (benchmarks/profile_loop.py)
import results  # noqa: E402


def test_each_part_is_a_share_of_the_measured_cpu(monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("gymnasium")
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    monkeypatch.setattr(profile_loop, "COUNTS", {"gym": 6000, "run": 6})
    rows: list[tuple[str, str, str, bool | None]] = []
    profile_loop.perf(1, lambda *row: rows.append(row))
    assert all(ok is None and aim == "" for _, _, aim, ok in rows)  # INFO: no target
    for target, scale in (("gym", "µs"), ("run", "ms")):
        mine = [(name, text) for name, text, _, _ in rows if name.startswith(f"{target}: ")]
        cpu = results.parse_measured(mine[0][1])[0]
        assert mine[0][0].startswith(f"{target}: CPU per ")
        assert cpu is not None
        assert cpu > 0
        shares = [results.parse_measured(text) for _, text in mine[1:]]
        assert shares, f"no part of {target} was sampled"
        assert sum(v for v, _, _ in shares) == pytest.approx(100, abs=0.5)
        for value, _, detail in shares:  # the share of the CPU per step, in its unit
            cost = float(detail.split()[0])
            assert cost == pytest.approx(cpu * value / 100, rel=0.01)
            assert detail.split()[1] == scale
    names = {name for name, _, _, _ in rows}
    assert "gym: physics step (C), % of CPU" in names or "gym: components, % of CPU" in names


def test_the_manual_has_the_generated_block() -> None:
    text = (ROOT / "docs" / "performance.md").read_text()
    assert "<!-- results: profile -->" in text
    table = results.render(["profile"], [])
    assert "--only profile" in table
