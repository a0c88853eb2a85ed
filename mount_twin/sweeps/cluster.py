"""A Dask cluster for the duration of some work: the one a sweep and a qualification run on."""

from __future__ import annotations

import os
import signal
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any


@contextmanager
def dask_client(scheduler: str | None = None, workers: int | None = None) -> Iterator[Any]:
    """A `dask.distributed.Client` of the scheduler at `scheduler`, or of a local cluster of
    `workers` processes, one thread each (default one per core), closed afterwards. Fewer
    than one worker is a ValueError (a LocalCluster of −1 workers waits for ever)."""
    if workers is not None and workers < 1:
        msg = f"workers: must be ≥ 1, got {workers}"
        raise ValueError(msg)
    from dask.distributed import Client, LocalCluster

    cluster = None
    if scheduler is None:
        n = (os.cpu_count() or 1) if workers is None else workers
        # ":0": its dashboard on a free port (None still took 8787, warning "Port 8787 is
        # already in use" beside a second sweep or any other Dask cluster)
        cluster = LocalCluster(
            n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0"
        )
    client = Client(scheduler or cluster)
    try:
        if cluster is not None:  # its workers, not a shared cluster's
            client.run(_ignore_sigint)
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _ignore_sigint() -> None:
    """Run in each worker process of a local cluster: Ctrl-C, which reaches the terminal's whole
    process group, is the command's, which stops the workers with the cluster (each had printed
    a KeyboardInterrupt traceback beside the command's own line)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def results_as_completed(
    client: Any, fn: Callable[..., Any], *arg_lists: list[Any]
) -> Iterator[Any]:
    """fn over the argument lists on the cluster (impure: every call runs), each result as its
    task completes; a task's exception is raised here."""
    from dask.distributed import as_completed

    for future in as_completed(client.map(fn, *arg_lists, pure=False)):
        yield future.result()
