"""A falsification's JSON records read back as data: ``falsify.json`` and ``trial.json``.

A falsification's directory may come from anywhere (a colleague, a CI artefact, an
interrupted search someone edited), and ``--resume`` and ``plot`` read it. So a record is
read only if it is a regular file of at most :data:`MAX_RECORD_BYTES` (the project's one
check, :func:`~amsa_phys.model.yamlio.read_regular_file`: a FIFO never blocks, ``/dev/zero``
is never read), and a file that is not JSON, or nests too deeply for the parser, is one line
naming the file (exit 2) rather than a traceback. Kept apart from ``trials.py`` and the
search so ``plot`` reads a record without importing the search.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..model.yamlio import MAX_FILE_BYTES, parse_json, read_regular_file

#: the largest record read: a user's file's limit (amsa-phys writes a few hundred bytes, a
#: few hundred kilobytes for a search with long ``--grid`` lists)
MAX_RECORD_BYTES = MAX_FILE_BYTES


def read_record(path: Path, expected: str) -> dict[str, Any]:
    """The JSON object in ``path`` (one line naming the file if it is not one)."""
    raw = read_regular_file(Path(path), MAX_RECORD_BYTES, expected, follow=False)
    doc = parse_json(raw, path)
    if not isinstance(doc, dict):
        raise ConfigError(f"not {expected}: expected a JSON object, got {_kind(doc)}", file=path)
    return doc


def _kind(value: Any) -> str:
    """A JSON value's kind in JSON's words (``array``, not ``list``)."""
    names = {list: "array", str: "string", bool: "true or false", type(None): "null"}
    return names.get(type(value), "number")
