"""``amsa-phys graph``: DOT lists every component and link; PNG and SVG are real images."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


def test_dot_has_every_component_coloured_by_kind_and_every_link(tmp_path: Path) -> None:
    out = tmp_path / "a.dot"
    assert main(["graph", str(ROOT / "scenarios" / "scenario1.yaml"), "-o", str(out)]) == 0
    dot = out.read_text()
    assert dot.startswith('digraph "mdeChallenge" {')
    assert (
        '"Follower" [label="Follower\\ncontrolledRobot (process, 4 Hz)", fillcolor="#fdb462"]'
        in dot
    )
    assert '"LeaderGPS" -> "MyFollowerController" [label="gpsPosX→xLeader"' in dot
    assert '"MyNormalizePower" -> "Follower" [label="normalizedPowerL→powerL"' in dot
    assert dot.count(" -> ") == 19  # every input of the eight components


@pytest.mark.parametrize(("suffix", "magic"), [(".png", b"\x89PNG"), (".svg", b"<?xml")])
def test_images(tmp_path: Path, suffix: str, magic: bytes) -> None:
    out = tmp_path / f"a{suffix}"
    assert main(["graph", str(WORLD), "-o", str(out)]) == 0
    data = out.read_bytes()
    assert data.startswith(magic)
    if suffix == ".svg":
        assert b"MyFollowerController" in data


def test_bad_output_name(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["graph", str(WORLD), "-o", str(tmp_path / "a.jpg")]) == 2
    assert "--output: expected a .png, .svg or .dot file name" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["mde_challenge", "platoon"])
def test_every_link_label_is_readable(name: str) -> None:
    # each label overlaps no component and no other label, and lies inside the picture
    import matplotlib.pyplot as plt

    from amsa_phys.model.world import load_world
    from amsa_phys.plots.graph import diagram, structure

    world = load_world(ROOT / "worlds" / f"{name}.yaml")
    fig, boxes, labels = diagram(world)
    try:
        assert len(labels) == len({(a, b) for a, b, _ in structure(world).links})
        for i, label in enumerate(labels):
            assert not any(label.overlaps(box) for box in boxes), i
            assert not any(label.overlaps(other) for other in labels[:i]), i
            assert fig.bbox.contains(label.x0, label.y0)
            assert fig.bbox.contains(label.x1, label.y1)
    finally:
        plt.close(fig)


def test_copies_of_a_counted_composite_are_drawn_once(tmp_path: Path) -> None:
    out = tmp_path / "p.dot"
    assert main(["graph", str(ROOT / "worlds" / "platoon.yaml"), "-o", str(out)]) == 0
    dot = out.read_text()
    assert dot.count("[label=") - dot.count(" -> ") == 8  # Leader and Car{i}'s seven parts
    assert '"Car{i}.Robot" [label="Car{i}.Robot\\ncontrolledRobot (process, 4 Hz, ×10)"' in dot
    # car 1 follows the Leader, car i the car ahead: both links say so
    assert '"Leader" -> "Car{i}.AheadGps" [label="posX (i=1)"' in dot
    assert '"Car{i}.Robot" -> "Car{i}.AheadGps" [label="posX (from i-1, i=2..10)"' in dot
    assert '"Car{i}.Robot" -> "Car{i}.Gps" [label="posX"' in dot  # every copy: no note
    expanded = tmp_path / "e.dot"
    argv = ["graph", str(ROOT / "worlds" / "platoon.yaml"), "-o", str(expanded), "--expand"]
    assert main(argv) == 0
    assert '"Car7.Robot" -> "Car8.AheadGps" [label="posX"' in expanded.read_text()
    png = tmp_path / "p.png"
    assert main(["graph", str(ROOT / "worlds" / "platoon.yaml"), "-o", str(png)]) == 0
    assert png.read_bytes()[:4] == b"\x89PNG"
