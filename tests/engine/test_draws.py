"""A group's random streams refilled in one C call (``_draws.c``, ``rng.DrawnMany``): every
stream yields exactly what its Generator method yields, so a run's random numbers are what
they always were; an extension that draws otherwise is not used."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from amsa_phys.engine import publish, rng

BUILT = importlib.util.find_spec("amsa_phys.engine._draws") is not None
needs_c = pytest.mark.skipif(
    not BUILT or rng._draws_extension() is None,
    reason="the draws extension was not built, or the pure path was asked for",
)

METHODS = ("standard_normal", "random", "standard_exponential")


def _gens(n: int, bitgen: type = np.random.PCG64, base: int = 7) -> list[np.random.Generator]:
    return [np.random.Generator(bitgen(base + 1000 * i)) for i in range(n)]


@needs_c
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("bitgen", [np.random.PCG64, np.random.Philox, np.random.SFC64])
def test_fill_draws_what_the_generator_method_draws(method: str, bitgen: type) -> None:
    """Blocks of several sizes in a row, each stream's numbers those of its own Generator's
    method, bit for bit, the sequence going on across blocks."""
    ext = publish._extension("_draws")
    ours, theirs = _gens(9, bitgen), _gens(9, bitgen)
    streams = ext.Streams([g.bit_generator for g in ours])
    for block in (1, 3, 64, 257, 1024):
        out = np.empty((9, block))
        streams.fill(rng._KINDS[method], out)
        want = np.array([getattr(g, method)(block) for g in theirs])
        assert out.tobytes() == want.tobytes(), (method, block)
    # the Generators themselves go on from where the fills left them
    assert [g.standard_normal() for g in ours] == [g.standard_normal() for g in theirs]


@needs_c
def test_fill_refuses_a_bad_kind_or_buffer() -> None:
    ext = publish._extension("_draws")
    streams = ext.Streams([g.bit_generator for g in _gens(3)])
    with pytest.raises(ValueError, match="unknown kind"):
        streams.fill(ext.KINDS, np.empty((3, 4)))
    with pytest.raises(ValueError, match="one row a stream"):
        streams.fill(0, np.empty((4, 4)))  # 16 numbers are not 3 rows
    with pytest.raises(ValueError, match="float64"):
        streams.fill(0, np.empty((3, 4), dtype=np.float32))
    with pytest.raises(ValueError, match="C-contiguous"):
        streams.fill(0, np.empty((4, 3)).T)
    with pytest.raises(ValueError, match="writable"):
        streams.fill(0, np.empty((3, 4)).tobytes())  # read-only
    with pytest.raises(AttributeError):
        ext.Streams([object()])  # no bit generator


def _only_draws(monkeypatch: pytest.MonkeyPatch, fake: object) -> None:
    """``fake`` as the ``_draws`` extension (not yet checked), every other one as it is."""
    real = publish._extension
    monkeypatch.setattr(rng, "_checked", {})
    monkeypatch.setattr(
        publish, "_extension", lambda name="_publish": fake if name == "_draws" else real(name)
    )


def _drawn_many(method: str, n: int) -> rng.DrawnMany:
    return rng.DrawnMany([rng.Drawn(getattr(g, method)) for g in _gens(n)])


@needs_c
@pytest.mark.parametrize("method", METHODS)
def test_drawn_many_draws_the_same_rows_with_and_without_the_extension(method: str) -> None:
    """A DrawnMany over 300 streams through several refills (blocks of 64, 128, ...): the
    same rows whether it refills in C or stream by stream in Python."""
    fast = _drawn_many(method, 300)
    slow = _drawn_many(method, 300)
    assert fast._fill is not None
    slow._fill = None
    for _ in range(700):
        assert fast().tobytes() == slow().tobytes()


def test_an_extension_that_draws_otherwise_is_not_used(monkeypatch: pytest.MonkeyPatch) -> None:
    """An extension built against a numpy whose distributions differ (here: normals where
    uniforms are asked) is found out and the Python loop refills."""

    class Streams:
        def __init__(self, bitgens: list[object]) -> None:
            self.gens = [np.random.Generator(b) for b in bitgens]

        def fill(self, kind: int, out: np.ndarray) -> None:
            for g, row in zip(self.gens, out, strict=True):
                g.standard_normal(out=row)  # every kind drawn as a normal

    class Fake:
        KINDS = 3

    Fake.Streams = Streams  # type: ignore[attr-defined]
    _only_draws(monkeypatch, Fake())
    assert rng._draws_extension() is None
    many = rng.DrawnMany([rng.Drawn(g.random) for g in _gens(4)])
    assert many._fill is None
    want = np.array([g.random(64) for g in _gens(4)])
    assert np.array_equal(np.array([many() for _ in range(64)]).T, want)


def test_a_faithful_extension_is_used(monkeypatch: pytest.MonkeyPatch) -> None:
    """The check passes an extension that draws as numpy does (the method's own fill)."""
    names = {v: k for k, v in rng._KINDS.items()}

    class Streams:
        def __init__(self, bitgens: list[object]) -> None:
            self.gens = [np.random.Generator(b) for b in bitgens]

        def fill(self, kind: int, out: np.ndarray) -> None:
            for g, row in zip(self.gens, out, strict=True):
                getattr(g, names[kind])(out=row)

    class Fake:
        pass

    Fake.Streams = Streams  # type: ignore[attr-defined]
    fake = Fake()
    _only_draws(monkeypatch, fake)
    assert rng._draws_extension() is fake


def test_pure_path_refills_in_python(monkeypatch: pytest.MonkeyPatch) -> None:
    """``AMSA_PHYS_PURE=1``: no extension, the same numbers."""
    monkeypatch.setenv("AMSA_PHYS_PURE", "1")
    many = _drawn_many("standard_normal", 5)
    assert many._fill is None
    want = np.array([g.standard_normal(64) for g in _gens(5)])
    assert np.array_equal(np.array([many() for _ in range(64)]).T, want)


@pytest.mark.skipif(not BUILT, reason="the draws extension was not built")
def test_the_extension_built_here_is_used(monkeypatch: pytest.MonkeyPatch) -> None:
    """Built against this numpy, the extension passes its check (else every group would
    refill stream by stream, and the tests above would skip)."""
    monkeypatch.delenv("AMSA_PHYS_PURE", raising=False)
    monkeypatch.setattr(rng, "_checked", {})
    assert rng._draws_extension() is not None
