"""No rover passes through a wall, whatever speed the parameters allow (issue 31, item 4).

Chipmunk's collisions are discrete: a rover that moves further in one step than half the
thinnest pair of shapes it can meet stops past the middle of a wall and is pushed out the far
side (a rover crossed a 1 cm wall at ~62 m/s). ``space.resolvable_speed`` is the speed one
step resolves; faster, the physics step is cut into Chipmunk sub-steps (``bodyio.substeps``).
A small, fast rover (5 cm wide, 8 m/s: 8 cm a step at 100 Hz, more than itself and the wall)
driven at a 1 cm wall must stop in front of it; the mutation test runs it without sub-steps
and sees it come out behind the wall.
"""

from __future__ import annotations

from pathlib import Path

import pymunk
import pytest
from rig import ON_AXLE, drive

from amsa_phys.physics import space
from amsa_phys.physics.space import resolvable_speed

#: Where the wall stands: far enough for the dart to meet it at 7.0-7.4 m/s (7 cm a step at
#: 100 Hz). Whether a step without sub-steps ends past the wall's middle depends on where the
#: steps fall against it, so three places: none may be crossed, and without sub-steps one is.
WALLS_X = (7.5, 8.0, 8.5)
#: Small and fast: 0.1 x 0.05 m, 8 m/s no-load speed, reaching the walls in ~2 s.
DART = {
    **ON_AXLE,
    "casterOffset": -0.04,
    "length": 0.1,
    "width": 0.05,
    "track": 0.04,
    "mass": 2.0,
    "stallForce": 400.0,
    "freeSpeed": 8.0,
    "maxWheelTorque": 40.0,
}


def run_at_wall(tmp_path: Path, rate: int, wall_x: float) -> tuple[float, float]:
    """(the rover's largest x over the run, its top speed) driving at full power at a wall."""
    wall = {"type": "polyline", "points": [[wall_x, -5.0], [wall_x, 5.0]], "thickness": 0.01}
    tmp_path = tmp_path / str(wall_x)
    tmp_path.mkdir()
    tr, _ = drive(
        tmp_path,
        100,
        100,
        2.5,
        robot=DART,
        physics={"rate": rate, "obstacles": [wall]},
        rate_hz=rate,
    )
    return float(tr["Rover.posX"].max()), float(tr["Rover.speed"].max())


@pytest.mark.parametrize("pure", ["0", "1"])
def test_a_fast_rover_stops_at_a_thin_wall(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, pure: str
) -> None:
    monkeypatch.setenv("AMSA_PHYS_PURE", pure)
    for wall_x in WALLS_X:
        x, top = run_at_wall(tmp_path, 100, wall_x)
        assert top * 0.01 > 0.05 + 0.01  # one step covers more than rover and wall together
        assert x < wall_x  # never behind the wall (its centre line; the rover's centre)


def test_mutation_tunnelling_check_fails_without_sub_steps(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(space, "resolvable_speed", lambda *a: float("inf"))
    assert any(run_at_wall(tmp_path, 100, w)[0] > w for w in WALLS_X)


def test_the_resolvable_speed_is_half_the_thinnest_pair_a_step() -> None:
    class Box:
        length, width = 0.8, 0.6

    sp = pymunk.Space()
    sp.add(pymunk.Segment(sp.static_body, (0, 0), (1, 0), 0.005))  # a 1 cm wall
    # rover against wall: (0.6 + 0.01) / 2 = 0.305 m; rover against rover: 0.3 m: the lesser
    assert resolvable_speed([Box()], sp, 0.01) == pytest.approx(30.0)  # type: ignore[list-item]
    sp.add(pymunk.Poly.create_box(sp.static_body, (0.2, 0.004)))  # thinner still: 4 mm
    assert resolvable_speed([Box()], sp, 0.01) == pytest.approx(30.0)  # type: ignore[list-item]
    # a 5 cm rover: rover against rover (0.025 m) is less than against the 4 mm box (0.027 m)
    thin = type("Thin", (), {"length": 0.1, "width": 0.05})
    assert resolvable_speed([thin()], sp, 0.01) == pytest.approx(2.5)  # type: ignore[list-item]
