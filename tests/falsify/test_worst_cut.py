"""``worst.yaml`` of a search run shorter than the scenario (``falsify --duration``) is a
scenario its own loader takes: checks of phases the runs never reached, and windows opening
after their end, are left out, so ``amsa-phys run worst.yaml`` replays as the header says."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"


def test_worst_yaml_of_a_cut_search_validates_and_replays(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = tmp_path / "s.yaml"
    # scenario1's checks of phase 3 (from 375 s), and a trace window opening at 100 s
    scen.write_text(
        SCENARIO1.read_text().replace("../worlds/", f"{ROOT}/worlds/")
        + "  - {trace: MyDistanceMonitor.distanceFollowerToLeader, after: 100, below: 100}\n"
    )
    assert main(["validate", str(scen)]) == 0
    out = tmp_path / "found"
    argv = ["falsify", str(scen), "--range", "MyNormalizePower.motorCoef=50:100"]
    argv += ["--budget", "2", "--duration", "5", "-j", "1", "--out", str(out)]
    assert main(argv) in (0, 1)
    worst = out / "worst.yaml"
    text = worst.read_text()
    assert "phase: 3" not in text
    assert "after: 100" not in text
    assert "phase: 0" in text  # the checks of the phase the runs reached stay
    capsys.readouterr()
    assert main(["validate", str(worst)]) == 0
    replay = ["run", str(worst), "--headless", "--no-plot", "-q", "--out", str(tmp_path / "r")]
    assert main(replay) in (0, 1)
    assert "skipped" not in capsys.readouterr().out  # every check it keeps is judged
