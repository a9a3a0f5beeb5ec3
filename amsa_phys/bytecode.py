"""The package's own bytecode, written once where Python was told not to write it.

With ``PYTHONDONTWRITEBYTECODE=1`` (set on many CI images and containers) Python reads
``.pyc`` files but never writes them. A wheel's install byte-compiles the package, so that
costs nothing there; an editable install (``pip install -e``) has no such step, and every
``amsa-phys`` process then compiles each module it imports from source: about a third of a
headless run's CPU time (``docs/performance.md``, "Start-up and bytecode").

So at the end of a command, :func:`warm` writes the ``.pyc`` of the package's modules that
this process imported and that have none (or a stale one), exactly where Python looks for
them (``importlib.util.cache_from_source``: ``__pycache__`` beside the source, or under
``sys.pycache_prefix``), with the same header and atomic write as ``python -m compileall``.
The next process reads them. It does so only when all of these hold:

* the interpreter does not write bytecode itself (``sys.dont_write_bytecode``), else it
  already did;
* ``AMSA_PHYS_NO_PYC`` is unset or empty (the opt-out);
* the package's directory belongs to the user running the command and the cache directory
  can be written (a shared or system install is never written to).

It writes nothing but bytecode of the package's own source, never raises, and costs what
compiling the modules imported costs, once; a process that finds them all fresh reads one
header per module (~1 ms in all).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

#: set (non-empty) to never write the package's bytecode
OPT_OUT = "AMSA_PHYS_NO_PYC"

PACKAGE = Path(__file__).resolve().parent


def wanted() -> bool:
    """Whether this process should write the package's bytecode (the module docstring)."""
    if not sys.dont_write_bytecode or os.environ.get(OPT_OUT):
        return False
    try:
        return PACKAGE.stat().st_uid == os.getuid()
    except (OSError, AttributeError):  # no getuid (Windows): leave it to Python
        return False


def stale_modules() -> list[tuple[str, str]]:
    """(source, cache) of every imported module of the package whose ``.pyc`` is missing or
    does not match its source (the mtime and size its header records, as Python checks)."""
    import importlib.util

    root = str(PACKAGE) + os.sep
    out = []
    for module in list(sys.modules.values()):
        source = getattr(module, "__file__", None)
        if not source or not source.endswith(".py") or not source.startswith(root):
            continue
        cache = importlib.util.cache_from_source(source)
        if not _fresh(source, cache):
            out.append((source, cache))
    return out


def _fresh(source: str, cache: str) -> bool:
    """Whether ``cache`` is the timestamp-checked bytecode of ``source`` as it is now."""
    try:
        st = os.stat(source)
        with open(cache, "rb") as f:
            header = f.read(16)
    except OSError:
        return False
    if len(header) < 16 or int.from_bytes(header[4:8], "little") != 0:
        return False  # not a timestamp-checked .pyc: leave it be, written by someone else
    mtime = int.from_bytes(header[8:12], "little")
    size = int.from_bytes(header[12:16], "little")
    return mtime == int(st.st_mtime) & 0xFFFFFFFF and size == st.st_size & 0xFFFFFFFF


def warm() -> int:
    """Write the missing or stale ``.pyc`` of the imported modules if :func:`wanted`;
    return how many were written. Never raises: a cache that cannot be written is only a
    slower start."""
    try:
        if not wanted():
            return 0
        import py_compile

        written = 0
        for source, cache in stale_modules():
            if not _writable(Path(cache).parent):
                continue
            try:
                py_compile.compile(source, cfile=cache, doraise=True)
                written += 1
            except (OSError, py_compile.PyCompileError):
                continue
        return written
    except Exception:  # a warm-up must never turn a command into a failure
        return 0


def _writable(directory: Path) -> bool:
    """Whether ``directory`` (or, when missing, its nearest existing parent) can be
    written by this user."""
    for d in (directory, *directory.parents):
        if d.exists():
            return os.access(d, os.W_OK)
    return False
