"""The runs' random streams seeded without numpy's Python-level seeding (``rng.FastSeed``,
``_seeds.c``): every Generator, and every stream split off it, draws what numpy's own
``SeedSequence`` gives, so a scenario's random numbers are what they always were."""

from __future__ import annotations

import copy
import importlib.util
import pickle
import random
import zlib

import numpy as np
import pytest

from amsa_phys.engine import rng

BUILT = importlib.util.find_spec("amsa_phys.engine._seeds") is not None
#: built and not switched off (``AMSA_PHYS_PURE=1``)
needs_c = pytest.mark.skipif(
    not BUILT or not isinstance(rng.seed_sequence(0, ()), rng.FastSeed),
    reason="the seeding extension was not built, or the pure path was asked for",
)


def _numpy(entropy: int, key: tuple[int, ...]) -> np.random.Generator:
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(entropy, spawn_key=key)))


def _cases() -> list[tuple[int, tuple[int, ...]]]:
    edges = [0, 1, 2**32 - 1, 2**32, 2**63 - 1, 2**64 - 1]
    cases = [(e, k) for e in edges for k in [(), (0,), (2**32 - 1,), (2**32 + 5, 0), (7, 8, 9)]]
    draw = random.Random(45)
    for _ in range(500):
        bits = draw.choice([1, 16, 31, 32, 33, 48, 63, 64])
        key = tuple(
            draw.randrange(2 ** draw.choice([1, 32, 33, 64])) for _ in range(draw.randrange(5))
        )
        cases.append((draw.randrange(2**bits), key))
    return cases


@needs_c
def test_the_state_is_numpys_for_seeds_and_keys_of_every_size() -> None:
    from amsa_phys.engine import _seeds

    for entropy, key in _cases():
        want = np.random.SeedSequence(entropy, spawn_key=key).generate_state(4, np.uint64)
        assert _seeds.seed_state(entropy, key) == want.astype("<u8").tobytes(), (entropy, key)


@needs_c
def test_streams_and_the_streams_split_off_them_draw_numpys_numbers() -> None:
    path = "Leader.GPS"
    got = rng.component_rng(7, path)
    want = _numpy(7, (zlib.crc32(path.encode()),))
    assert isinstance(got.bit_generator.seed_seq, rng.FastSeed)
    assert got.standard_normal(50).tobytes() == want.standard_normal(50).tobytes()
    for n in (4, 2):  # the children numbered on from those spawned before
        for a, b in zip(got.spawn(n), want.spawn(n), strict=True):
            assert a.random(20).tobytes() == b.random(20).tobytes()
            for c, d in zip(a.spawn(3), b.spawn(3), strict=True):  # grandchildren
                assert c.integers(0, 2**62, 10).tolist() == d.integers(0, 2**62, 10).tolist()
    named = rng.named_rng(3, path, "jitter")
    key = (zlib.crc32(path.encode()), (1 << 32) | zlib.crc32(b"jitter"))
    assert named.random(20).tobytes() == _numpy(3, key).random(20).tobytes()


@needs_c
def test_a_copy_or_a_pickle_is_numpys_own_sequence_in_the_same_place() -> None:
    got = rng.component_rng(11, "A")
    want = _numpy(11, (zlib.crc32(b"A"),))
    got.spawn(2)
    want.spawn(2)
    for other in (pickle.loads(pickle.dumps(got)), copy.deepcopy(got)):
        seq = other.bit_generator.seed_seq
        assert type(seq) is np.random.SeedSequence
        assert seq.n_children_spawned == 2
        assert other.spawn(1)[0].random(5).tobytes() == want.spawn(1)[0].random(5).tobytes()
        want = _numpy(11, (zlib.crc32(b"A"),))
        want.spawn(2)
    seq = got.bit_generator.seed_seq
    assert seq.pool.tolist() == want.bit_generator.seed_seq.pool.tolist()
    assert seq.generate_state(3).tolist() == want.bit_generator.seed_seq.generate_state(3).tolist()


def test_what_the_extension_does_not_take_is_numpys_sequence() -> None:
    """Seeds beyond 64 bits (or anything not an int) go to numpy, which seeds (or refuses)
    them as it always did."""
    big = rng.seed_sequence(2**70 + 3, (5,))
    assert type(big) is np.random.SeedSequence
    assert big.entropy == 2**70 + 3
    with pytest.raises((TypeError, ValueError)):
        rng.seed_sequence(-1, (5,)).generate_state(4)
