"""A progress bar on a terminal, and nothing (not even tqdm's import) anywhere else.

tqdm costs ~12-18 ms of imports, paid by every ``sweep`` and ``falsify`` even in a script or
CI log where the bar is disabled anyway (it is drawn only when stderr is a terminal).
"""

from __future__ import annotations

import sys
from typing import Any


class _Silent:
    """What a disabled bar does: count, and say lines as plain stderr lines."""

    def __init__(self, total: int) -> None:
        self.total = total
        self.n = 0

    def __enter__(self) -> _Silent:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def update(self, n: int = 1) -> None:
        """Count ``n`` more done."""
        self.n += n

    @staticmethod
    def write(text: str, file: Any = None) -> None:
        """Print a line (tqdm's ``write`` prints it above the bar)."""
        print(text, file=file if file is not None else sys.stderr)


def bar(total: int, unit: str) -> Any:
    """A tqdm bar of ``total`` ``unit`` on a terminal (stderr), else a silent counter.

    Both are context managers with ``update(n)``; ``type(bar).write(text, file=...)`` prints
    a line above the bar (or just prints it).
    """
    if not sys.stderr.isatty():
        return _Silent(total)
    from tqdm import tqdm

    return tqdm(total=total, unit=unit)
