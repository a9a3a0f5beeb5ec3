"""Loading a scenario with many STL requirements does work linear in their number.

Each requirement's name was compared with every earlier one (a list search): 60,000
requirements (a 3 MB file, within every limit) took minutes to ``validate``. The test
counts the Python calls the scenario builder makes, never the time: twice the
requirements, about twice the calls (the quadratic search made four times as many).
"""

from __future__ import annotations

import sys
from pathlib import Path
from types import FrameType
from typing import Any

from amsa_phys.model.scenario import load_scenario

WORLD = Path(__file__).resolve().parents[2] / "worlds" / "mde_challenge.yaml"
BUILDER = "scenariobuild.py"


def _calls_to_load(tmp_path: Path, n: int) -> int:
    path = tmp_path / f"s{n}.yaml"
    path.write_text(
        f"world: {WORLD}\nduration: 5\nexpect:\n"
        + "".join(f'  - {{stl: "always(t >= 0)", name: r{i}}}\n' for i in range(n))
    )
    calls = 0

    def count(frame: FrameType, event: str, _: Any) -> None:
        nonlocal calls
        if event == "call" and frame.f_code.co_filename.endswith(BUILDER):
            calls += 1

    sys.setprofile(count)
    try:
        scenario = load_scenario(path)
    finally:
        sys.setprofile(None)
    assert len(scenario.expect) == n
    return calls


def test_twice_the_requirements_about_twice_the_work(tmp_path: Path) -> None:
    small, large = _calls_to_load(tmp_path, 300), _calls_to_load(tmp_path, 600)
    assert large < 2.5 * small, (small, large)
