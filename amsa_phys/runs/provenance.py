"""What made a run: the amsa-phys version and which physics step ran, for ``metrics.json``.

Two runs that differ in their last digits are compared first by asking "same code, same
step?": the compiled step (``_step.c``) and the pure-Python one agree to the bit by design,
but a build without a C compiler, ``AMSA_PHYS_PURE=1`` or a pymunk that hides Chipmunk's
functions changes the path silently, and ``amsa-phys --version`` only says what *would*
run on this machine today. So the run directory records what did.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

from .._version import __version__
from ..engine.face import SimView

#: force models whose whole step (or, for a batch's columns, whose force pass) is the C one
COMPILED_MODELS = ("CompiledFewRovers", "CompiledFleet", "ColumnForces")


def provenance(sim: SimView) -> dict[str, Any]:
    """``{"amsa_phys_version": ..., "physics": {...} or None}`` for ``sim``'s run.

    ``physics`` is None for a world without a physics world (no rover). Otherwise:
    ``rate_hz`` and ``dt_s`` (the physics step), ``steps`` taken, ``step`` (``compiled (C)``
    or ``pure Python (why)``, as ``amsa-phys --version`` words it), ``force_model`` (the
    class that stepped), and ``substep_speed_m_s``: a step is cut into equal Chipmunk
    sub-steps only while the fastest rover is faster than this (so none tunnels through a
    thin wall; null when nothing in the world is thin enough to need it).
    """
    physics = sim.service("physics")
    return {"amsa_phys_version": __version__, "physics": _physics(physics)}


def _physics(physics: Any) -> dict[str, Any] | None:
    if physics is None or not hasattr(physics, "rate"):
        return None
    from ..physics.compiled import status

    model = getattr(physics, "_model", None)
    on, why = status()
    if model is None:  # never stepped (a zero-length run): the step it would have taken
        name, step = None, why
    else:
        name = type(model).__name__
        step = "compiled (C)" if name in COMPILED_MODELS else (why if not on else "pure Python")
    sub = getattr(model, "sub_speed", None)
    rate = Fraction(physics.rate)
    return {
        "rate_hz": int(rate) if rate.denominator == 1 else float(rate),
        "dt_s": float(physics.dt),
        "steps": int(getattr(physics, "_steps", 0)),
        "step": step,
        "force_model": name,
        "substep_speed_m_s": float(sub) if sub is not None and math.isfinite(sub) else None,
    }
