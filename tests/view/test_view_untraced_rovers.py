"""``view`` on a run whose trace kept no rover's position says so, rather than opening on an
empty world a user takes for a broken replay."""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

import pytest

import amsa_phys.view.player as player_module
import amsa_phys.view.window as window_module
from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"


class _Shown:
    """Stands in for the window: records the scene it was given and returns at once."""

    scenes: ClassVar[list[object]] = []

    def __init__(self, scene: object, **_: object) -> None:
        _Shown.scenes.append(scene)

    def run(self) -> None:
        return None


@pytest.fixture
def no_window(monkeypatch: pytest.MonkeyPatch) -> type[_Shown]:
    _Shown.scenes = []
    monkeypatch.setattr(player_module, "Player", _Shown)
    monkeypatch.setattr(window_module, "open_display", lambda interactive=False: None)
    return _Shown


@pytest.mark.parametrize(
    ("columns", "said"),
    [
        ("MyDistanceMonitor.*", "for Leader, Follower (the run traced only some buffers: "),
        ("MyDistanceMonitor.*,Leader.*", "for Follower (the run traced only some buffers: "),
        (None, None),
    ],
)
def test_view_names_the_rovers_it_cannot_draw(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    no_window: type[_Shown],
    columns: str | None,
    said: str | None,
) -> None:
    out = tmp_path / "run"
    extra = ["--trace-columns", columns] if columns else []
    assert (
        main(
            [
                "run",
                str(SCENARIO),
                "--headless",
                "--duration",
                "20",
                "--no-plot",
                "-q",
                "--out",
                str(out),
                *extra,
            ]
        )
        == 0
    )
    capsys.readouterr()
    assert main(["view", str(out)]) == 0
    assert len(no_window.scenes) == 1  # the replay still opens: the HUD has its signal
    err = capsys.readouterr().err
    if said is None:
        assert "note:" not in err
        return
    lines = [line for line in err.splitlines() if line.startswith("note:")]
    assert len(lines) == 1, err
    assert said in lines[0]
    assert str(out / "trace.csv") in lines[0]
    whom = "no rover is drawn" if "Leader.*" not in columns else "Follower is not drawn"
    assert whom in lines[0]
