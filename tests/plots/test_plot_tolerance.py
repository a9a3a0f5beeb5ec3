"""A tolerance the schema accepts is drawn, however large (found trying the CLI as a user).

`quality.tolerance: 1.0e+308` is a legal value (any finite number above 0), but the run's
distance plot put the axis's top at the band's edge with headroom, which overflowed to inf:
matplotlib raised `LinAlgError: Singular matrix` and `amsa-phys run` ended in a traceback
after writing the trace and metrics.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


@pytest.mark.parametrize("tolerance", ["1.0e+308", repr(sys.float_info.max)])
def test_a_tolerance_near_the_float_limit_is_plotted(
    tmp_path: Path, tolerance: str, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = tmp_path / "s.yaml"
    scen.write_text(
        f"world: {WORLD}\nduration: 2\nquality: {{signal: "
        f"MyDistanceMonitor.distanceFollowerToLeader, reference: 15, tolerance: {tolerance}}}\n"
    )
    out = tmp_path / "run"
    assert main(["run", str(scen), "--headless", "--out", str(out), "-q"]) == 0
    assert (out / "distance.png").stat().st_size > 10_000
    assert capsys.readouterr().err == ""
