"""A Dask cluster on this machine for the tests that sweep on Dask, taking no fixed port.

``LocalCluster(dashboard_address=None)`` turns the dashboard off, but its scheduler still
starts an HTTP server (health and metrics routes) on 8787, and where that port is taken (a
parallel test worker's cluster, a user's dashboard) it warns ("Port 8787 is already in use")
in a run whose user asked for no dashboard. Here that server listens on a free loopback port
(distributed's documented ``:0``) and the dashboard stays off (the scheduler's ``dashboard``).
"""

from __future__ import annotations

from typing import Any


def local_cluster(workers: int = 2) -> Any:
    """A ``distributed.LocalCluster`` of ``workers`` single-threaded worker processes, no
    dashboard, nothing on a fixed port (use it as a context manager)."""
    import distributed

    return distributed.LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address="127.0.0.1:0",
        scheduler_kwargs={"dashboard": False},
    )
