"""Every file amsa-phys writes goes through here: a temporary name, checked writes, a rename.

Why one module: a full disk, a read-only file system, a directory where the file should go
or a symbolic link planted at the temporary name must end the same way for the trace, the
metrics, the resolved scenario, the plots, the snapshot, ``results.csv``, ``summary.png``,
JUnit XML and the architecture graph: one line naming the file
(:class:`~amsa_phys.errors.OutputError`, exit 3), never a truncated file under its final
name, never a write through somebody else's link.

* The temporary name is ``NAME.tmp`` beside the target, so a killed process leaves only
  ``*.tmp`` files and the rename stays on one file system. It is opened with
  ``O_CREAT | O_EXCL | O_NOFOLLOW``: whatever already has that name (a leftover of a killed
  run, a planted symlink) is unlinked first -- unlinking a link never touches its target --
  and the exclusive open fails rather than follow a link planted in between.
* Every write is checked (Python's buffered writer raises on a short write); data is
  flushed and fsync'ed before the rename, so a crash after the rename cannot leave an empty
  file under the final name either.
* On failure the temporary file is removed at once: on a full disk that frees the space the
  next file needs (``metrics.json`` after a trace that filled the disk).
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
from pathlib import Path
from typing import IO

from .errors import OutputError

_FLAGS = (
    os.O_WRONLY
    | os.O_CREAT
    | os.O_EXCL
    | getattr(os, "O_NOFOLLOW", 0)
    | getattr(os, "O_CLOEXEC", 0)
    | getattr(os, "O_BINARY", 0)
)


def temp_path(path: Path) -> Path:
    """The temporary name of ``path`` while it is written: ``NAME.tmp`` beside it."""
    return path.with_name(path.name + ".tmp")


def reason(exc: OSError) -> str:
    """What an OSError means for a file, in words (``No space left on device``)."""
    if exc.errno == errno.EISDIR:
        return "is a directory"
    return exc.strerror or type(exc).__name__


def open_exclusive(tmp: Path) -> int:
    """Create ``tmp`` for writing without following a link; return its descriptor.

    A file or link already at ``tmp`` is removed first (a directory is refused).
    """
    try:
        st = os.lstat(tmp)
    except FileNotFoundError:
        pass
    else:
        if stat.S_ISDIR(st.st_mode):
            raise IsADirectoryError(errno.EISDIR, "is a directory", str(tmp))
        os.unlink(tmp)
    return os.open(tmp, _FLAGS, 0o666)


class AtomicFile:
    """A file being written under its temporary name: :meth:`write`, then :meth:`commit`.

    Any failure raises :class:`OutputError` naming the final file, after removing the
    temporary one; later calls are then no-ops (:attr:`failed`).
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.tmp = temp_path(self.path)
        self.failed = False
        self._fh: IO[bytes] | None = None
        try:
            self._fh = os.fdopen(open_exclusive(self.tmp), "wb")
        except OSError as exc:
            self.failed = True
            raise OutputError(self.path, reason(exc)) from None

    def write(self, data: bytes) -> None:
        """Append ``data``; a failed write removes the temporary file and raises."""
        if self._fh is None:
            return
        try:
            self._fh.write(data)
        except OSError as exc:
            self.discard()
            raise OutputError(self.path, reason(exc)) from None

    def commit(self) -> Path:
        """Flush, fsync, close and rename to the final name."""
        fh = self._fh
        if fh is None:
            return self.path
        try:
            fh.flush()
            os.fsync(fh.fileno())
            fh.close()
            self._fh = None
            os.replace(self.tmp, self.path)
        except OSError as exc:
            self.discard()
            raise OutputError(self.path, reason(exc)) from None
        return self.path

    def discard(self) -> None:
        """Give up: close and remove the temporary file (never raises)."""
        self.failed = True
        fh, self._fh = self._fh, None
        if fh is not None:
            with contextlib.suppress(OSError):
                fh.close()
        with contextlib.suppress(OSError):
            os.unlink(self.tmp)


def write_atomic(path: str | Path, data: str | bytes) -> Path:
    """Write a whole file (text as UTF-8) under its temporary name, then rename it."""
    # encoded before the temporary file exists: text that cannot be encoded (a surrogate
    # from a file name that is not UTF-8) must not leave a ``NAME.tmp`` behind
    raw = data.encode("utf-8") if isinstance(data, str) else data
    out = AtomicFile(path)
    out.write(raw)
    return out.commit()
