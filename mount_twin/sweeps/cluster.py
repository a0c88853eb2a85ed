"""A Dask cluster for the duration of some work: the one a sweep and a qualification run on."""

from __future__ import annotations

import logging
import os
import signal
from collections.abc import Callable, Iterator
from contextlib import contextmanager, nullcontext
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

    cluster = client = None
    stopped = False
    try:
        if scheduler is None:
            n = (os.cpu_count() or 1) if workers is None else workers
            with _workers_deaf_to_ctrl_c():
                # ":0": its dashboard on a free port (None still took 8787, warning "Port 8787
                # is already in use" beside a second sweep or any other Dask cluster);
                # silence_logs: the workers' own warnings, at ERROR: a Ctrl-C closing the
                # cluster under running cases printed "Async instruction ... ended with
                # CancelledError" per case beside the command's line (a case that fails is
                # its own FAILED row, a lost worker the command's error)
                cluster = LocalCluster(
                    n_workers=n,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=":0",
                    silence_logs=logging.ERROR,
                )
        client = Client(scheduler or cluster)
        yield client
    except BaseException:
        stopped = True
        raise
    finally:
        with _quiet_dask() if stopped else nullcontext():
            if client is not None:
                client.close()
            if cluster is not None:
                cluster.close()


@contextmanager
def _quiet_dask() -> Iterator[None]:
    """Within this, nothing dask.distributed logs in this process is shown: the work stopped
    (Ctrl-C, an error), and closing forgets the tasks still running, which the local
    scheduler (in this process) logged at ERROR ("Couldn't gather keys: {...: 'forgotten'}")
    beside the command's own line; the command says why it stopped."""
    logger = logging.getLogger("distributed")
    level = logger.level
    logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        logger.setLevel(level)


@contextmanager
def _workers_deaf_to_ctrl_c() -> Iterator[None]:
    """Start a local cluster within this: its worker processes have SIGINT blocked from their
    first instruction to their end. Ctrl-C reaches the terminal's whole process group and is
    the command's, which stops the workers with the cluster; a worker that took it printed a
    KeyboardInterrupt traceback (or "Fatal Python error: init_import_site") beside the
    command's own line, and ignoring it from the cluster's first task on still left the second
    a worker takes to start.

    A signal mask is inherited by the threads a thread starts and across fork and exec: this
    thread's, blocked here, is the cluster's event-loop thread's, which spawns the workers (and
    restarts one that dies) for the cluster's life. The multiprocessing resource tracker is
    started first: its start, had the loop thread made it, unblocks SIGINT in that thread
    afterwards (its own mask dance), and the workers spawned after it would take Ctrl-C again.
    A Ctrl-C to this process meanwhile waits, pending, and is raised when this block ends."""
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


def results_as_completed(
    client: Any, fn: Callable[..., Any], *arg_lists: list[Any]
) -> Iterator[Any]:
    """fn over the argument lists on the cluster (impure: every call runs), each result as its
    task completes; a task's exception is raised here."""
    from dask.distributed import as_completed

    for future in as_completed(client.map(fn, *arg_lists, pure=False)):
        yield future.result()
