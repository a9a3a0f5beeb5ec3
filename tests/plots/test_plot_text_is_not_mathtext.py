"""Names from the user's files reach titles and legends as text, never as mathtext.

A scenario named ``$\\frac{x$`` (two ``$``) was parsed as TeX when its plots were drawn: a
traceback, exit 1, and the run lost ``distance.png`` and ``trajectory.png``. Every figure is
saved through ``plots/save.py``, which draws every text as written.
"""

from __future__ import annotations

from pathlib import Path

from amsa_phys.cli.main import main

WORLD = Path(__file__).resolve().parents[2] / "worlds" / "mde_challenge.yaml"


def test_a_scenario_named_with_dollars_gets_its_plots(tmp_path: Path) -> None:
    scen = tmp_path / "s.yaml"
    scen.write_text(
        'name: "$\\\\frac{x$"\n'
        f"world: {WORLD}\nduration: 1\nseed: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
    )
    out = tmp_path / "out"
    assert main(["run", str(scen), "--headless", "-q", "--out", str(out)]) == 0
    assert (out / "distance.png").stat().st_size > 0
    assert (out / "trajectory.png").stat().st_size > 0
