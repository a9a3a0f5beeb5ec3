"""``graph`` with a world whose ``name:`` is hostile: DOT is code, the picture's title text.

A world's name may be any string. In DOT it was written between quotes as it was:
``a"]; x [label="`` closed the string and wrote statements of its own (Graphviz attributes
such as ``image=`` read files when the graph is rendered), a newline split the header. In
the PNG/SVG title two ``$`` were parsed as mathtext (a traceback, exit 1).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from amsa_phys.cli.main import main

WORLD = Path(__file__).resolve().parents[2] / "worlds" / "mde_challenge.yaml"
HOSTILE = 'a"]; evil [image="/etc/passwd" label="\\N\n\x01$\\frac{x$'


def _world(tmp_path: Path, name: str) -> Path:
    text = WORLD.read_text().replace("name: mdeChallenge", f"name: {json.dumps(name)}")
    path = tmp_path / "w.yaml"
    path.write_text(text)
    return path


def _dot_strings_and_rest(text: str) -> tuple[list[str], str]:
    """DOT's double-quoted strings (with their escapes) and the text outside them."""
    strings = re.findall(r'"((?:[^"\\]|\\.)*)"', text, flags=re.S)
    return strings, re.sub(r'"(?:[^"\\]|\\.)*"', '""', text, flags=re.S)


def test_a_hostile_world_name_stays_inside_its_dot_string(tmp_path: Path) -> None:
    """The DOT with the hostile name has the same statements as with a harmless one."""
    outs = []
    for i, name in enumerate((HOSTILE, "harmless")):
        folder = tmp_path / str(i)
        folder.mkdir()
        dot = folder / "g.dot"
        assert (
            main(
                [
                    "graph",
                    str(_world(folder, name)),
                    "-o",
                    str(dot),
                ]
            )
            == 0
        )
        outs.append(dot.read_text())
    (strings, rest), (_, harmless_rest) = map(_dot_strings_and_rest, outs)
    assert rest == harmless_rest
    assert "\n" not in strings[0]
    assert "evil" in strings[0]


@pytest.mark.parametrize("suffix", ["png", "svg"])
def test_a_mathtext_name_is_drawn_as_text(tmp_path: Path, suffix: str) -> None:
    out = tmp_path / f"g.{suffix}"
    assert main(["graph", str(_world(tmp_path, "$\\frac{x$")), "-o", str(out)]) == 0
    assert out.stat().st_size > 0
