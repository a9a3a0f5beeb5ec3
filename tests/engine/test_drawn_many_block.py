"""A group's random streams (``rng.DrawnMany``) draw blocks sized by the group
(``rng.many_block``): whatever the block, every stream yields the numbers it yields alone."""

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
    block = rng.many_block(n)
    draws = 2 * block + 5  # two refills and part of a third
    got = np.array([many().copy() for _ in range(draws)])  # (draws, n)
    for s in (0, n // 2, n - 1):
        alone = getattr(np.random.default_rng(s), method)(draws)
        assert got[:, s].tobytes() == alone.tobytes()
