"""Register the Gymnasium environments when ``amsa_phys`` is imported, without importing
Gymnasium (nor numpy) for the many users who never touch it.

Gymnasium 1.x dropped its entry-point plugin group (``gymnasium.envs``): environments are
found only once something calls ``gymnasium.register``. So ``import amsa_phys`` registers
them right away when Gymnasium is already imported, and otherwise leaves a one-shot finder
on ``sys.meta_path`` that registers them the moment Gymnasium finishes importing. Either
order of ``import gymnasium`` / ``import amsa_phys`` then makes
``gymnasium.make("amsa_phys/Follow-v0")`` work; the environment's own module (and so
numpy, pymunk, the engine) is imported only by ``make``, through the entry point string.
"""

from __future__ import annotations

import importlib.machinery
import sys
from collections.abc import Sequence
from types import ModuleType
from typing import Any

#: The environments this package registers (id -> entry point).
ENVIRONMENTS = {"amsa_phys/Follow-v0": "amsa_phys.gym.follow:FollowEnv"}
#: Each one's own vector env (``make_vec(..., vectorization_mode="vector_entry_point")``)
VECTOR = {"amsa_phys/Follow-v0": "amsa_phys.gym.vector:FollowVecEnv"}


def register(gymnasium: ModuleType) -> None:
    """Register every environment not yet in Gymnasium's registry (safe to call twice)."""
    for env_id, entry in ENVIRONMENTS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(
                id=env_id,
                entry_point=entry,
                vector_entry_point=VECTOR.get(env_id),
                nondeterministic=False,
            )


class _Loader:
    """Gymnasium's own loader, then :func:`register` once the module has executed (not an
    ``importlib.abc`` subclass: that module imports tempfile and random, 6 ms on every
    ``import amsa_phys``)."""

    def __init__(self, inner: Any) -> None:
        self.inner = inner

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType | None:
        return self.inner.create_module(spec)  # type: ignore[no-any-return]

    def exec_module(self, module: ModuleType) -> None:
        self.inner.exec_module(module)
        register(module)


class _AfterGymnasium:
    """Finds nothing itself: wraps Gymnasium's spec so that its import ends registered."""

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        if fullname != "gymnasium":
            return None
        _remove_finder()
        spec = importlib.machinery.PathFinder.find_spec(fullname, path)
        if spec is not None and spec.loader is not None:
            spec.loader = _Loader(spec.loader)
        return spec


def _remove_finder() -> None:
    # no lock (threading is another import): both callers run under an import lock
    sys.meta_path[:] = [f for f in sys.meta_path if not isinstance(f, _AfterGymnasium)]


def install() -> None:
    """Register now if Gymnasium is imported, else when it is (called by ``import amsa_phys``)."""
    gymnasium = sys.modules.get("gymnasium")
    if gymnasium is not None and hasattr(gymnasium, "registry"):
        register(gymnasium)
        return
    if not any(isinstance(f, _AfterGymnasium) for f in sys.meta_path):
        sys.meta_path.insert(0, _AfterGymnasium())
