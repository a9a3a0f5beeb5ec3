"""A group's random streams (``rng.DrawnMany``) draw blocks that grow from 64 to a size
set by the group (``rng.many_block``): whatever the blocks, every stream yields the numbers
it yields alone, and a short run draws little more than it uses."""

from __future__ import annotations

import numpy as np
import pytest

from amsa_phys.engine import rng


def test_the_block_shrinks_with_the_streams_within_its_bounds() -> None:
    assert rng.many_block(1) == rng.MANY_BLOCK_MAX
    assert rng.many_block(16) == rng.MANY_BLOCK_MAX
    assert rng.many_block(1000) == rng.MANY_BYTES // 8000
    assert rng.many_block(10**6) == 64
    for n in (1, 16, 300, 1000, 10**5):
        assert 64 <= rng.many_block(n) <= rng.MANY_BLOCK_MAX
        assert n * rng.many_block(n) * 8 <= max(rng.MANY_BYTES, n * 64 * 8)


@pytest.mark.parametrize("n", [3, 1000])
@pytest.mark.parametrize("method", ["standard_normal", "random"])
def test_every_stream_draws_what_it_draws_alone_across_refills(n: int, method: str) -> None:
    many = rng.DrawnMany([rng.Drawn(getattr(np.random.default_rng(s), method)) for s in range(n)])
    draws = sum(64 << k for k in range(5)) + 2 * rng.many_block(n) + 5  # past the largest
    got = np.array([many().copy() for _ in range(draws)])  # (draws, n)
    for s in (0, n // 2, n - 1):
        alone = getattr(np.random.default_rng(s), method)(draws)
        assert got[:, s].tobytes() == alone.tobytes()


def test_a_short_run_draws_at_most_about_twice_what_it_uses() -> None:
    asked: list[int] = []

    def draw(size: int) -> np.ndarray:
        asked.append(size)
        return np.arange(size, dtype=np.float64)

    many = rng.DrawnMany([rng.Drawn(draw) for _ in range(4)])
    for used in range(1, 3000):
        many()
        drawn = sum(asked) // 4
        assert drawn <= max(rng.MANY_BLOCK_FIRST, 2 * used + rng.MANY_BLOCK_FIRST), used
    assert max(asked) == rng.many_block(4)  # the blocks reached the largest
