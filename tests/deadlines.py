"""How long a test waits for an event before it calls the wait a hang.

A deadline for a failure, never a measure of speed: CI machines are loaded (a load of 80 on
two cores has been seen here), and there a process that takes minutes to start or to stop is
slow, not stuck. A test that passes waits only as long as the event takes.
"""

#: s before a subprocess (or an event it should cause) is declared hung and the test fails
HANG_S = 600.0
