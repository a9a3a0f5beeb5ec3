"""amsa-phys: a physics-backed 2D rover testbed implementing the AMSA component framework.

Public API (README, "From Python"): :func:`run`, :func:`load`, :func:`validate`, the
:class:`Run` they return, the errors (:class:`AmsaError`, :class:`ConfigError`,
:class:`RunFault`, :class:`Interrupted`), and what a user template needs (:class:`Template`,
:class:`Port`, :class:`Param`, :class:`Kind`).

Every name is imported on first use (a module ``__getattr__``, PEP 562): ``import amsa_phys``
— which every ``amsa-phys`` command does — must not pay for numpy, pymunk, matplotlib,
jsonschema or tqdm (a test holds it to that).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from ._version import __version__

#: public name -> module that defines it (relative to this package)
_LAZY = {
    "run": ".api.result",
    "Run": ".api.result",
    "TraceSizeWarning": ".api.memory",
    "OverrideWarning": ".runs.overrides",
    "ReferenceWarning": ".runs.references",
    "SearchWarning": ".api.falsify",
    "load": ".api.source",
    "falsify": ".api.falsify",
    "validate": ".api.source",
    "AmsaError": ".errors",
    "ConfigError": ".errors",
    "RunFault": ".errors",
    "Interrupted": ".errors",
    "ExpectationFailed": ".errors",
    "Template": ".model.template",
    "Port": ".model.template",
    "Kind": ".model.template",
    "Param": ".model.params",
    "load_scenario": ".model.scenario",
    "load_world": ".model.world",
    "run_scenario": ".runs.single",
}

__all__ = [  # noqa: RUF022  grouped as the README lists them
    "__version__",
    "run",
    "Run",
    "TraceSizeWarning",
    "OverrideWarning",
    "ReferenceWarning",
    "SearchWarning",
    "load",
    "validate",
    "falsify",
    "AmsaError",
    "ConfigError",
    "RunFault",
    "Interrupted",
    "ExpectationFailed",
    "Template",
    "Port",
    "Kind",
    "Param",
    "load_scenario",
    "load_world",
    "run_scenario",
]

if TYPE_CHECKING:  # for type checkers and editors: the same names, imported eagerly
    from .api.falsify import SearchWarning, falsify
    from .api.memory import TraceSizeWarning
    from .api.result import Run, run
    from .api.source import load, validate
    from .errors import AmsaError, ConfigError, ExpectationFailed, Interrupted, RunFault
    from .model.params import Param
    from .model.scenario import load_scenario
    from .model.template import Kind, Port, Template
    from .model.world import load_world
    from .runs.overrides import OverrideWarning
    from .runs.references import ReferenceWarning
    from .runs.single import run_scenario


from .gymreg import install as _install_gym  # noqa: E402  (light: no gymnasium, no numpy)

_install_gym()  # gymnasium.make("amsa_phys/Follow-v0") after import amsa_phys (gymreg.py)


def __getattr__(name: str) -> Any:
    """Import a public name on first use and keep it (later lookups are plain attributes)."""
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'amsa_phys' has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
