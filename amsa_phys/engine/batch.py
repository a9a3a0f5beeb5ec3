"""Like components of repeated Composites stepped as arrays (the platoon's cars).

A world with 200 cars of seven components each runs 5,600 component steps per simulated
second; at ~3 µs a Python step that alone caps it at ~50x real time. Leaves whose paths
differ only in the number ending their parent's name (``Car1.Pilot``, ``Car2.Pilot``, ...),
with the same template, frequency and connected inputs, form a *group*. When the template
defines ``step_many`` and the group has at least :data:`MIN_GROUP` members, the engine runs
the group in one call at the place of its first member: each input port gathered into one
numpy array, each output scattered back into the members' buffers. The grouping depends
only on the world's paths, so a world expanded by hand (the resolved ``scenario.yaml``)
groups exactly like its ``count:`` form and replays byte for byte.

Stepping a group at one place must not change what any component reads. A group is used
only if, at every instant, for every buffer a component of the instant writes and another
reads, the reader still runs before (or after) the writer as in the world's order — inside
a group, members read before any member writes. Groups that would change a read are not
formed (anywhere, so a leaf is either always or never stepped in its group).

Copies with the same phase and latency group as usual (the group's outputs go through one
delay line); copies with jitter step one by one, since each copy's messages arrive at
instants of their own.

Array arithmetic rounds like the scalar code except where numpy's transcendental functions
or summation order differ in the last bit; a grouped run therefore matches the same world
run leaf by leaf to ~1e-12, not bit for bit (the tests hold it to that).
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np

from . import noise

#: Smallest group stepped as arrays: below it numpy's fixed cost per call outweighs the
#: per-component Python it saves.
MIN_GROUP = 32

_COPY = re.compile(r"^(.*?)(\d+)$")


class ParamArrays:
    """The members' parameter values as float arrays (``p.Kv``), built on first use.

    A built array is kept as an attribute of the instance, so that the next ``p.Kv`` is
    an ordinary attribute read and never reaches :meth:`__getattr__` (a vector env of the
    default scenario reads ~60 parameters a vector step). The engine calls
    :meth:`invalidate` after a timeline or live change to any member.
    """

    def __init__(self, comps: Sequence[Any]) -> None:
        self._comps = comps
        self._built: list[str] = []

    def __getattr__(self, name: str) -> np.ndarray:
        if name.startswith("__") or name in ParamArrays.__dict__:
            raise AttributeError(name)  # copy/pickle probes; never shadow a method
        arr = np.array([getattr(c.p, name) for c in self.__dict__["_comps"]], dtype=float)
        self.__dict__[name] = arr
        self.__dict__["_built"].append(name)
        return arr

    def invalidate(self) -> None:
        """Forget the arrays (a member's parameter changed)."""
        d = self.__dict__
        for name in d["_built"]:
            d.pop(name, None)
        d["_built"].clear()


class Group:
    """Members of one group, each port resolved to the members' positions in the store.

    A port's positions are a :data:`Columns`: a slice when they are evenly spaced (copies
    of one Composite in a single run; one leaf across the runs of a batch, consecutive), a
    fancy index otherwise; either way a whole port moves in one numpy call.
    """

    def __init__(self, tasks: Sequence[Any]) -> None:
        self.tasks = list(tasks)
        self.paths = [t.path for t in tasks]
        self.comps = [t.comp for t in tasks]
        self.template = type(self.comps[0])
        first = dict(tasks[0].reads)
        #: input port -> where the members' values sit in the store
        self.inputs: list[tuple[str, Columns]] = [
            (port, columns([dict(t.reads)[port] for t in tasks])) for port in first
        ]
        #: the same input ports and their positions apart, for the compiled gather
        self.ports = tuple(port for port, _ in self.inputs)
        self.ats = tuple(at for _, at in self.inputs)
        #: output port -> the members' positions, as a list (a delayed group's writes)
        self.targets = {port: [t.writes[port] for t in tasks] for port in tasks[0].writes}
        #: output port -> the same positions as a slice or index array
        self.outputs = {port: columns(at) for port, at in self.targets.items()}
        self.params = ParamArrays(self.comps)
        #: the members' common delay line (they share one latency and have no jitter)
        self.delay = tasks[0].delay
        #: scratch space the template's ``step_many`` owns (arrays of per-member state)
        self.state: dict[str, Any] = {}


#: Where a group's port sits in the store's array: a slice, or an index array.
Columns = slice | np.ndarray


def columns(positions: Sequence[int]) -> Columns:
    """``positions`` as a slice if evenly spaced and increasing (a view, no index array),
    else as an index array."""
    n = len(positions)
    first = positions[0]
    step = positions[1] - first if n > 1 else 1
    if step > 0 and all(positions[k] == first + k * step for k in range(n)):
        return slice(first, first + n * step, step)
    return np.array(positions, dtype=np.intp)


@dataclass(frozen=True)
class Grouping:
    """How a Simulation groups like components (an argument, not a subclass's override).

    ``key(task, freq)`` says which group a task steps in (None: alone); groups smaller than
    ``min_group`` (None: :data:`MIN_GROUP`) are not formed; nothing is grouped unless
    ``enabled``. A batch of runs keys by the path within the run and groups at any size.
    """

    key: Callable[[Any, Fraction], tuple[Any, ...] | None] = field(
        default_factory=lambda: group_key
    )
    min_group: int | None = None
    enabled: bool = True


def group_key(task: Any, freq: Fraction) -> tuple[Any, ...] | None:
    """What members of one group share; None for a leaf that is no copy of anything."""
    parent, _, name = task.path.rpartition(".")
    m = _COPY.match(parent)
    if m is None or not hasattr(type(task.comp), "step_many") or type(task.comp).has_arrays():
        return None
    delay = task.delay
    if delay is not None and delay.draw is not None:
        return None  # jitter: each copy's messages arrive at their own instants
    latency = None if delay is None else delay.fixed
    inputs = tuple(sorted(p for p, _ in task.inputs))
    return (m.group(1), name, type(task.comp), freq, task.phase, latency, inputs)


def plan(
    instants: Sequence[Sequence[Any]],
    keys: dict[tuple[int, str], tuple[Any, ...] | None],
    min_group: int | None = None,
    enabled: bool = True,
) -> list[list[Any]]:
    """Each instant's tasks with the allowed groups merged in (a :class:`Group` per group).

    ``keys`` maps a task's :func:`ident` to its :func:`group_key`; groups smaller than ``min_group``
    (default :data:`MIN_GROUP`) are not formed, nor any if not ``enabled`` (the caller's
    choice: a run compared with its leaf-by-leaf self). Groups that would change what any
    component reads at any instant are dropped everywhere, then the rest re-checked.
    """
    smallest = MIN_GROUP if min_group is None else min_group
    # each distinct key as a small int: a key holds a Fraction, whose hash is Python code,
    # and every instant looks up every task's key again (a 250-run batch: 2,000 tasks)
    ids: dict[tuple[Any, ...], int] = {}
    kid = {p: None if k is None else ids.setdefault(k, len(ids)) for p, k in keys.items()}
    banned: set[int] = set()
    cache: dict[tuple[str, ...], Group] = {}
    sources: dict[int, list[tuple[int, str]]] = {}
    while True:
        out: list[list[Any]] = []
        bad: set[int] = set()
        # an instant whose tasks are those of an instant planned before (the same objects
        # in the same order: most instants of a cycle repeat a few patterns, a batch of
        # scenario1 50 instants in 4) gets that plan: the same groups, the same breaks
        seen: dict[tuple[int, ...], list[Any]] = {}
        for tasks in instants:
            pattern = tuple(map(id, tasks))
            again = seen.get(pattern)
            if again is not None:
                out.append(again)
                continue
            members: dict[int, list[Any]] = {}
            if enabled:
                for t in tasks:
                    key = kid.get(ident(t))
                    if key is not None and key not in banned:
                        members.setdefault(key, []).append(t)
            groups = {k: v for k, v in members.items() if len(v) >= smallest}
            seq = _merged(tasks, groups, cache)
            bad |= _breaks(tasks, seq, kid, groups, sources)
            out.append(seq)
            seen[pattern] = seq
        if not bad:
            return out
        banned |= bad


def _merged(
    tasks: Sequence[Any], groups: dict[int, list[Any]], cache: dict[Any, Group]
) -> list[Any]:
    in_group = {id(t): k for k, ts in groups.items() for t in ts}
    seq: list[Any] = []
    placed: set[int] = set()
    for t in tasks:
        key = in_group.get(id(t))
        if key is None:
            seq.append(t)
        elif key not in placed:
            placed.add(key)
            paths = tuple(ident(m) for m in groups[key])
            if paths not in cache:
                cache[paths] = Group(groups[key])
            seq.append(cache[paths])
    return seq


def _breaks(
    tasks: Sequence[Any],
    seq: Sequence[Any],
    keys: dict[tuple[int, str], int | None],
    groups: dict[int, list[Any]],
    sources: dict[int, list[tuple[int, str]]],
) -> set[int]:
    """Group keys whose merging would change a read at this instant (a reader reads the
    writers of its own run). ``sources`` caches each task's writers (by ``id``) across
    instants."""
    if not groups:  # only a group's key can be bad
        return set()
    pos = {ident(t): i for i, t in enumerate(tasks)}
    slot: dict[tuple[int, str], int] = {}
    for i, item in enumerate(seq):
        for t in item.tasks if isinstance(item, Group) else [item]:
            slot[ident(t)] = i
    bad: set[int] = set()
    for r in tasks:
        me = ident(r)
        writers = sources.get(id(r))
        if writers is None:
            writers = sources[id(r)] = [(r.run, buf.rpartition(".")[0]) for _, buf in r.inputs]
        for w in writers:
            if w not in pos or w == me or tasks[pos[w]].delay is not None:
                continue  # a delayed writer's outputs are never read in the same instant
            before = pos[w] < pos[me]
            same = slot[w] == slot[me]
            if (not before) if same else ((slot[w] < slot[me]) == before):
                continue
            for path in (w, me):
                key = keys.get(path)
                if key is not None and key in groups:
                    bad.add(key)
    return bad


def ident(task: Any) -> tuple[int, str]:
    """What tells tasks apart: (run, path); the runs of a batch share their paths."""
    return (task.run, task.path)


def derived(
    state: dict[str, Any], key: str, args: tuple[Any, ...], make: Callable[..., Any]
) -> Any:
    """``make(*args)``, remembered in a group's ``state`` under ``key`` while ``args`` are the
    very same objects (``is``).

    Why: a template's ``step_many`` recomputes what depends on its parameters alone (a
    sensor's turn-on bias, whether every copy quantises) at every step, a few numpy calls
    each. Parameter arrays (:class:`ParamArrays`) are the same objects until a member's
    parameter changes, when they are built anew: so identity says when to recompute.
    """
    ids = tuple(map(id, args))
    hit = state.get(key)
    # equal ids are the same objects: the entry holds the old ones, so none of their ids
    # can have been given to another object meanwhile
    if hit is not None and hit[0] == ids:
        return hit[1]
    value = make(*args)
    state[key] = (ids, value, args)
    return value


def all_positive(values: np.ndarray) -> bool:
    """Whether every copy's ``values`` is above 0 (a sensor: every copy quantises, so
    ``noise.quantise_many`` is its plain arithmetic; for :func:`derived`)."""
    return bool((values > 0).all())


def gauss_markov(state: dict[str, Any], sigma: Any, tau: Any, dt: float) -> Any:
    """``noise.gauss_markov_many(sigma, tau, dt)``, remembered in a group's ``state`` while
    the parameter arrays are the same objects and the period the same (as :func:`derived`;
    a sensor asks at every step with the same three)."""
    hit = state.get("_gauss_markov")
    if hit is None or hit[0] is not sigma or hit[1] is not tau or hit[2] != dt:
        hit = state["_gauss_markov"] = (sigma, tau, dt, noise.gauss_markov_many(sigma, tau, dt))
    return hit[3]


# the quick check below squares the values: finite values above ~1e154 overflow it, which
# numpy reports as a RuntimeWarning attributed to this module. The overflow is expected and
# handled (the exact check clears such values), so that one message from here is not shown;
# a filter costs nothing per call, where ``np.errstate`` would cost more than the check.
warnings.filterwarnings(
    "ignore", message="overflow encountered in dot", category=RuntimeWarning, module=__name__
)


def first_bad(arr: np.ndarray, published: np.ndarray | None) -> int | None:
    """Index of the first published member whose value is not finite, or None.

    Every output of every group at every instant passes here (a vector env of the default
    scenario: ~35 a vector step), so the usual case is one call, not two: the dot product
    of the values with themselves is finite only if every value is (NaN and infinity carry
    through, and a sum of squares is never NaN otherwise). Finite values large enough to
    overflow the sum (|x| > ~1e154) take the exact path below and are found good there.
    With a ``published`` mask the same call clears the usual case too (every value finite,
    so every published one): the mask is applied only when some value is not finite (a
    lost GPS fix's row may hold anything).
    """
    if math.isfinite(arr.dot(arr)):  # the usual case, one call
        return None
    bad = ~np.isfinite(arr)
    if published is not None:
        bad &= published
    return int(np.argmax(bad)) if bad.any() else None
