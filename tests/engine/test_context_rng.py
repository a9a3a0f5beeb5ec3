"""A component's random stream is made when it first asks for it: the same numbers as ever
(keyed by the seed and the path alone), and none made for a component that draws nothing."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from amsa_phys.engine import context
from amsa_phys.engine.context import Context
from amsa_phys.engine.rng import component_rng


def sim(seed: int) -> SimpleNamespace:
    return SimpleNamespace(seed=seed, world=None)


def test_the_stream_is_the_components_own(monkeypatch: pytest.MonkeyPatch) -> None:
    made: list[str] = []

    def counted(seed: int, path: str):  # type: ignore[no-untyped-def]
        made.append(path)
        return component_rng(seed, path)

    monkeypatch.setattr(context, "component_rng", counted)
    ctx = Context(sim(42), "Leader")  # type: ignore[arg-type]
    assert made == []  # nothing drawn, nothing made
    first = ctx.rng.random(5).tolist()
    assert ctx.rng.random(2).tolist() == component_rng(42, "Leader").random(7).tolist()[5:]
    assert first == component_rng(42, "Leader").random(5).tolist()
    assert made == ["Leader"]  # made once, kept
    assert Context(sim(43), "Leader").rng.random() != component_rng(42, "Leader").random()  # type: ignore[arg-type]


def test_other_missing_attributes_still_raise() -> None:
    ctx = Context(sim(1), "A")  # type: ignore[arg-type]
    with pytest.raises(AttributeError, match="no attribute 'rnq'"):
        ctx.rnq  # noqa: B018
    assert not hasattr(ctx, "nothing")
