"""Gymnasium environments (extra ``amsa-phys[gym]``), registered as ``amsa_phys/...``.

``import amsa_phys.gym`` registers them; ``gymnasium.make("amsa_phys.gym:amsa_phys/Follow-v0",
scenario=...)`` imports this module itself (Gymnasium 1.x has no entry-point plugin
mechanism any more: the ``module:`` prefix of the id is how a package's environments are
found without an explicit import).
"""

from __future__ import annotations

try:
    import gymnasium
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError(
        f"amsa_phys.gym needs gymnasium ({exc}); install it with: pip install 'amsa-phys[gym]'"
    ) from None

from .follow import FollowEnv

#: The environments this package registers (id -> entry point).
ENVIRONMENTS = {"amsa_phys/Follow-v0": "amsa_phys.gym.follow:FollowEnv"}

for _id, _entry in ENVIRONMENTS.items():
    if _id not in gymnasium.registry:
        gymnasium.register(id=_id, entry_point=_entry, nondeterministic=False)

__all__ = ["ENVIRONMENTS", "FollowEnv"]
