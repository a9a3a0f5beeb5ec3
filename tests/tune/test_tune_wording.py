"""What ``amsa-phys tune`` says: counted nouns right, and what --box 0 means said aloud."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from amsa_phys.cli.main import main

FIXTURE = Path(__file__).resolve().parents[1] / "fixtures" / "adapt"

ARGV = ["tune", str(FIXTURE / "sweep.yaml"), "--range", "MyFollowerController.Kv=0.05:0.8"]


def test_one_seed_one_evaluation_are_singular(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([*ARGV, "--budget", "1", "--seeds", "1", "--duration", "20"]) == 0
    out = capsys.readouterr().out
    assert not re.search(r"\b1 (seeds|evaluations|contexts)\b", out)
    assert "x 1 seed " in out.splitlines()[0]
    assert "budget 1 evaluation" in out.splitlines()[0]
    assert out.splitlines()[-1].endswith("x 1 seed; 1 evaluation)")


def test_box_zero_says_it_uses_the_named_contexts(capsys: pytest.CaptureFixture[str]) -> None:
    """--box 0 is the default (the named contexts): the first line says which were used."""
    assert main([*ARGV, "--box", "0", "--budget", "1", "--seeds", "1", "--duration", "20"]) == 0
    assert " over 4 named contexts x " in capsys.readouterr().out.splitlines()[0]


def test_box_zero_is_documented_in_the_help(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["tune", "--help"])
    help_text = capsys.readouterr().out
    box = " ".join(help_text.split("\n  --box K", 1)[1].split("\n  --seeds", 1)[0].split())
    assert "0 (the default): the named contexts" in box
    assert "1..1000" in box
