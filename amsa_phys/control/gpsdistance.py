"""GpsDistance: the leader-follower distance as the follower can know it, from two GPS fixes.

The 2019 model feeds the controller's ``distanceLeaderFollower`` from ``MyDistanceMonitor``,
the *true* distance between the rovers: GPS noise and lost fixes then only reach the
bearing, and a 90 % GPS loss barely moves the paper's Fig. 6. A real follower
has no such oracle. This component computes the distance from the fixes the controller
already reads, so a lost leader fix (the GPS publishes nothing and its consumers keep the
stale fix) is a stale distance, and GPS noise is distance noise. ``worlds/
mde_challenge_sensed.yaml`` wires it in; ``MyDistanceMonitor`` stays the judge (the quality
signal is the true distance).

A controller, not a sensor: in the AMSA style a sensor feeds only controllers and observers
(``model/links.py``), and this reads two sensors' outputs; it is the first stage of a
cascade whose second stage is the follower law.
"""

from __future__ import annotations

from ..model.template import Kind, Port
from .monitor import DistanceMonitor


class GpsDistance(DistanceMonitor):
    """Euclidean distance between the leader's and the follower's GPS fixes.

    The same arithmetic as :class:`DistanceMonitor` (inherited: ``do_step`` and
    ``step_many``), fed with fixes instead of true positions; a controller stage, not a
    sensor, because one sensor may not feed another in this architecture.
    """

    kind = Kind.CONTROLLER
    inputs = (
        Port("xLeader", 0.0, "leader x (GPS fix)", "m"),
        Port("yLeader", 0.0, "leader y (GPS fix)", "m"),
        Port("xFollower", 0.0, "follower x (GPS fix)", "m"),
        Port("yFollower", 0.0, "follower y (GPS fix)", "m"),
    )
    outputs = (Port("distanceFollowerToLeader", 0.0, "distance between the two fixes", "m"),)
