"""Mounts that age, live: the deck and body IMU streams cut into windows of `ageing.window_s`
of body stamps, each re-fitted (`ageing.fit_window`) once both streams have passed its end, and
judged against the scene's `ageing` bands as a `mount_twin: ageing` diagnostics status.

The windows are `track`'s: from the first body sample's stamp plus `ageing.LEAD_S`, the deck's
record taken from `LEAD_S` before each window's start. A window is cut by stamps alone, so
its fit is the same live and in a replay; a fit takes seconds, so the node runs the jobs
(`WindowJob`, `run_job`) in a worker process and publishes each report when it is done,
stamped with the window's last body stamp.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mount_twin.analysis.ageing import LEAD_S, Band, WindowFit, fit_window
from mount_twin.engine.batch import LEVEL_NAMES, WARN, HealthReport, HealthStatus
from mount_twin.io.signals import Signal
from mount_twin.scene.description import Scene

NAME = "mount_twin: ageing"


@dataclass(frozen=True)
class WindowJob:
    """One window to re-fit: the scene (with its `ageing`), the (foundation, body) records
    (s on the twin's time base), the window's span (s) and its last body stamp (ns)."""

    scene: Scene
    records: tuple[Signal, Signal]
    span: tuple[float, float]
    stamp_ns: int


def _status(fit: WindowFit) -> HealthStatus:
    """A window's fit as a diagnostics status."""
    shown = ", ".join(f"{n} ×{v:.3f} ± {fit.sigma[n]:.2g}" for n, v in fit.values.items())
    span = f"{fit.start_s:.1f}–{fit.end_s:.1f} s"
    message = f"{span}: {shown or 'nothing identified'}" + (f" — {fit.why}" if fit.why else "")
    if fit.refused:
        message += "; not identified: " + ", ".join(fit.refused)
    values = {"window_start_s": f"{fit.start_s:.3f}", "window_end_s": f"{fit.end_s:.3f}"}
    for name, value in fit.values.items():
        values[name] = f"{value:.4f}"
        values[f"{name}_sigma"] = f"{fit.sigma[name]:.3g}"
    values.update({f"{name}_refused": why for name, why in fit.refused.items()})
    return HealthStatus(NAME, LEVEL_NAMES.index(fit.level), message, values)


def run_job(job: WindowJob) -> HealthReport:
    """The window's fit as a diagnostics report (a plain function of plain data: it runs in a
    worker process live). A window the twin cannot follow is a WARN saying why."""
    ageing = job.scene.ageing
    assert ageing is not None
    band = Band(ageing.warn, ageing.error)
    try:
        status = _status(fit_window(job.scene, job.records, job.span, ageing.fit, band))
    except ValueError as err:
        span = f"{job.span[0]:.1f}–{job.span[1]:.1f} s"
        status = HealthStatus(NAME, WARN, f"{span}: not fitted: {err}", {})
    return HealthReport(job.stamp_ns * 1e-9, -1, [status])


class _Record:
    """A growing record (stamps ns and s, accel, gyro), its oldest part dropped as it goes."""

    def __init__(self) -> None:
        self.parts: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        self.last_t = -math.inf

    def add(self, ns: np.ndarray, t: np.ndarray, accel: np.ndarray, gyro: np.ndarray) -> None:
        if t.shape[0]:
            self.parts.append((ns, t, accel, gyro))
            self.last_t = float(t[-1])

    def cut(self, start: float, end: float) -> tuple[Signal, int]:
        """The samples in [start, end) and the last one's stamp (ns); those before `start`
        dropped for good."""
        ns, t, accel, gyro = (np.concatenate(a) for a in zip(*self.parts, strict=True))
        self.parts = [(ns[t >= start], t[t >= start], accel[t >= start], gyro[t >= start])]
        keep = (t >= start) & (t < end)
        last = int(ns[keep][-1]) if keep.any() else 0
        return Signal(t[keep], accel[keep], gyro[keep]), last


class AgeingTracker:
    """The windows of the deck and body IMU streams, due once both pass their end."""

    def __init__(self, scene: Scene) -> None:
        assert scene.ageing is not None
        self.scene = scene
        self._window_s = scene.ageing.window_s
        self._foundation, self._body = _Record(), _Record()
        self._start: float | None = None

    def add_foundation(
        self, ns: np.ndarray, t: np.ndarray, accel: np.ndarray, gyro: np.ndarray
    ) -> list[WindowJob]:
        """Deck samples (stamps ns and s, sensor-frame accel m/s², gyro rad/s); the windows
        they complete."""
        self._foundation.add(ns, t, accel, gyro)
        return self._due()

    def add_body(
        self, ns: np.ndarray, t: np.ndarray, accel: np.ndarray, gyro: np.ndarray
    ) -> list[WindowJob]:
        """Body IMU samples, as `add_foundation`'s."""
        if self._start is None and t.shape[0]:
            self._start = float(t[0]) + LEAD_S
        self._body.add(ns, t, accel, gyro)
        return self._due()

    def _due(self) -> list[WindowJob]:
        jobs = []
        while (
            self._start is not None
            and min(self._foundation.last_t, self._body.last_t) >= self._start + self._window_s
        ):
            start, end = self._start, self._start + self._window_s
            foundation, _ = self._foundation.cut(start - LEAD_S, end)
            body, stamp_ns = self._body.cut(start, end)
            self._start = end
            if foundation.t.shape[0] > 2 and body.t.shape[0] > 2:
                jobs.append(WindowJob(self.scene, (foundation, body), (start, end), stamp_ns))
        return jobs
