"""``--bag`` naming the run directory (``--bag P --out P``, or a directory holding it) is
refused before running, exit 2 in one line: it used to run the whole run, then fail writing
the bag with exit 3."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"


@pytest.mark.parametrize("out", ["P.mcap", "P.mcap/run", "./P.mcap/../P.mcap"])
def test_a_bag_that_is_the_run_directory_is_refused_before_running(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    out: str,
) -> None:
    monkeypatch.chdir(tmp_path)
    argv = ["run", str(SCENARIO), "--headless", "-q", "--no-plot", "--bag", "P.mcap"]
    assert main([*argv, "--out", out]) == 2
    err = capsys.readouterr().err
    assert err == "error: P.mcap: --bag: is the run directory (--out): name another file\n"
    assert list(tmp_path.iterdir()) == []  # nothing ran, nothing written
