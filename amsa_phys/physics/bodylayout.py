"""Whether the compiled step may read pymunk's bodies in place (``_step.c``'s ``direct``
mode): checked once a process against pymunk's own getters (see :func:`body_layout_ok`)."""

from __future__ import annotations

from typing import Any

_layout: bool | None = None


def body_layout_ok() -> bool:
    """Whether the C step may read this pymunk's bodies in place (``_step.c``'s ``BODY_*``
    offsets, its ``direct`` mode): a body set up with a distinct value in every field it
    reads, each found at its offset as pymunk's own getters report it, and the position it
    writes related to the transform as ``cpBodySetPosition`` relates them (Python's float
    arithmetic, which rounds as C without contraction does). Checked once a process; any
    difference (another Chipmunk layout, a build that fuses multiply-adds) keeps every
    access a call into Chipmunk."""
    global _layout
    if _layout is None:
        _layout = _check_layout()
    return _layout


def _check_layout() -> bool:
    from .step_path import extension

    step: Any = extension()
    if step is None or not hasattr(step, "body_fields"):
        return False
    try:
        import pymunk
        from pymunk._chipmunk import ffi, lib

        body = pymunk.Body(2.0, 3.0)
        body.center_of_gravity = (0.125, -0.375)
        body.angle = 0.7
        body.position = (1.5, -2.25)
        body.velocity = (3.5, -4.75)
        body.angular_velocity = 1.25
        cx, cy, px, py, vx, vy, a, w, ta, tb, tc, td, tx, ty = step.body_fields(
            int(ffi.cast("uintptr_t", body._body))
        )
        rot = lib.cpBodyGetRotation(body._body)
        pos = body.position
        return (
            (cx, cy) == (0.125, -0.375)
            and (vx, vy) == (3.5, -4.75)
            and (a, w) == (0.7, 1.25)
            and (ta, tb) == (rot.x, rot.y)
            and (tc, td) == (-rot.y, rot.x)
            and (ta * 0.0 + tc * 0.0 + tx, tb * 0.0 + td * 0.0 + ty) == (pos.x, pos.y)
            and tx == px - (cx * ta - cy * tb)
            and ty == py - (cx * tb + cy * ta)
        )
    except Exception:  # another pymunk layout: every access a call
        return False
