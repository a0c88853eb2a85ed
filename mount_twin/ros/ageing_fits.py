"""The node's ageing fits (`analysis.ageing_live`), each in a worker process: a window's fit
takes seconds, and run in the executor's thread it would hold the node's input for them (a
kHz input queue overflows). The reports go out in window order as their fits finish, each
stamped with its window's last body stamp, so they equal a replay's.
"""

from __future__ import annotations

import multiprocessing
import signal
import time
from collections import deque
from collections.abc import Callable
from concurrent import futures
from concurrent.futures import Future, ProcessPoolExecutor

from mount_twin.analysis.ageing_live import NAME, WindowJob, run_job
from mount_twin.engine.batch import ERROR, HealthReport, HealthStatus
from mount_twin.io.output_encoding import encode_report
from mount_twin.scene.description import Scene

FIT_WAIT_S = 120.0
"""At shutdown, how long (s) the node waits for each ageing fit still running."""
POLL_S = 0.1
"""Slice (s) of that wait, between which a second stop is seen."""
STOP_SIGNALS = frozenset({signal.SIGINT, signal.SIGTERM})
"""The signals that stop the node, blocked in its worker (see `AgeingFits.submit`)."""


class AgeingFits:
    """The fits submitted and not yet published, oldest first."""

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self._pool: ProcessPoolExecutor | None = None
        self._pending: deque[tuple[int, Future[HealthReport]]] = deque()
        self.not_waited_for = 0
        """Fits a second stop left unfinished (`done`)."""

    def submit(self, job: WindowJob) -> None:
        """Fit `job` in the worker process (started at the first: a fresh interpreter, not a
        fork of a process running DDS threads).

        The worker is spawned with the stop signals blocked, a mask it keeps for its life: a
        stop sent to the node's whole process group (a terminal's Ctrl-C, systemd's SIGTERM)
        stops the node alone, which finishes the fits (`done`) and then the worker. Taken by
        the worker too, SIGINT raised a KeyboardInterrupt out of the fit's result into the
        node's shutdown, and SIGTERM killed the worker, its fit read as failed."""
        if self._pool is None:
            spawn = multiprocessing.get_context("spawn")
            self._pool = ProcessPoolExecutor(max_workers=1, mp_context=spawn)
        # Blocked in this thread only: the node's other threads still take a stop (its
        # handler runs in the main thread either way).
        mask = signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
        try:
            future = self._pool.submit(run_job, job)  # spawns the worker the first time
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        self._pending.append((job.stamp_ns, future))

    def done(
        self, wait: bool = False, give_up: Callable[[], bool] = lambda: False
    ) -> list[tuple[str, int, bytes]]:
        """The reports of the fits finished in order (`wait`: all, each within FIT_WAIT_S,
        then the worker stops), as /diagnostics messages; a fit that raised or did not finish
        in time is an ERROR saying so. Once `give_up()` (the node stopped again), the fits
        still running are not waited for: each an ERROR saying so, the worker ended."""
        msgs = []
        hung = False
        while self._pending and (wait or self._pending[0][1].done()):
            stamp_ns, future = self._pending.popleft()
            deadline = time.monotonic() + FIT_WAIT_S
            while wait and not future.done() and not give_up() and time.monotonic() < deadline:
                futures.wait([future], timeout=POLL_S)  # a stop's handler runs in between
            if not future.done() and give_up():
                hung = True
                self.not_waited_for += 1
                text = "the ageing fit was not waited for: the node was stopped again"
                report = HealthReport(stamp_ns * 1e-9, -1, [HealthStatus(NAME, ERROR, text, {})])
            else:
                try:
                    report = future.result(timeout=0.0)
                except Exception as err:  # the worker died, the fit raised or hung: said
                    hung = hung or not future.done()
                    status = HealthStatus(NAME, ERROR, f"the ageing fit failed: {err!r}", {})
                    report = HealthReport(stamp_ns * 1e-9, -1, [status])
            msgs.append(encode_report(self.scene, report, stamp_ns))
        if wait and self._pool is not None:
            if hung:  # its fit would hold the interpreter's exit (it joins the pool's thread)
                for worker in self._pool._processes.values():  # no public way before 3.14
                    worker.kill()
                    worker.join()
            # Joined, the worker done or killed and reaped (the pool's thread then sees it
            # gone and ends): left running (wait=False), the pool's thread closed its wake-up
            # pipe under the interpreter's exit hook, which then printed "OSError: Bad file
            # descriptor" after the shutdown (CPython gh-83279; a second stop's, 1 CI run in 6
            # on 2026-11-28).
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
        return msgs
