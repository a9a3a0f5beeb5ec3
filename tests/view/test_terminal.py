"""Names, keys, values and paths with control characters or ANSI escapes reach the terminal
escaped, in every command's output and messages (a scenario named ``"\\e[2J"`` must not clear
the user's screen)."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
RAW = ("\x1b", "\x07", "\x9b", "\u202e")  # ESC, BEL, CSI, right-to-left override


def clean(capsys: pytest.CaptureFixture[str]) -> str:
    captured = capsys.readouterr()
    text = captured.out + captured.err
    for char in RAW:
        assert char not in text, repr(text)
    return text


def test_a_hostile_scenario_name_is_escaped_everywhere(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = tmp_path / "s.yaml"
    scen.write_text(
        'name: "evil\\e[2J\\a\\x9b\\u202e"\n'
        f"world: {WORLD}\nduration: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
        "expect:\n  - {metric: collisions, below: 1}\n"
    )
    out = tmp_path / "o\x1b[31m"
    commands = [
        ["validate", str(scen)],
        ["describe", str(scen)],
        ["run", str(scen), "--headless", "--out", str(out)],
        ["test", str(scen), "--out", str(tmp_path / "t"), "-j", "1"],
        ["sweep", str(scen), "--grid", "Leader.x=0,1", "-j", "1", "--out", str(tmp_path / "w")],
        ["plot", str(out)],
    ]
    for argv in commands:
        assert main(argv) == 0, argv
        text = clean(capsys)
        if argv[0] in ("describe", "test"):
            assert "evil\\x1b[2J\\x07\\x9b\\u202e" in text


@pytest.mark.parametrize(
    "argv",
    [
        ["--set", "Lea\x1b[31mder.x=1"],
        ["--set", "Leader.x=\x1b[31mred"],
        ["--seed", "\x1b[2J"],
        ["--out", "o\x1b[2J/..", "--force"],
    ],
    ids=["key", "value", "seed", "out"],
)
def test_hostile_command_line_values_are_escaped_in_errors(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    argv: list[str],
) -> None:
    monkeypatch.chdir(tmp_path)
    scen = tmp_path / "s.yaml"
    scen.write_text(f"world: {WORLD}\nduration: 1\n")
    try:
        code = main(["run", str(scen), "--headless", "-q", "--no-plot", *argv])
    except SystemExit as exc:  # argparse's own usage errors
        code = int(exc.code or 0)
    text = clean(capsys)
    assert code in (0, 2), text
    assert len(text.splitlines()) <= 1


def test_a_hostile_key_in_a_file_is_escaped(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = tmp_path / "s.yaml"
    scen.write_text(f'world: {WORLD}\nduration: 1\nset: {{"Lea\\e[31mder.x": 1}}\n')
    assert main(["validate", str(scen)]) == 2
    assert clean(capsys) == (
        f"error: {scen}:3: set.Lea\\x1b[31mder.x: unknown component 'Lea\\x1b[31mder' "
        "(did you mean Leader?)\n"
    )
