"""The rule for an output *file* a command is given (``plot -o``, ``graph -o``, ``adapt -o``).

The same as for an output directory (:mod:`amsa_phys.runs.rundir`): nothing already written is
lost unless the user says so. An existing file is refused without ``--force``, except one this
tool drew, which a redraw may replace (``ours``: ``plot -o``/``graph -o`` give
:func:`drawn_by_us`, so regenerating a figure needs no flag); a symbolic link is refused
without ``--force`` and, with it, replaced rather than followed (the writer renames over the
link); and an output that is one of the command's own inputs is refused even with
``--force``: writing it would destroy what the command reads.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Callable, Iterable
from pathlib import Path

from ..errors import ConfigError
from .rundir import check_output

#: How much of an SVG or DOT file is read to see who wrote it (the mark is in its head)
_HEAD = 4096


def check_output_file(
    out: Path,
    flag: str,
    force: bool | None,
    inputs: Iterable[Path] = (),
    ours: Callable[[Path], bool] | None = None,
    make_parent: bool = False,
) -> Path:
    """``out`` checked as an output file before any work (one line naming ``flag`` if not).

    ``force`` None: the command has no ``--force`` (``test --junit``), so a file that is
    not ``ours`` is never replaced and the message does not offer the flag.
    """
    out = check_output(Path(out), flag, make_parent)
    refuse_input_file(out, inputs, flag)
    _refuse_special(out, flag)
    if force:
        return out
    how = "use --force to replace it" if force is not None else "remove it or choose another file"
    if out.is_symlink():
        link = "use --force to replace the link" if force is not None else how
        raise ConfigError(
            f"is a symbolic link ({link}; its target is not touched)", key=flag, file=out
        )
    if out.exists() and not (ours is not None and ours(out)):
        why = "exists and was not written by amsa-phys" if ours is not None else "exists"
        raise ConfigError(f"{why} ({how})", key=flag, file=out)
    return out


def _refuse_special(out: Path, flag: str) -> None:
    """Refuse, even with ``--force``, an ``out`` that is a device, a FIFO or a socket.

    ``--force`` replaces a file written earlier; the writer renames over whatever has the
    name, so ``adapt -o /dev/null --force`` run as root replaced the machine's ``/dev/null``
    by a rules file. A link is not judged here: it is replaced, never followed."""
    try:
        mode = os.lstat(out).st_mode
    except OSError:
        return
    if stat.S_ISLNK(mode) or stat.S_ISREG(mode):
        return
    kind = "a FIFO" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode) else "a device"
    raise ConfigError(
        f"is {kind}, not a file; amsa-phys writes only files (choose a file name)",
        key=flag,
        file=out,
    )


def refuse_input_file(out: Path, inputs: Iterable[Path], flag: str) -> None:
    """Refuse ``out`` if it names one of ``inputs`` (through any link to its directory)."""
    target = _named(out)
    for given in inputs:
        given = Path(given)
        if target in {_named(given), given.resolve()}:
            raise ConfigError(
                f"is an input of this command ({given}); choose another file", key=flag, file=out
            )


def _named(path: Path) -> Path:
    """The file ``path`` names: its directory resolved, its last component kept (a link there
    is replaced by the writer, not followed, so it is not the file it points to)."""
    return Path(os.path.realpath(path.parent)) / path.name


def drawn_by_us(path: Path) -> bool:
    """Whether ``path`` is a regular file amsa-phys drew: a PNG or SVG Matplotlib wrote (as
    every picture of amsa-phys is: the PNG's ``Software`` text, the SVG's creator), a DOT
    graph ``graph`` wrote (its comment). Read bounded, without blocking.

    The pictures carry no mark of amsa-phys's own: the shipped figures are checked byte for
    byte against their recipes, and a mark would change every one of them.
    """
    from ..plots.graphmodel import DOT_MARK
    from ..plots.save import png_text

    suffix = path.suffix.lower()
    if suffix == ".png":
        return png_text(path).get("Software", "").startswith("Matplotlib version")
    head = _head(path)
    if suffix == ".svg":
        return b"<dc:creator>" in head and b"Matplotlib v" in head
    if suffix == ".dot":
        return f'comment="{DOT_MARK}"'.encode() in head
    return False


def junit_by_us(path: Path) -> bool:
    """Whether ``path`` is a JUnit report ``test --junit`` wrote (its root element's name):
    CI runs regenerate one each time, where any other file there is someone's."""
    from .junit import SUITE_NAME

    return f'<testsuites name="{SUITE_NAME}"'.encode() in _head(path)


def _head(path: Path) -> bytes:
    """The first bytes of ``path`` if it is a regular file (b"" if not, or unreadable)."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError:
        return b""
    try:
        return os.read(fd, _HEAD) if stat.S_ISREG(os.fstat(fd).st_mode) else b""
    except OSError:
        return b""
    finally:
        os.close(fd)
