"""``run_lockstep`` passes roslaunch's output through and names the error that stopped it.

Without ROS: a small Python program stands in for roslaunch. What is checked is what a user
reads: every byte of both streams arrives on the same stream, unchanged; the children see a
terminal where the user has one (else the nodes' lines would wait in a pipe's buffer until
they exit); and the last line's pointer names the first ``error: `` line, not a Python
exception's ``...Error: `` nor a line that merely mentions an error. The e2e test
(``tests/ros/test_ros_leaf_failure.py``) checks it on a real launch.
"""

from __future__ import annotations

import contextlib
import os
import pty
import signal
import subprocess
import sys
import textwrap

import pytest
import sigint

from amsa_phys.ros.runtime.launchout import Seen, run

BAD_KV = "/MyFollowerController: /MyFollowerController/Kv: -5 is below the minimum 0"


def _seen(*lines: str) -> Seen:
    seen = Seen()
    for line in lines:
        seen.note(line)
    return seen


def test_the_first_error_line_is_named() -> None:
    seen = _seen(
        "\x1b]2;/ws/src/pkg/launch/s1.launch\x07",
        "ModuleNotFoundError: No module named 'rospy'",  # a traceback's last line: not ours
        "[ERROR] [1.2]: some node's log line that says error: in its middle",
        f"\x1b[31merror: {BAD_KV}\x1b[0m\r",  # coloured, from a terminal (CR LF)
        "error: amsa_simulator: a second error",
    )
    assert seen.errors == [BAD_KV, "amsa_simulator: a second error"]
    assert seen.cause() == f"see the 2 errors above (the first: {BAD_KV})"
    assert _seen(f"error: {BAD_KV}").cause() == f"see the error above ({BAD_KV})"


def test_without_an_error_line_the_dead_process_is_named() -> None:
    died = "\x1b[31m=====REQUIRED process [amsa_leaves-4] has died!"
    assert _seen(died, "REQUIRED process [amsa_simulator-2] has died!").cause() == (
        "roslaunch's required process amsa_leaves died first (see its output above)"
    )
    assert _seen("error: ", "process has finished cleanly").cause() == (
        "see roslaunch's output above"
    )


def test_an_error_line_names_itself_on_one_line() -> None:
    """A control character in a node's error (a scenario's name) cannot drive the terminal
    from the script's last line: colours and titles go, the others are escaped."""
    assert _seen("error: bad \x1b[2J\x07 name").errors == ["bad \\x07 name"]


CHILD = textwrap.dedent(
    """
    import os, sys
    os.write(1, b"\\x1b[1mstarted roslaunch server\\x1b[0m\\n")
    os.write(2, b"error: " + sys.argv[1].encode() + b"\\n")
    os.write(1, b"partial line without its end")
    os.write(2, b"isatty " + str(os.isatty(1)).encode() + b"\\n")
    sys.exit(3)
    """
)


def test_both_streams_pass_through_unchanged(capfd: pytest.CaptureFixture[bytes]) -> None:
    code, seen = run([sys.executable, "-c", CHILD, BAD_KV], dict(os.environ))
    out, err = capfd.readouterr()
    assert code == 3
    assert out == "\x1b[1mstarted roslaunch server\x1b[0m\npartial line without its end"
    assert err == f"error: {BAD_KV}\nisatty False\n"
    assert seen.errors == [BAD_KV]


def test_the_launch_gets_a_terminal_where_the_user_has_one() -> None:
    """On a terminal, roslaunch and its nodes write to a terminal of their own (line by
    line, in colour), as they would run by hand; the script's own output still arrives."""
    master, slave = pty.openpty()
    script = (
        "import os, sys\n"
        "from amsa_phys.ros.runtime.launchout import run\n"
        f"code, seen = run([sys.executable, '-c', {CHILD!r}, 'x'], dict(os.environ))\n"
        "print('\\nverdict', code, seen.cause(), flush=True)\n"
    )
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=slave, stderr=subprocess.PIPE)
    os.close(slave)
    chunks = []
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:  # EIO: every writer closed its side
            break
        if not chunk:
            break
        chunks.append(chunk)
    os.close(master)
    _, err = proc.communicate()
    shown = b"".join(chunks).decode().replace("\r\n", "\n")
    assert proc.returncode == 0, err
    assert err.decode().splitlines() == ["error: x", "isatty True"]
    assert shown.startswith("\x1b[1mstarted roslaunch server\x1b[0m\npartial line without")
    assert shown.rstrip().endswith("verdict 3 see the error above (x)")


WAITS_FOR_CTRL_C = textwrap.dedent(
    """
    import signal, sys
    def stop(*_):
        print("stopped by SIGINT", flush=True)
        sys.exit(0)
    signal.signal(signal.SIGINT, stop)
    print("ready", flush=True)
    while True:
        signal.pause()
    """
)


def test_sigterm_to_the_script_stops_the_launch_as_ctrl_c() -> None:
    """A CI's timeout that sends SIGTERM to ``run_lockstep`` alone: roslaunch gets the
    SIGINT that stops a launch cleanly, its last words still pass through, and the script
    goes on to its verdict (it used to leave roslaunch running, orphaned)."""
    script = (
        "import os, sys\n"
        "from amsa_phys.ros.runtime.launchout import run\n"
        f"code, seen = run([sys.executable, '-c', {WAITS_FOR_CTRL_C!r}], dict(os.environ))\n"
        "print('verdict', code, flush=True)\n"
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", script],
        stdout=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=sigint.at_default,
    )
    try:
        assert proc.stdout is not None
        assert proc.stdout.readline() == "ready\n"
        proc.send_signal(signal.SIGTERM)
        out, _ = proc.communicate(timeout=600)  # a deadline for a failure, not a measure
    finally:  # the stand-in too, whatever happened
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
    assert out == "stopped by SIGINT\nverdict 0\n"
    assert proc.returncode == 0


def test_a_sigterm_as_roslaunch_starts_is_passed_on_too() -> None:
    """The SIGTERM handler was set only once the output readers ran: roslaunch's first line
    could reach the user (a CI reading it, then timing out) before it was, and a SIGTERM
    then killed the script alone, leaving roslaunch orphaned. Here one comes as roslaunch
    starts: the script still stops roslaunch and gives its verdict."""
    script = (
        "import os, signal, subprocess, sys\n"
        "from amsa_phys.ros.runtime import launchout\n"
        "real = subprocess.Popen\n"
        "def popen(*args, **kwargs):\n"
        "    child = real(*args, **kwargs)\n"
        "    print('child', child.pid, file=sys.stderr, flush=True)\n"
        "    os.kill(os.getpid(), signal.SIGTERM)  # a CI's timeout, as roslaunch starts\n"
        "    return child\n"
        "launchout.subprocess.Popen = popen\n"
        f"code, seen = launchout.run([sys.executable, '-c', {WAITS_FOR_CTRL_C!r}], {{}})\n"
        "print('verdict', code, flush=True)\n"
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", script],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=sigint.at_default,
    )
    try:
        out, err = proc.communicate(timeout=600)  # a deadline for a failure, not a measure
    finally:  # the stand-in too, whatever happened
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 0, err
    assert out.splitlines()[-1].startswith("verdict "), (out, err)
    child = int(err.split("child ", 1)[1].split()[0])
    with pytest.raises(ProcessLookupError):  # ended by the SIGINT, and reaped
        os.kill(child, 0)
