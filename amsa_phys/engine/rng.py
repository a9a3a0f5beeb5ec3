"""The seed tree: one independent, reproducible random stream per component.

Each component's stream is keyed by ``zlib.crc32`` of its path (never ``hash()``, which is
salted per process), so adding a component or running in another process or order leaves
every other component's random numbers unchanged.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import numpy as np
from numpy.random.bit_generator import ISpawnableSeedSequence

from . import publish


def component_rng(seed: int, path: str) -> np.random.Generator:
    """The Generator for ``path`` under scenario ``seed``."""
    ss = seed_sequence(seed, (zlib.crc32(path.encode("utf-8")),))
    return np.random.Generator(np.random.PCG64(ss))


def seed_sequence(entropy: int, spawn_key: tuple[int, ...]) -> ISpawnableSeedSequence:
    """``numpy.random.SeedSequence(entropy, spawn_key=spawn_key)``, or where the ``_seeds``
    extension is built a :class:`FastSeed` that seeds a ``PCG64`` (and spawns children)
    exactly as it would, ~10x cheaper (``_seeds.c`` says why)."""
    return _seed_sequence(publish._extension("_seeds"), entropy, spawn_key)


def _seed_sequence(fast: Any, entropy: int, spawn_key: tuple[int, ...]) -> ISpawnableSeedSequence:
    """:func:`seed_sequence` with the ``_seeds`` extension (or None) already looked up: a
    spawn asks once for all its children."""
    if fast is not None:
        state = fast.seed_state(entropy, spawn_key)
        if state is not None:
            return FastSeed(entropy, spawn_key, state)
    return np.random.SeedSequence(entropy=entropy, spawn_key=spawn_key)


#: the dtype of the C seeding's words (little-endian, as numpy's ``generate_state`` makes them)
_WORDS = np.dtype("<u8")


class FastSeed(ISpawnableSeedSequence):
    """A ``numpy.random.SeedSequence`` (pool size 4) whose ``PCG64`` state was computed in C.

    ``generate_state(4, uint64)`` (what ``PCG64`` asks) is the C result; ``spawn(n)`` gives
    children of this class keyed as numpy's (``spawn_key + (i,)``, counting the children
    spawned so far); anything else (another size, ``pool``, ``state``) is asked of the
    equivalent numpy ``SeedSequence``, and a pickle or a copy is one.
    """

    __slots__ = ("_state", "entropy", "n_children_spawned", "spawn_key")
    pool_size = 4

    def __init__(self, entropy: int, spawn_key: tuple[int, ...], state: bytes) -> None:
        self.entropy = entropy
        self.spawn_key = spawn_key
        self.n_children_spawned = 0
        self._state = state

    def generate_state(self, n_words: int, dtype: Any = np.uint32) -> np.ndarray:
        """numpy's ``generate_state``; (4, uint64) without numpy's seeding."""
        # ``PCG64`` passes the type itself: the identity test spares a dtype conversion
        if n_words == 4 and (dtype is np.uint64 or np.dtype(dtype) == np.uint64):
            return np.frombuffer(self._state, dtype=_WORDS).astype(np.uint64)
        return self.as_numpy().generate_state(n_words, dtype)

    def spawn(self, n_children: int) -> list[ISpawnableSeedSequence]:
        """numpy's ``spawn``: the next ``n_children`` children."""
        first = self.n_children_spawned
        self.n_children_spawned += n_children
        fast = publish._extension("_seeds")
        return [
            _seed_sequence(fast, self.entropy, (*self.spawn_key, i))
            for i in range(first, first + n_children)
        ]

    def as_numpy(self) -> np.random.SeedSequence:
        """The same sequence as numpy's own."""
        return np.random.SeedSequence(
            self.entropy, spawn_key=self.spawn_key, n_children_spawned=self.n_children_spawned
        )

    @property
    def pool(self) -> np.ndarray:
        return self.as_numpy().pool

    @property
    def state(self) -> dict[str, Any]:
        return self.as_numpy().state

    def __reduce__(self) -> tuple[Any, ...]:
        return (_numpy_seed, (self.entropy, self.spawn_key, self.n_children_spawned))

    def __repr__(self) -> str:
        return repr(self.as_numpy())


def _numpy_seed(entropy: int, spawn_key: tuple[int, ...], spawned: int) -> np.random.SeedSequence:
    """A pickled :class:`FastSeed`, back as numpy's own."""
    return np.random.SeedSequence(entropy, spawn_key=spawn_key, n_children_spawned=spawned)


def named_rng(seed: int, path: str, name: str) -> np.random.Generator:
    """A stream of ``path`` for one engine purpose (``"phase"``, ``"jitter"``), apart from
    the component's own.

    Keyed by the component's crc32 and the name's, with bit 32 set so it can never be a
    child the component spawns from its own stream (``rng.spawn(n)`` keys 0 .. n-1 under
    the same first key): adding timing to a world changes no component's random numbers.
    """
    key = (zlib.crc32(path.encode("utf-8")), (1 << 32) | zlib.crc32(name.encode("utf-8")))
    ss = seed_sequence(seed, key)
    return np.random.Generator(np.random.PCG64(ss))


class Drawn:
    """Scalars from one random stream, drawn from numpy in blocks.

    A sensor needs one or two random numbers a step; asking numpy for each costs ~1 µs (a
    call and an array), drawing 64 at once costs ~0.02 µs a number. The sequence is fixed by
    the stream alone, so it is the same whatever else the component does between draws.
    ``draw(n)`` returns the next ``n`` numbers, e.g. ``rng.standard_normal``.
    """

    def __new__(cls, draw: Callable[[int], np.ndarray], block: int = 64) -> Any:
        """The compiled ``Drawn`` where built (``_publish.c``: the same numbers, a call a
        fraction of this class's ``__call__``), this class on the pure path."""
        fast = publish.drawn() if cls is Drawn else None
        if fast is not None:
            return fast(draw, block)
        return super().__new__(cls)

    def __init__(self, draw: Callable[[int], np.ndarray], block: int = 64) -> None:
        self._draw = draw
        self._block = block
        self._it: Iterator[float] = iter(())
        self._unused = self._it  # replaced at the first draw

    def __call__(self) -> float:
        """The next number."""
        try:
            return next(self._it)
        except StopIteration:
            self._it = iter(self._draw(self._block).tolist())
            return next(self._it)

    @property
    def fresh(self) -> bool:
        """Whether nothing was drawn yet (a group may then take the stream over)."""
        return self._it is self._unused


#: the first block a :class:`DrawnMany` draws; each refill after it draws twice as many
MANY_BLOCK_FIRST = 64
#: the most bytes one :class:`DrawnMany` buffer holds (the largest block fills it)
MANY_BYTES = 2 << 20
#: the largest block a :class:`DrawnMany` of few streams draws at a time
MANY_BLOCK_MAX = 1024


def many_block(streams: int) -> int:
    """The largest block a :class:`DrawnMany` of ``streams`` streams draws per stream at a
    refill: as many as :data:`MANY_BYTES` hold, between 64 and :data:`MANY_BLOCK_MAX`.

    Why: a refill is one Python call per stream (~1-2 µs) whatever the block. At 1,000
    streams and blocks of 64 that was ~30 µs of every draw's ~50 (a vector env's GPS and
    compass groups draw 15 times a vector step); blocks of 262 bring a draw to ~16 µs, for
    2 MB a buffer. The blocks grow to it from :data:`MANY_BLOCK_FIRST`, doubling at each
    refill, so a short run (a sweep's 60 s: 240 GPS fixes) draws at most about twice the
    numbers it uses. A stream's numbers do not depend on the blocks (a Generator fills in
    sequence), so the runs do not either."""
    return max(64, min(MANY_BLOCK_MAX, MANY_BYTES // (8 * max(1, streams))))


class DrawnMany:
    """The next number of each of many streams at once, as an array.

    The group form of :class:`Drawn` (``engine/batch.py``): every stream fills its row of a
    (streams, block) array in one numpy call, the array is turned once into (block,
    streams), and each call returns the next row, so every stream yields exactly the numbers
    it would one at a time. It takes over fresh ``Drawn`` streams (a leaf is stepped in its
    group always or never).

    Why the turn: a column of the (streams, block) array has its numbers ``8 * block`` bytes
    apart; with blocks of 1,024 that is 8 KB, which puts every one of them in the same set
    of the CPU's first-level cache, and a GPS group's draws and arithmetic then cost twice
    what they cost on contiguous rows. One copy a refill makes every draw a contiguous row.
    """

    def __init__(self, streams: Sequence[Drawn], block: int | None = None) -> None:
        if not all(d.fresh for d in streams):
            raise RuntimeError("a stream was drawn from before its group took it over")
        self._draws = [d._draw for d in streams]
        #: the largest block (``block`` given: every block); the first is at most
        #: :data:`MANY_BLOCK_FIRST`, and each refill doubles it up to this
        self._largest = many_block(len(streams)) if block is None else block
        self._block = min(MANY_BLOCK_FIRST, self._largest) if block is None else block
        self._buf = np.empty((0, len(streams)))  # (block, streams) once filled
        #: the rows of the block not handed out yet (a draw is ``next`` of it: ~0.1 µs,
        #: where counting and indexing rows was ~0.4)
        self._rows: Iterator[np.ndarray] = iter(())
        #: every stream a Generator method that can fill a row in place (``out=``): a
        #: refill then allocates one array, not one per stream plus the stacked copy
        #: (1,000 streams: ~0.95 ms instead of ~1.15; the same numbers either way)
        self._in_place = all(_fills(draw) for draw in self._draws)
        #: every stream the same such method, and the ``_draws`` extension built and drawing
        #: as numpy does here: the whole block in one call (``_draws.c`` says why)
        self._fill: Callable[[int, np.ndarray], None] | None = None
        self._kind = _KINDS.get(self._draws[0].__name__, -1) if self._draws else -1
        if self._in_place and self._kind >= 0:
            name = self._draws[0].__name__
            ext = _draws_extension()
            if ext is not None and all(d.__name__ == name for d in self._draws):
                streams = ext.Streams([d.__self__.bit_generator for d in self._draws])
                self._fill = streams.fill

    def __call__(self) -> np.ndarray:
        """The next number of every stream."""
        row = next(self._rows, None)
        if row is None:
            self._refill()
            row = next(self._rows)
        return row

    def _refill(self) -> None:
        """Draw the next block of every stream (see the class docstring)."""
        if len(self._buf):  # not the first refill: a longer block
            self._block = min(2 * self._block, self._largest)
        if self._fill is not None:
            buf = np.empty((len(self._draws), self._block))
            self._fill(self._kind, buf)
        elif self._in_place:
            buf = np.empty((len(self._draws), self._block))
            for draw, row in zip(self._draws, buf, strict=True):
                draw(out=row)
        else:
            buf = np.array([draw(self._block) for draw in self._draws])
        # a new buffer each time: rows handed out stay valid
        self._buf = np.ascontiguousarray(buf.T)
        self._rows = iter(self._buf)


#: Generator methods that draw float64s into ``out=`` exactly as ``method(size)`` would
_OUT_METHODS = frozenset({"standard_normal", "random", "standard_exponential"})
#: the same methods as the ``_draws`` extension's kinds (``_draws.c``'s ``fills``)
_KINDS = {"standard_normal": 0, "random": 1, "standard_exponential": 2}
#: the ``_draws`` extension once checked against numpy (:func:`_draws_extension`)
_checked: dict[str, Any] = {}


def _draws_extension() -> Any:
    """The ``_draws`` extension, or None: not built, the pure path asked for, or drawing
    other numbers than this numpy's Generator methods.

    Why the check: the extension carries the distributions of the numpy it was built
    against, and numpy may change a distribution's algorithm between versions; a run must
    draw what ``Generator.standard_normal`` draws in the numpy it runs with. Asked once a
    process (~0.1 ms): each kind's first 300 numbers of two seeds, both ways."""
    ext = publish._extension("_draws")
    if ext is None:
        return None
    verdict = _checked.get("ok")
    if verdict is None:
        verdict = _checked["ok"] = _draws_agree(ext)
    return ext if verdict else None


def _draws_agree(ext: Any) -> bool:
    """Whether ``ext`` fills every kind as this numpy's Generator methods draw."""
    for name, kind in _KINDS.items():
        ours = [np.random.Generator(np.random.PCG64(s)) for s in (1, 2**63 + 5)]
        theirs = [np.random.Generator(np.random.PCG64(s)) for s in (1, 2**63 + 5)]
        out = np.empty((2, 300))
        ext.Streams([g.bit_generator for g in ours]).fill(kind, out)
        want = np.array([getattr(g, name)(300) for g in theirs])
        if out.tobytes() != want.tobytes():
            return False
    return True


def _fills(draw: Callable[..., Any]) -> bool:
    """Whether ``draw`` is a Generator method in :data:`_OUT_METHODS`."""
    owner = getattr(draw, "__self__", None)
    return isinstance(owner, np.random.Generator) and draw.__name__ in _OUT_METHODS
