"""A local Dask cluster shaped like a small real one, for the tests and the city bench."""

from __future__ import annotations

from typing import Any


def two_workers() -> Any:
    """A LocalCluster of two worker processes of one thread each, on the loopback, without
    a dashboard; a context manager (``with two_workers() as cluster``)."""
    from distributed import LocalCluster

    return LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        host="127.0.0.1",
        processes=True,
        dashboard_address=None,
    )
