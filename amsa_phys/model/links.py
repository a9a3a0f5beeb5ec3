"""The AMSA architectural style: which kind of component may feed which.

The paper (section 2.1) says interactions "follow classical control data flow (i.e. a sensor
produces data only for the control law or system observers)". Spelled out for all six kinds:

* the environment acts on the process and is seen by sensors and observers;
* the process is seen by sensors and observers, and may act back on its environment;
* sensors feed only controllers and observers (the paper's example);
* controllers command actuators, may feed other controllers (cascades) and observers;
* actuators act only on the process (and may be observed);
* observers only watch: they feed nothing but other observers.
"""

from __future__ import annotations

from .template import Kind

ALLOWED: dict[Kind, frozenset[Kind]] = {
    Kind.ENVIRONMENT: frozenset({Kind.PROCESS, Kind.SENSOR, Kind.OBSERVER, Kind.ENVIRONMENT}),
    Kind.PROCESS: frozenset({Kind.SENSOR, Kind.OBSERVER, Kind.ENVIRONMENT}),
    Kind.SENSOR: frozenset({Kind.CONTROLLER, Kind.OBSERVER}),
    Kind.CONTROLLER: frozenset({Kind.ACTUATOR, Kind.CONTROLLER, Kind.OBSERVER}),
    Kind.ACTUATOR: frozenset({Kind.PROCESS, Kind.OBSERVER}),
    Kind.OBSERVER: frozenset({Kind.OBSERVER}),
}


def link_allowed(producer: Kind, consumer: Kind) -> bool:
    """Whether a Data produced by ``producer`` may be consumed by ``consumer``."""
    return consumer in ALLOWED[producer]


def allowed_text(producer: Kind) -> str:
    """The kinds a producer may feed, for error messages."""
    return ", ".join(sorted(k.value for k in ALLOWED[producer]))
