"""``test --junit FILE`` loses nothing: it replaces only an earlier report of its own.

``amsa-phys test s.yaml --junit s.yaml`` wrote its XML over the scenario it had just run
(and ``--junit`` naming the world did the same to the world). The report now follows the
output-file rule (``runs/outfile.py``): an input is refused, and an existing file is
replaced only if it is a JUnit report amsa-phys wrote, so CI reruns need no flag.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from amsa_phys.atomic import write_atomic
from amsa_phys.cli.main import main

WORLD = Path(__file__).resolve().parents[2] / "worlds" / "mde_challenge.yaml"


def _scenario(folder: Path, world: Path = WORLD) -> Path:
    path = folder / "s.yaml"
    path.write_text(
        f"world: {world}\nduration: 2\nseed: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
        "expect:\n  - {metric: collisions, below: 1}\n"
    )
    return path


def _one_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    return err


def test_the_scenario_it_runs_is_not_the_report(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = _scenario(tmp_path)
    before = scen.read_bytes()
    assert main(["test", str(scen), "--junit", str(scen), "-j", "1"]) == 2
    assert "--junit: is an input of this command" in _one_line(capsys)
    assert scen.read_bytes() == before


def test_a_file_that_is_not_a_report_is_kept(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The world the scenario reads (found by nothing but its content) and a notes file."""
    world = tmp_path / "w.yaml"
    world.write_bytes(WORLD.read_bytes())
    scen = _scenario(tmp_path, world)
    for victim in (world, tmp_path / "notes.xml"):
        if not victim.exists():
            victim.write_text("<notes>mine</notes>\n")
        before = victim.read_bytes()
        assert main(["test", str(scen), "--junit", str(victim), "-j", "1"]) == 2
        assert "exists and was not written by amsa-phys" in _one_line(capsys)
        assert victim.read_bytes() == before


def test_an_earlier_report_is_replaced_and_a_link_is_not_followed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = _scenario(tmp_path)
    report = tmp_path / "report.xml"
    assert main(["test", str(scen), "--junit", str(report), "-j", "1"]) == 0
    assert main(["test", str(scen), "--junit", str(report), "-j", "1"]) == 0
    assert report.read_text().count("<testsuites") == 1
    capsys.readouterr()
    link = tmp_path / "link.xml"
    link.symlink_to(scen)
    before = scen.read_bytes()
    assert main(["test", str(scen), "--junit", str(link), "-j", "1"]) == 2
    assert "is a symbolic link" in _one_line(capsys)
    assert scen.read_bytes() == before


def test_a_hostile_name_or_file_name_gives_a_report_that_parses(tmp_path: Path) -> None:
    """A scenario named with control characters and a file name that is not UTF-8: the
    report parses (XML 1.0 has no ``\\x01``) and shows them escaped, as the terminal does."""
    scen = _scenario(tmp_path)
    scen.write_text('name: "a\\x01b\\x1b[2J"\n' + scen.read_text())
    odd = tmp_path / os.fsdecode(b"odd\xff.yaml")
    odd.write_bytes(scen.read_bytes())
    report = tmp_path / "r.xml"
    assert main(["test", str(scen), str(odd), "--junit", str(report), "-j", "1"]) == 0
    suites = ET.parse(report).getroot().findall("testsuite")
    assert [s.get("name") for s in suites] == ["a\\x01b\\x1b[2J"] * 2
    assert suites[1].get("file").endswith("odd\\udcff.yaml")
    assert not list(tmp_path.glob("*.tmp"))


def test_text_that_cannot_be_encoded_leaves_no_temporary_file(tmp_path: Path) -> None:
    with pytest.raises(UnicodeEncodeError):
        write_atomic(tmp_path / "f.txt", "\udcff")
    assert list(tmp_path.iterdir()) == []


def test_the_table_keeps_its_columns_for_a_hostile_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The scenario column is as wide as the escaped name it shows."""
    scen = _scenario(tmp_path)
    scen.write_text('name: "a\\x01b"\n' + scen.read_text())
    assert main(["test", str(scen), "-j", "1"]) == 0
    header, row = capsys.readouterr().out.splitlines()[:2]
    assert row.startswith("a\\x01b  ")
    assert row.index("collisions") == header.index("check")
