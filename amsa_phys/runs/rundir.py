"""Choosing and preparing a run's output directory, safely.

Three rules keep a run from ever destroying a user's files:

* a scenario's ``name`` reaches the file system only through :func:`safe_name`, which makes
  it one harmless path component (``..``, ``/etc`` or a control character can never
  name a directory outside the output root);
* every directory amsa-phys creates for its outputs holds a marker file (:data:`MARKER`);
  ``--force`` replaces only such a directory, never one the user made or filled, and only
  one of the same kind: a run's ``--force`` never wipes a sweep's or a search's results
  (hours of work), the marker says which command made the directory;
* a directory that holds the run's own inputs (the scenario or its world), or the current
  directory or one of its parents, is refused outright, with or without ``--force``.

An existing directory is never overwritten without ``force``; an unwritable location is
reported before the run starts, not after minutes of simulation.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import secrets
import shutil
import tempfile
import time
from collections.abc import Iterable, Iterator
from pathlib import Path

from ..errors import AmsaError, ConfigError

#: The file that says "amsa-phys made this directory": ``--force`` replaces nothing else.
MARKER = ".amsa-phys-run"
#: Longest name a scenario contributes to a directory name (file systems allow 255 bytes).
MAX_NAME = 80
_UNSAFE = re.compile(r"[^A-Za-z0-9_.+=-]")


def safe_name(name: str) -> str:
    """``name`` as one safe path component: no separator, no ``.``/``..``, no control chars.

    Characters outside ``[A-Za-z0-9_.+=-]`` become ``_`` and leading dots become ``_``
    (so ``..`` is ``__`` and ``/some/dir`` is ``_some_dir``); an empty name is ``scenario``.
    """
    text = _UNSAFE.sub("_", name)[:MAX_NAME]
    stripped = text.lstrip(".")
    text = "_" * (len(text) - len(stripped)) + stripped
    return text or "scenario"


def default_run_dir(scenario_name: str, root: Path = Path("runs")) -> Path:
    """``runs/<scenario>-<YYYYmmdd-HHMMSS>`` (a suffix is added if it exists already)."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    base = root / f"{safe_name(scenario_name)}-{stamp}"
    out = base
    n = 1
    while out.exists() or out.is_symlink():
        n += 1
        out = base.with_name(f"{base.name}-{n}")
    return out


def unique_names(names: Iterable[str]) -> list[str]:
    """Safe, distinct directory names for ``names`` in order (``a``, ``a-2``, ``a-3``...).

    Two scenarios with the same ``name`` in one ``test --out`` must not share (or delete)
    each other's directory; the comparison ignores case, for case-insensitive file systems.
    """
    taken: set[str] = set()
    out: list[str] = []
    for raw in names:
        base = safe_name(raw)
        name, n = base, 1
        while name.lower() in taken:
            n += 1
            name = f"{base}-{n}"
        taken.add(name.lower())
        out.append(name)
    return out


def is_ours(path: Path) -> bool:
    """True if amsa-phys created ``path`` as an output directory (it holds the marker)."""
    return (path / MARKER).is_file() and not (path / MARKER).is_symlink()


#: What made an output directory, as its marker says (``kind: sweep``); a run's by default.
KINDS = {
    "run": "a run's",
    "sweep": "a sweep's",
    "falsify": "a falsification search's",
    "export": "an exported package's",
}
_KIND_LINE = re.compile(r"^kind: ([a-z]+)$", re.M)


def kind_of(path: Path) -> str | None:
    """The kind of output directory ``path`` is (its marker's ``kind:``), None if unsaid.

    Markers written before kinds existed say none: such a directory may be replaced by any
    command's ``--force``, as before. Only the marker's first 200 bytes are read.
    """
    try:
        with open(path / MARKER, encoding="utf-8", errors="replace") as f:
            head = f.read(200)
    except OSError:
        return None
    found = _KIND_LINE.search(head)
    return found.group(1) if found and found.group(1) in KINDS else None


def _inside(child: Path, parent: Path) -> bool:
    return child == parent or parent in child.parents


def _refuse_inputs(out: Path, inputs: Iterable[Path], flag: str) -> None:
    """Refuse a non-empty output directory that holds an input, the working directory or a
    parent of it: replacing it (or mixing outputs into it) would destroy what the user has."""
    real = out.resolve()
    cwd = Path.cwd().resolve()
    if _inside(cwd, real):
        what = "the current directory" if real == cwd else "a parent of the current directory"
        raise ConfigError(f"is {what}; choose a new directory for the outputs", key=flag, file=out)
    for given in inputs:
        source = Path(given).resolve()
        if _inside(source, real):
            raise ConfigError(
                f"holds the input {given}; choose a directory that does not contain it",
                key=flag,
                file=out,
            )


def _without_dotdot(out: Path) -> Path:
    """``out`` with its ``..`` resolved, so it is judged as the directory it really names.

    ``new/..`` is the directory holding ``new``: checked as written, it does not exist (``new``
    does not), and creating it would make ``new`` and then run into its parent -- the
    current directory, full of the user's files. The last component itself is kept as
    written (a symbolic link there must still be seen as one).
    """
    if ".." not in out.parts:
        return out
    if out.name == "..":
        return Path(os.path.realpath(out))
    return Path(os.path.realpath(out.parent)) / out.name


def check_output_dir(
    out: Path, force: bool, inputs: Iterable[Path] = (), flag: str = "--out", kind: str = "run"
) -> bool:
    """The refusals of :func:`prepare_run_dir`, touching nothing.

    Returns True if ``out`` exists and is not empty (and may be replaced: ``force`` was
    given, amsa-phys made it for outputs of the same ``kind`` and it holds none of
    ``inputs``).
    """
    inputs = list(inputs)
    out = _without_dotdot(out)
    if out.is_symlink():  # to a directory or dangling: never written through
        raise ConfigError(
            "is a symbolic link; give the real directory (amsa-phys does not replace links)",
            key=flag,
            file=out,
        )
    if not out.exists():
        return False
    if not out.is_dir():
        raise ConfigError("exists and is not a directory", key=flag, file=out)
    if not any(out.iterdir()):
        return False
    _refuse_inputs(out, inputs, flag)
    if not force and is_ours(out):
        raise ConfigError(
            "directory exists and is not empty (use --force to replace it)",
            key=flag,
            file=out,
        )
    if not is_ours(out):  # --force would not help: say so at once, not after a retry
        raise ConfigError(
            f"directory exists and was not made by amsa-phys (no {MARKER} in it); "
            "--force replaces only run directories: choose a new one",
            key=flag,
            file=out,
        )
    made = kind_of(out)
    if made is not None and made != kind:
        raise ConfigError(
            f"holds {KINDS[made]} outputs (amsa-phys {made}); --force replaces only "
            f"{KINDS[kind]}: choose a new directory, or remove this one yourself",
            key=flag,
            file=out,
        )
    return True


def prepare_run_dir(
    out: Path, force: bool, inputs: Iterable[Path] = (), flag: str = "--out", kind: str = "run"
) -> Path:
    """Create ``out`` for a run's (or a ``kind`` of command's) outputs and mark it as ours.

    A non-empty ``out`` is refused unless ``force``, and even then only replaced if amsa-phys
    made it (:func:`is_ours`) for the same kind of outputs and it holds none of ``inputs``.
    Symbolic links are never followed into a removal.
    """
    inputs = list(inputs)
    out = _without_dotdot(out)
    if check_output_dir(out, force, inputs, flag, kind):
        shutil.rmtree(out)
    _make_marked(out, flag, kind)
    return out


@contextlib.contextmanager
def run_dir_for(
    out: Path, force: bool, inputs: Iterable[Path] = (), flag: str = "--out", kind: str = "run"
) -> Iterator[Path]:
    """The directory to write ``out``'s outputs into, checked as :func:`prepare_run_dir`
    checks ``out``.

    Where ``force`` replaces an earlier run, the new one is written into a staged directory
    beside it and put in its place in one rename when the run ends (completed, faulted or
    interrupted: its outputs are the run's), so the earlier run stays whole until then, and
    stays if the process dies or fails outside the run. Otherwise ``out`` itself.
    """
    out = _without_dotdot(out)
    if not check_output_dir(out, force, inputs, flag, kind):
        yield prepare_run_dir(out, force, inputs, flag, kind)
        return
    staged = staged_dir(out, force, inputs, flag, kind)
    try:
        yield staged
    except (AmsaError, KeyboardInterrupt):
        commit_staged(staged, out, flag)  # a fault's or an interruption's outputs: the run's own
        raise
    except BaseException:
        discard_staged(staged)
        raise
    commit_staged(staged, out, flag)


def _make_marked(out: Path, flag: str, kind: str) -> None:
    try:
        out.mkdir(parents=True, exist_ok=True)
        (out / MARKER).write_text(
            f"amsa-phys output directory; --force may replace it\nkind: {kind}\n"
        )
    except OSError as exc:
        raise ConfigError(f"cannot create directory: {exc.strerror}", key=flag, file=out) from None
    if not os.access(out, os.W_OK):
        raise ConfigError("directory is not writable", key=flag, file=out)


def unwritable(directory: Path) -> str | None:
    """Why no file can be made in ``directory`` (None if one can): a probe file is made and
    removed at once. Why a probe: ``os.access`` answers for permissions only, and yes for
    root everywhere, where a file system that takes no new files (``/proc``, a read-only
    mount) refuses only the write itself, then half-way through a run."""
    try:
        fd, probe = tempfile.mkstemp(dir=directory, prefix=".amsa-phys-probe-")
    except OSError as exc:
        return exc.strerror or str(exc)
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(probe)
    return None


def prepare_out_root(root: Path, flag: str = "--out") -> Path:
    """A folder the command makes its output directories in (``test --out DIR`` puts each
    scenario's under it), created and checked before any work.

    Each directory under it is still judged by :func:`prepare_run_dir`; but a root that is
    a file, cannot be created or takes no new file fails every one of them, so it is one
    line (exit 2) up front, not one error per scenario after the suite has started.
    """
    root = _without_dotdot(Path(root))
    if root.exists() and not root.is_dir():
        raise ConfigError("exists and is not a directory", key=flag, file=root)
    try:
        root.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"cannot create directory: {exc.strerror}", key=flag, file=root) from None
    if unwritable(root) is not None:
        raise ConfigError("directory is not writable", key=flag, file=root)
    return root


def check_output(path: Path, flag: str, make_parent: bool = False) -> Path:
    """An output file's path, checked before any work (exit 2 naming ``flag``).

    Refused: a directory (or a link to one) where the file should go, a directory that does
    not exist (created with ``make_parent``), one that is not writable (a read-only file
    system). A write that still fails later (a full disk) is an OutputError naming the file.
    """
    path = Path(path)
    if path.is_dir():
        raise ConfigError("is a directory; give a file name", key=flag, file=path)
    parent = path.parent
    if make_parent and not parent.exists():
        try:
            parent.mkdir(parents=True)
        except OSError as exc:
            raise ConfigError(
                f"cannot create directory: {exc.strerror}", key=flag, file=parent
            ) from None
    if not parent.is_dir():
        why = "is not a directory" if parent.exists() else "directory does not exist"
        raise ConfigError(why, key=flag, file=parent)
    if not os.access(parent, os.W_OK) or (why := unwritable(parent)) is not None:
        raise ConfigError("directory is not writable", key=flag, file=parent)
    return path


def staged_dir(
    out: Path, force: bool, inputs: Iterable[Path] = (), flag: str = "-o", kind: str = "export"
) -> Path:
    """A new, marked, empty directory beside ``out`` to write a whole output tree into.

    ``out`` is checked as :func:`prepare_run_dir` checks it (nothing is touched); the caller
    fills the returned directory, then :func:`commit_staged` puts it in place in one rename,
    so a failure half-way leaves ``out`` as it was (and :func:`discard_staged` cleans up).
    The directory is made afresh under a name nothing held (:func:`_fresh_beside`): a link or
    a directory someone left at a name we would choose is never written through.
    """
    out = _without_dotdot(out)
    check_output_dir(out, force, inputs, flag, kind)
    try:  # ``-o a/b/pkg``: a and b made as for any output directory
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"cannot create directory: {exc.strerror}", key=flag, file=out) from None
    staged = _fresh_beside(out, "amsa-tmp", flag)
    _make_marked(staged, flag, kind)
    return staged


def _fresh_beside(out: Path, tag: str, flag: str) -> Path:
    """A new empty directory ``.NAME.TAG-PID-XXXXXXXX`` beside ``out``, made by ``mkdir``
    itself (which fails on anything already there, a link included, and follows none)."""
    for _ in range(100):
        path = out.parent / f".{out.name}.{tag}-{os.getpid()}-{secrets.token_hex(4)}"
        try:
            os.mkdir(path)
        except FileExistsError:
            continue
        except OSError as exc:
            raise ConfigError(
                f"cannot create a directory beside it: {exc.strerror}", key=flag, file=out
            ) from None
        return path
    raise ConfigError("cannot create a directory beside it: every name taken", key=flag, file=out)


def commit_staged(staged: Path, out: Path, flag: str = "--out") -> None:
    """Replace ``out`` (checked by :func:`staged_dir`: absent, empty or ours) by ``staged``.

    The earlier ``out`` is first renamed onto a fresh empty directory beside it, then
    removed. Another command that put its own ``out`` in place meanwhile wins: this one says
    so in one line and where its outputs are kept (nothing is removed)."""
    old: Path | None = None
    if out.exists() or out.is_symlink():
        old = _fresh_beside(out, "amsa-old", flag)
        try:
            os.replace(out, old)  # onto the empty directory just made
        except FileNotFoundError:  # moved away meanwhile by another command
            old.rmdir()
            old = None
        except OSError as exc:
            old.rmdir()
            raise ConfigError(f"cannot replace it: {exc.strerror}", key=flag, file=out) from None
    try:
        os.replace(staged, out)
    except OSError as exc:
        if exc.errno in (errno.EEXIST, errno.ENOTEMPTY, errno.ENOTDIR, errno.EISDIR):
            if old is not None and not out.exists():
                os.replace(old, out)
            raise ConfigError(
                f"was replaced by another command while this one wrote; its outputs are in "
                f"{staged}",
                key=flag,
                file=out,
            ) from None
        raise ConfigError(f"cannot write: {exc.strerror}", key=flag, file=out) from None
    if old is not None:
        if is_ours(old):
            shutil.rmtree(old)
        else:
            old.rmdir()  # an empty directory the user made


def discard_staged(staged: Path) -> None:
    """Remove a staged directory after a failure (only if it is ours)."""
    if staged.is_dir() and not staged.is_symlink() and is_ours(staged):
        shutil.rmtree(staged)
