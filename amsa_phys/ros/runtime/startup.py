"""A node stopped while it starts ends quietly; once it runs, the signals are ROS's again.

When a launch stops early (a C++ Leaf refused its parameters and its process, ``required``,
ended the launch; or Ctrl-C), roslaunch sends SIGINT to the Python nodes still importing
numpy and rospy or inside ``rospy.init_node``. Left to Python, each printed a 20–30 line
``KeyboardInterrupt`` traceback under the one line that said what was wrong, and a user read
it as a second crash. Left to rospy, worse: its handler calls ``signal_shutdown``, which asks
the master to unregister the node through the same XML-RPC proxy the interrupted
``init_node`` holds the lock of, so the node hung until roslaunch's SIGKILL 17 s later
("required SIGKILL. May still be running").

So the generated script (``files/node.py.in``) puts a handler on SIGINT and SIGTERM before
its first heavy import that ends the process at once, saying nothing (exit 128 + the
signal's number); :func:`init_node` keeps rospy's handlers off while the node starts; and
:func:`started`, called where the node's start-up ends (its readers connected, its run
about to begin), puts back the signals' own handling and, for a node that wants them,
rospy's handlers, exactly as ``rospy.init_node`` would have installed them: during its run a
node stops as it always did (the simulator writes its outputs so far and says
"interrupted").

Nothing of a node is lost by ending at once while it starts: it has published nothing and
written nothing yet (the simulator's run directory is created empty, as Ctrl-C there always
left it); the master, which roslaunch stops too, forgets it with the launch.
"""

from __future__ import annotations

import signal
from typing import Any

#: The attribute the script's handler carries: the handlers it replaced, by signal number.
PREVIOUS = "amsa_previous"
SIGNALS = (signal.SIGINT, signal.SIGTERM)


def init_node(rospy: Any, name: str, **kwargs: Any) -> None:
    """``rospy.init_node`` without rospy's signal handlers (see the module's docstring)."""
    rospy.init_node(name, disable_signals=True, **kwargs)


def started(rospy: Any = None) -> None:
    """The node's start-up is over: SIGINT and SIGTERM back to what they were before the
    script's handler (Python's KeyboardInterrupt, the default end), then, given ``rospy``,
    rospy's own handlers on top, as ``init_node`` installs them.

    Does nothing to a signal whose handler is not the script's (a node run otherwise than by
    its generated script, a signal its parent ignored), so it can be called in any case.
    """
    for sig in SIGNALS:
        previous = getattr(signal.getsignal(sig), PREVIOUS, {})
        if sig in previous:
            signal.signal(sig, previous[sig])
    if rospy is not None:
        rospy.core.register_signals()
