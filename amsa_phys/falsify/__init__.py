"""Falsification: search a box of context parameters for the worst case.

``space`` (the box), ``objective`` (a metric, or the robustness of ``expect``), ``search``
(Latin hypercube then CMA-ES, each generation one batch through ``runs.evaluate``) and
``outputs`` (results.csv, worst.yaml); ``cli/falsify.py`` drives them.
"""

import importlib
import sys
import types
from typing import Any


class _CallableModule(types.ModuleType):
    """This package, callable as :func:`amsa_phys.api.falsify.falsify`.

    WHY: ``ap.falsify(...)`` is the public function, but importing this package binds the
    name ``falsify`` of ``amsa_phys`` to it (Python sets a subpackage as its parent's
    attribute), which would hide the lazily imported function. Calling the package calls the
    function, so ``ap.falsify(...)`` works whichever was bound first. The API module is
    found by name when called: it sits above this layer.
    """

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        api = importlib.import_module("amsa_phys.api.falsify")
        return api.falsify(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
