"""The compiled step reading (and writing the position of) Chipmunk's bodies in place
(``_step.c``'s ``direct`` mode, ``bodylayout.body_layout_ok``) changes no bit: the same states
after every step, contacts and sub-steps included, as every access through Chipmunk's own
getters and setters; and a layout the check does not recognise keeps the calls."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from regimes import DT, every_regime
from test_collision_index import pile_up, run

from amsa_phys.physics import bodylayout, compiled
from amsa_phys.physics.bodyio import BodyIO
from amsa_phys.physics.forces import ground_list
from amsa_phys.physics.step_path import extension

ROOT = Path(__file__).resolve().parents[2]
built = pytest.mark.skipif(
    extension() is None, reason="the compiled step was not built (no C compiler at install)"
)


@built
def test_the_layout_is_recognised_with_this_pymunk(monkeypatch: pytest.MonkeyPatch) -> None:
    """Else every step would go through the calls, and the tests below compare nothing."""
    monkeypatch.setattr(bodylayout, "_layout", None)
    assert bodylayout.body_layout_ok() is True


@built
def test_a_layout_that_is_not_recognised_keeps_the_calls(monkeypatch: pytest.MonkeyPatch) -> None:
    """Fields one slot off (as another Chipmunk would lay them out): not used."""
    step = extension()
    real = step.body_fields
    monkeypatch.setattr(bodylayout, "_layout", None)
    monkeypatch.setattr(step, "body_fields", lambda a: (*real(a)[1:], 0.0))
    assert bodylayout.body_layout_ok() is False


def _regimes(
    cls: Any, direct: bool, monkeypatch: pytest.MonkeyPatch, cog: bool = False
) -> list[Any]:
    monkeypatch.setattr(bodylayout, "_layout", direct)
    space, rovers, rims, grounds = every_regime(60)
    if cog:  # a body whose centre of gravity is off its origin: the written position's term
        for k, r in enumerate(rovers):
            r.body.center_of_gravity = (0.01 * (k % 7) - 0.03, 0.02 - 0.005 * (k % 5))
    terms = [ground_list(r, *g) for r, g in zip(rovers, grounds, strict=True)]
    model = cls(BodyIO(space, [r.body for r in rovers]), rovers, DT, (100.0, 1e4), terms)
    flat = [u for pair in rims for u in pair]
    model.rims = np.array(rims).T.copy() if cls is compiled.CompiledFleet else flat
    assert model._stepper is not None
    steps = []
    for _ in range(40):
        model.advance()
        steps.append([(*model.kinematics(k), *model.rim_speeds(k)) for k in range(60)])
    return steps


@built
@pytest.mark.parametrize("cog", [False, True], ids=["centred", "off-centre"])
@pytest.mark.parametrize("cls", ["CompiledFewRovers", "CompiledFleet"])
def test_every_regime_steps_alike_in_place_and_through_calls(
    cls: str, cog: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    model = getattr(compiled, cls)
    direct = _regimes(model, True, monkeypatch, cog)
    assert direct == _regimes(model, False, monkeypatch, cog)


@built
def test_a_pile_up_collides_alike_in_place_and_through_calls(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """120 rovers (the fleet path, the spatial hash) whose tail piles up: the same collisions
    at the same instants and the same final states, bit for bit."""
    scen = pile_up(tmp_path, 52)
    monkeypatch.setattr(bodylayout, "_layout", True)
    direct = run(scen, None, monkeypatch)
    monkeypatch.setattr(bodylayout, "_layout", False)
    calls = run(scen, None, monkeypatch)
    assert direct["count"] >= 2  # contacts were solved, or this would compare little
    assert direct["events"] == calls["events"]
    assert np.array_equal(direct["states"], calls["states"])
