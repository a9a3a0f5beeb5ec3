"""What ``run_lockstep`` saw of its launch: roslaunch's output passed through as it comes,
with the lines that say why a run did not start noted on the way.

A launch that stops before its run starts (a C++ Leaf refusing a parameter, the simulator
refusing ``out:=``) prints the cause in one ``error: ...`` line, somewhere among roslaunch's
screens of its own. ``run_lockstep``'s last line used to say only that the run directory
was empty; it now names that line (:meth:`Seen.cause`), so the last line of a terminal or a
CI log is the reason. To see the output, the script reads roslaunch's stdout and stderr and
writes each chunk to its own stdout and stderr as soon as it is read, unchanged (colours,
partial lines, and the split between the two streams: ``2> file`` still separates them).

Each of the two reaches roslaunch as what it is here: a terminal of its own (``pty``) where
ours is a terminal, a pipe otherwise. A pipe alone would change what the nodes print: a
Python process or rosconsole writing to a pipe holds its standard output in a block buffer
(a user would see the nodes' lines only when they exit) and rospy colours its warnings only
on a terminal. So the nodes behave exactly as under ``roslaunch`` run by hand.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import pty
import re
import signal
import subprocess
import sys
import termios
import threading
from dataclasses import dataclass, field

from ...errors import one_line

#: What a terminal would show as colour or a window title, not text.
ESCAPE = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]|\x1b\][^\x07\x1b]*(?:\x07|\x1b\\)")
#: roslaunch's own words for the process whose end ended the launch.
DIED = re.compile(r"REQUIRED process \[(.+?)-\d+\] has died!")
ERROR = "error: "
#: How long the output may go on after roslaunch exited (a node it could not stop still
#: holding the pipe): what comes later is still passed through, but not waited for.
DRAIN_S = 5.0
#: A line longer than this (bytes) is noted in pieces.
LONGEST = 1 << 20


@dataclass
class Seen:
    """The lines of note in a launch's output, in the order they were read."""

    #: every ``error: `` line's text after that prefix (amsa-phys's nodes' one-line errors)
    errors: list[str] = field(default_factory=list)
    #: the processes roslaunch said died while required (each ends the launch)
    died: list[str] = field(default_factory=list)
    lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    def note(self, line: str) -> None:
        """Take one line of output (escapes and surrounding blanks removed here)."""
        text = ESCAPE.sub("", line).strip()
        with self.lock:
            if text.startswith(ERROR) and text[len(ERROR) :].strip():
                self.errors.append(one_line(text[len(ERROR) :].strip()))
            died = DIED.search(text)
            if died:
                self.died.append(died.group(1))

    def cause(self) -> str:
        """Where a user finds why the run did not start, as the end of a sentence: the
        first error line named, else the first required process roslaunch saw die, else
        roslaunch's output as a whole."""
        if len(self.errors) == 1:
            return f"see the error above ({self.errors[0]})"
        if self.errors:
            return f"see the {len(self.errors)} errors above (the first: {self.errors[0]})"
        if self.died:
            return f"roslaunch's required process {self.died[0]} died first (see its output above)"
        return "see roslaunch's output above"


def _pass_through(source: int, target: int, seen: Seen) -> None:
    """Copy the file descriptor ``source`` to ``target`` until its end, noting each whole
    line in ``seen``; close ``source``.

    A target that can no longer be written (``| head`` closed it) is given up, but the
    source is still read to its end: roslaunch and its nodes must never block on a full pipe.
    """
    pending = b""
    writing = True
    while chunk := _read(source):
        left = chunk
        while writing and left:
            try:
                left = left[os.write(target, left) :]
            except OSError:
                writing = False
        *lines, pending = (pending + chunk).split(b"\n")
        if len(pending) > LONGEST:  # no line ends: note what came, keep memory bounded
            lines, pending = [*lines, pending], b""
        for line in lines:
            seen.note(line.decode(errors="replace"))
    seen.note(pending.decode(errors="replace"))
    os.close(source)


def _read(fd: int) -> bytes:
    """The next bytes of a pipe or a terminal's master side; b"" at the end (a terminal's
    master reads EIO once every process closed its side)."""
    try:
        return os.read(fd, 65536)
    except OSError as exc:
        if exc.errno == errno.EIO:
            return b""
        raise


def _channel(ours: int) -> tuple[int, int]:
    """(the child's end, our end) for the child's output that goes to our ``ours``: a
    terminal of its own if ``ours`` is one, else a pipe."""
    if os.isatty(ours):
        ours_side, child_side = pty.openpty()
        # its bytes as they are: ours, a terminal, turns "\n" into "\r\n" itself
        attrs = termios.tcgetattr(child_side)
        attrs[1] &= ~termios.ONLCR
        termios.tcsetattr(child_side, termios.TCSANOW, attrs)
        with contextlib.suppress(OSError):  # and its size
            size = fcntl.ioctl(ours, termios.TIOCGWINSZ, bytes(8))
            fcntl.ioctl(child_side, termios.TIOCSWINSZ, size)
        return child_side, ours_side
    read_end, write_end = os.pipe()
    return write_end, read_end


def run(argv: list[str], env: dict[str, str]) -> tuple[int, Seen]:
    """Run ``argv`` (roslaunch) with its output passed through; its exit code, what was seen."""
    seen = Seen()
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    # SIGTERM to this script alone (a CI's timeout) would leave roslaunch writing into a
    # closed pipe: it is passed on as the Ctrl-C that stops a launch cleanly, and the verdict
    # follows (130 when the simulator says "interrupted"). Taken before roslaunch starts: its
    # first output can reach our stdout (and whoever reads it send the SIGTERM) before this
    # thread runs again; one that comes before roslaunch exists is passed on once it does.
    started: list[subprocess.Popen[bytes]] = []
    asked: list[bool] = []

    def on_sigterm(*_: object) -> None:
        if started:
            started[0].send_signal(signal.SIGINT)
        else:
            asked.append(True)

    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, on_sigterm)
    try:
        return _launch(argv, env, seen, started, asked)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _launch(
    argv: list[str],
    env: dict[str, str],
    seen: Seen,
    started: list[subprocess.Popen[bytes]],
    asked: list[bool],
) -> tuple[int, Seen]:
    """:func:`run`'s launch, its SIGTERM handler in place: roslaunch started into
    ``started``, a SIGTERM noted in ``asked`` meanwhile passed on as SIGINT."""
    targets = (sys.stdout.fileno(), sys.stderr.fileno())
    channels = [_channel(t) for t in targets]
    try:
        proc = subprocess.Popen(argv, stdout=channels[0][0], stderr=channels[1][0], env=env)
    except OSError:
        for fds in channels:
            for fd in fds:
                os.close(fd)
        raise
    started.append(proc)
    if asked:
        proc.send_signal(signal.SIGINT)
    for child_side, _ in channels:
        os.close(child_side)  # ours closed: the end of output is the child's
    readers = [
        threading.Thread(target=_pass_through, args=(source, target, seen), daemon=True)
        for (_, source), target in zip(channels, targets, strict=True)
    ]
    for reader in readers:
        reader.start()
    code = proc.wait()
    for reader in readers:
        reader.join(DRAIN_S)
    return code, seen
