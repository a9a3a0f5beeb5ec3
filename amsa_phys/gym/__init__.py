"""Gymnasium environments (extra ``amsa-phys[gym]``), registered as ``amsa_phys/...``.

``import amsa_phys`` registers them already (``amsa_phys/gymreg.py``: at once if Gymnasium is
imported, else when it is), so ``gymnasium.make("amsa_phys/Follow-v0")`` needs no other
import; Gymnasium 1.x has no entry-point plugin group any more. Importing this module
registers them too, and ``gymnasium.make("amsa_phys.gym:amsa_phys/Follow-v0")`` imports it.
"""

from __future__ import annotations

try:
    import greenlet  # noqa: F401  the episode's coroutine (gym/episode.py)
    import gymnasium
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError(
        f"amsa_phys.gym needs gymnasium and greenlet ({exc}); install them with: "
        "pip install 'amsa-phys[gym]'"
    ) from None

from ..gymreg import ENVIRONMENTS, register
from .follow import FollowEnv
from .vector import FollowVecEnv

register(gymnasium)

__all__ = ["ENVIRONMENTS", "FollowEnv", "FollowVecEnv"]
