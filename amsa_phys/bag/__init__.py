"""Every run as a ROS 2 bag: an MCAP file with ROS 2 message encodings (``--bag``).

:class:`BagRecorder` listens to a run and streams it into a :class:`BagWriter`; the
messages and topics come from :mod:`amsa_phys.stdmsgs`. See the README's "Every run as a
bag".
"""

from .runbag import EVENTS_TOPIC, TF_TOPIC, BagRecorder
from .writer import BagWriter, scalar_cdr

__all__ = ["EVENTS_TOPIC", "TF_TOPIC", "BagRecorder", "BagWriter", "scalar_cdr"]
