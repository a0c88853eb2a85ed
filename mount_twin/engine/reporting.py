"""Outputs and health: a push's published rows into the health window, its OutputBatch, and
the diagnostics reports due in it."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from mount_twin.engine.batch import HealthReport, OutputBatch
from mount_twin.engine.delay_line import Frame
from mount_twin.engine.driver import CoreDriver
from mount_twin.engine.health import HealthWindow
from mount_twin.engine.rows import BatchRows, Part, Rows, Tail


class Reporting:
    """What one twin publishes.

    Args:
        driver: the core driver (utilisation peaks and the conditions holding per mount).
        health: the health window the reports come from.
        counts: the engine's counters (reported; lost_estimated is added here).
    """

    def __init__(self, driver: CoreDriver, health: HealthWindow, counts: Counter[str]) -> None:
        self._driver = driver
        self._health = health
        self._counts = counts
        self._n_mounts = driver.model.n_mounts

    def add(self, parts: list[Part], frame: Frame) -> None:
        """Hand published rows (of `frame`'s samples) to the health window: their peaks where
        the compiled loop gave them, else the rows."""
        for published in parts:
            if isinstance(published, Tail):
                self._health.add_outputs(
                    np.array([published.stamp]), published.pose, published.wrenches
                )
            elif published.peaks is None:
                self._health.add_outputs(
                    frame.stamps[published.sample], published.pose, published.wrenches
                )
            elif published.sample.shape[0]:
                self._health.add_output_peaks(*published.peaks)

    def batch(
        self, frame: Frame, rows: BatchRows, parts: list[Part], reports: list[HealthReport]
    ) -> OutputBatch:
        """The OutputBatch of a push's (or a flush's) published parts and reports."""
        if not parts:
            empty = OutputBatch.empty(self._n_mounts)
            empty.health = reports
            return empty
        whole = [p for p in parts if isinstance(p, Rows)]
        if len(whole) == len(parts):
            sample, pose, wrenches = rows.gather(whole)
            stamps, positions = frame.stamps[sample], frame.relative(sample)
        else:  # a run's last sample (`Tail`), maybe of an earlier push
            located = [_located(p, frame) for p in parts]
            stamps, positions = (np.concatenate([x[i] for x in located]) for i in (0, 1))
            pose = np.concatenate([p.pose for p in parts])
            wrenches = np.concatenate([p.wrenches for p in parts])
        return OutputBatch(stamps, positions, pose, wrenches, reports)

    def report(
        self,
        stamp: float,
        sample: int,
        parts: list[Part] | None = None,
        stalled_s: float | None = None,
        *,
        ended: bool = False,
    ) -> HealthReport:
        """The report due at `stamp` (s), after sample `sample` and the output rows of `parts`
        (those published before it in its batch); `stalled_s`: the input stalled that long (s,
        `input_status.ENDED`: the record ended) without a report falling due; `ended`: the
        stream's last report. Ends the window."""
        per_mount = np.full(self._n_mounts, math.nan)
        per_mount[self._driver.rated] = self._driver.window_utilisation()
        lost, nominal = self._health.lost_estimate()
        if lost:
            self._counts["lost_estimated"] += lost
        report = self._health.report(
            stamp,
            sample,
            self._counts,
            per_mount,
            self._driver.active(),
            lost_from_stamps=lost,
            nominal_interval_s=nominal,
            stalled_s=stalled_s,
            ended=ended,
        )
        report.rows = sum(p.pose.shape[0] for p in parts or ())
        self._driver.end_window()
        return report


def _located(part: Part, frame: Frame) -> tuple[np.ndarray, np.ndarray]:
    """A part's stamps (s) and positions relative to the push's first sample (`Frame.relative`;
    a `Tail` knows its own, whichever push its sample came in)."""
    if isinstance(part, Tail):
        return np.array([part.stamp]), np.array([part.stream_id - frame.first_id])
    return frame.stamps[part.sample], frame.relative(part.sample)
