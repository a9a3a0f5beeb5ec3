"""``amsa-phys plot --paper``: the paper's figures drawn from scenarios or run directories."""

from __future__ import annotations

from pathlib import Path

import matplotlib.image as mpimg
import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parents[2]


def test_fig5_from_scenarios_and_run_directories(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # two of the four gains, shortened: one as a run directory, one as a scenario file
    short = tmp_path / "kv005.yaml"
    short.write_text(
        (ROOT / "scenarios" / "paper_fig5_kv005.yaml")
        .read_text()
        .replace("../worlds/", f"{ROOT}/worlds/")
        .replace("duration: 300", "duration: 40")
        .split("expect:")[0]
    )
    rundir = tmp_path / "kv035"
    args = ["run", str(ROOT / "scenarios" / "paper_fig5_kv035.yaml"), "--headless", "-q"]
    assert main([*args, "--duration", "40", "--no-plot", "--out", str(rundir)]) in (0, 1)
    out = tmp_path / "fig5.png"
    assert main(["plot", "--paper", "fig5", str(short), str(rundir), "-o", str(out)]) == 0
    assert capsys.readouterr().out.endswith(f"wrote {out} (2 runs)\n")
    image = mpimg.imread(out)
    assert image.shape[0] > 400  # one row of two panels
    assert image.shape[1] > 1000


def test_fig6_is_one_run_and_the_scenarios_are_found_or_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)  # no scenarios/ here
    assert main(["plot", "--paper", "fig6"]) == 2
    assert capsys.readouterr().err == (
        "error: --paper fig6: no scenarios/paper_fig6.yaml here: run it from the project's "
        "folder or name the scenarios or run directories\n"
    )
    fig6 = ROOT / "scenarios" / "paper_fig6.yaml"
    assert main(["plot", "--paper", "fig6", str(fig6), str(fig6)]) == 2
    assert "Fig. 6 is one run" in capsys.readouterr().err
    assert main(["plot", str(tmp_path), str(tmp_path)]) == 2
    assert "expected one run or sweep directory" in capsys.readouterr().err
