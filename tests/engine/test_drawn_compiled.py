"""The compiled random stream (``_publish.Drawn``) hands out the very numbers of the Python
``Drawn``, in the same order, across block boundaries, and a group can still take it over."""

from __future__ import annotations

import numpy as np
import pytest

from amsa_phys.engine import publish, rng

compiled = publish.drawn()
pytestmark = pytest.mark.skipif(compiled is None, reason="the _publish extension is not built")


def python_drawn(draw, block=64):
    """The pure class, whatever the build (``Drawn(...)`` gives the compiled one)."""
    d = object.__new__(rng.Drawn)
    d.__init__(draw, block)
    return d


@pytest.mark.parametrize("block", [1, 3, 64])
@pytest.mark.parametrize("method", ["standard_normal", "random"])
def test_same_numbers_as_the_python_stream(block: int, method: str) -> None:
    fast = compiled(getattr(np.random.default_rng(7), method), block)
    slow = python_drawn(getattr(np.random.default_rng(7), method), block)
    got = [fast() for _ in range(3 * block + 5)]
    want = [slow() for _ in range(3 * block + 5)]
    assert got == want
    assert all(type(v) is float for v in got)


def test_drawn_is_the_compiled_stream_unless_pure(monkeypatch: pytest.MonkeyPatch) -> None:
    draw = np.random.default_rng(1).random
    assert type(rng.Drawn(draw)) is compiled
    monkeypatch.setenv(publish.PURE_ENV, "1")
    assert type(rng.Drawn(draw)) is rng.Drawn


def test_fresh_until_the_first_draw_and_a_group_takes_it_over() -> None:
    streams = [compiled(np.random.default_rng(s).standard_normal) for s in (3, 4)]
    assert all(d.fresh for d in streams)
    many = rng.DrawnMany(streams)
    alone = [python_drawn(np.random.default_rng(s).standard_normal) for s in (3, 4)]
    for _ in range(70):
        assert many().tolist() == [d() for d in alone]
    used = compiled(np.random.default_rng(5).random)
    used()
    assert not used.fresh
    with pytest.raises(RuntimeError, match="drawn from"):
        rng.DrawnMany([used])


def test_a_failing_draw_raises_and_bad_arguments_are_refused() -> None:
    def broken(n: int) -> np.ndarray:
        raise OSError("no entropy")

    d = compiled(broken)
    with pytest.raises(OSError, match="no entropy"):
        d()
    with pytest.raises(ValueError, match="no numbers"):
        compiled(lambda n: np.empty(0))()
    with pytest.raises(ValueError, match="at least 1"):
        compiled(np.random.default_rng(0).random, 0)
    with pytest.raises(TypeError):
        compiled(np.random.default_rng(0).random)(1)
