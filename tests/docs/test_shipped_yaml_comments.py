"""The comments of the shipped worlds and scenarios point to things a user can open.

A comment that sends the reader to a README section that no longer exists, or to a file that
is not in the repository, is worse than no comment: it is the first thing a user reads after
copying a world.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FILES = sorted([*(ROOT / "worlds").glob("*.yaml"), *(ROOT / "scenarios").glob("*.yaml")])

#: A path a comment names: something/with/slashes.ext (a manual page, a world, a test).
PATH = re.compile(r"(?<![\w./-])((?:[\w.-]+/)+[\w.-]+\.(?:md|yaml|py|amsacore|amsatemplate|csv))")
#: A section of a page: (docs/PAGE.md, "Heading").
SECTION = re.compile(r'\((docs/[\w-]+\.md),\s*"([^"]+)"\)')


def _comments(path: Path) -> str:
    """The file's comment text, lines joined so a reference broken over two lines reads whole."""
    lines = [m[1] for m in re.finditer(r"#\s?(.*)$", path.read_text(), re.M)]
    return " ".join(lines)


def _headings(page: Path) -> set[str]:
    return {m[1].strip() for m in re.finditer(r"^#+\s+(.*)$", page.read_text(), re.M)}


@pytest.mark.parametrize("path", FILES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_comments_name_no_readme_section(path: Path) -> None:
    assert not re.search(r"\bREADME,", _comments(path)), "the README has no sections to point to"


@pytest.mark.parametrize("path", FILES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_named_files_and_sections_exist(path: Path) -> None:
    text = _comments(path)
    for name in PATH.findall(text):
        here = [ROOT / name, path.parent / name, ROOT / "worlds" / name]
        assert any(p.exists() for p in here), f"{path.name} names {name}, which does not exist"
    for page, heading in SECTION.findall(re.sub(r"\s+", " ", text)):
        assert heading in _headings(ROOT / page), f'{path.name}: {page} has no "{heading}"'


def test_the_check_sees_a_missing_file(tmp_path: Path) -> None:
    """The patterns catch what they are for (a stale pointer, split over two lines)."""
    stale = tmp_path / "w.yaml"
    stale.write_text('# as in\n# shared/reference/amsa/x.amsacore (docs/physics.md,\n# "Nope")\n')
    text = _comments(stale)
    assert PATH.findall(text) == ["shared/reference/amsa/x.amsacore", "docs/physics.md"]
    assert SECTION.findall(re.sub(r"\s+", " ", text)) == [("docs/physics.md", "Nope")]
