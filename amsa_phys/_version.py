"""The package's version, in a root module of its own.

Modules that record or print it (provenance, generated files, ``--version``) import it from
here: importing it from the package root pointed an arrow back up to ``amsa_phys/__init__.py``
from inside the layers. ``pyproject.toml`` states the same number (a test compares them).
"""

__version__ = "0.1.0"
