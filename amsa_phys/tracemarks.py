"""Marks read back from a finished run's trace: where GPS fixes were lost.

A lost GPS sample publishes nothing, so its consumers (and the trace) keep the stale fix:
the fix column does not change across one of the GPS's sampling instants. The live window
counts losses in the running component; a finished run has only its trace, so the replay
(``amsa-phys view``) and ``trajectory.png`` find them here, the same way, and mark them with
the same red × as the window and the video (``palette.LOST_FIX``). Pure numpy, no drawing:
a top-level module because both ``view`` and ``plots`` use it and must not import each other.

Only a fix that can lose samples (one of its template's ``loss_params``, ``lostDataGPS`` or
``burstLoss`` for the GPS, above 0 at some point of the run) is searched: a noiseless GPS on
a parked rover also repeats its fix, and that is not a loss.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .templatemarks import Fix, marked

#: how far (s) a trace row may sit from a sampling instant and still show that sample
_EPS_S = 1e-9


@dataclass(frozen=True)
class GpsLink:
    """One GPS of the world: its path, the rover it measures and its sampling period."""

    path: str
    rover: str | None
    period_s: float
    #: the GPS can lose samples (its loss parameters, anywhere in the run, are above 0)
    lossy: bool
    #: the trace columns of the fix (``path.port``, its template's :class:`Fix` mark)
    x: str = ""
    y: str = ""
    #: the parameters that, above 0, make it lose samples
    loss_params: tuple[str, ...] = ()

    def made_lossy(self, lossy: set[tuple[str, str]]) -> bool:
        """Whether it can lose samples, its own settings or the run's (:func:`lossy_in_run`)."""
        return self.lossy or any((self.path, p) in lossy for p in self.loss_params)


def gps_links(
    leaves: Mapping[str, Any], lossy_also: Iterable[tuple[str, str]] = ()
) -> list[GpsLink]:
    """The position fixes of a world (``WorldSpec.leaves``), one per :class:`Fix` a template
    declares; ``lossy_also``: ``(path, parameter)`` the run set above 0
    (:func:`lossy_in_run`: a loss switched on at 125 s)."""
    lossy_also = set(lossy_also)
    out = []
    for path, leaf, fix in marked(leaves, Fix):
        params = dict(leaf.params)
        loses = any(params.get(p, 0) > 0 or (path, p) in lossy_also for p in fix.loss_params)
        source = leaf.inputs.get(fix.measures, "") if fix.measures else ""
        rover = source.rpartition(".")[0] or None
        freq = float(leaf.freq) if leaf.freq else 0.0
        period = 1.0 / freq if freq > 0 else 0.0
        x, y = f"{path}.{fix.x}", f"{path}.{fix.y}"
        out.append(GpsLink(path, rover, period, loses, x, y, tuple(fix.loss_params)))
    return out


def lossy_in_run(metrics: Mapping[str, Any]) -> set[tuple[str, str]]:
    """``(component, parameter)`` a run's ``metrics.json`` shows set above 0 (in a phase's
    ``set`` or a change inside a phase: ``--set``, the timeline, the window): a fix whose
    template names that parameter among its ``loss_params`` can lose samples."""
    out = set()
    for phase in metrics.get("phases") or []:
        sets = [phase.get("set") or {}, *((c.get("set") or {}) for c in phase.get("changes") or [])]
        for values in sets:
            for key, value in values.items():
                leaf, _, param = str(key).rpartition(".")
                if isinstance(value, int | float) and value > 0:
                    out.add((leaf, param))
    return out


def lost_fix_rows(t: np.ndarray, fx: np.ndarray, fy: np.ndarray, period_s: float) -> np.ndarray:
    """Rows (indices into ``t``) at which a GPS sample was due but no new fix appeared.

    ``t`` are the trace's times, ``fx``/``fy`` the GPS's published fix. Between two
    consecutive new fixes ``gap / period_s - 1`` samples (rounded) were lost, due one period
    after another from the earlier fix; after the last fix, every period until the trace
    ends. Counting from the fixes themselves, not from a grid ``k * period_s``, makes the
    GPS's timer phase (a free-running world draws one) and any constant delivery delay
    irrelevant. Before the first fix (a GPS with latency publishes nothing at first) nothing
    counts as lost.
    """
    if period_s <= 0 or len(t) < 2:
        return np.empty(0, dtype=int)
    new = np.flatnonzero((fx[1:] != fx[:-1]) | (fy[1:] != fy[:-1])) + 1
    if not new.size:
        return np.empty(0, dtype=int)
    at = t[new]
    due: list[float] = []
    for a, b in zip(at[:-1].tolist(), at[1:].tolist(), strict=True):
        missed = round((b - a) / period_s) - 1
        due += [a + k * period_s for k in range(1, missed + 1)]
    tail = math.floor((float(t[-1]) - float(at[-1])) / period_s + 1e-6)
    due += [float(at[-1]) + k * period_s for k in range(1, tail + 1)]
    rows = np.searchsorted(t, np.asarray(due) - _EPS_S, side="left")
    return rows[rows < len(t)].astype(int)
