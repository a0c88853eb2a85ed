"""Windows of the body messages' own stamps in which every message was rejected (`Refusals`):
a WARN when the next begins, so that a body IMU the twin never takes shows live, not only at
the end of the stream. It depends on the body stream alone (`body_check`)."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from mount_twin.engine.agreement import NAME
from mount_twin.engine.batch import WARN, HealthStatus
from mount_twin.engine.body_counts import REJECTED
from mount_twin.scene.description import BodySensor


class Refusals:
    """Windows of body_sensor.window_s of the body messages' own stamps (a grid from the first
    message with one, and afresh from one stamped more than `back_ns` before the latest; a
    message without, or stamped behind, counts in the window the stream is in): each in which
    messages came and none was accepted is reported, when the next begins."""

    def __init__(self, sensor: BodySensor, back_ns: int) -> None:
        self._sensor, self._back_ns = sensor, back_ns
        self._window_ns = sensor.window_s * 1e9
        self._origin: int | None = None
        self._index = 0
        self._accepted = 0
        self._rejected: Counter[str] = Counter()
        self._last_ns = 0

    def add(self, stamps_ns: np.ndarray, why: np.ndarray) -> list[tuple[int, HealthStatus]]:
        """Reports (stamp ns, status) of the windows these screened messages (stamps, and
        why each was rejected, '' where not) close."""
        reports = []
        for reason, ns in zip(why, stamps_ns.tolist(), strict=True):
            if ns > 0 and (self._origin is None or ns < self._last_ns - self._back_ns):
                if self._origin is not None:  # jumped back: the window ends, a grid afresh
                    reports += self._close(self._last_ns)
                self._origin, self._index, self._last_ns = ns, 0, ns
            i = math.floor((ns - self._origin) / self._window_ns) if ns > 0 else 0
            if self._origin is not None and i > self._index:
                reports += self._close(self._last_ns)  # the latest stamp in the window
                self._index = i
            if reason:
                self._rejected[reason] += 1
            else:
                self._accepted += 1
            self._last_ns = max(self._last_ns, ns)
        return reports

    def _close(self, stamp_ns: int) -> list[tuple[int, HealthStatus]]:
        rejected, accepted = self._rejected, self._accepted
        self._rejected, self._accepted = Counter(), 0
        if accepted or not rejected:
            return []
        n = sum(rejected.values())
        why = ", ".join(f"rejected_{r} {v}" for r, v in sorted(rejected.items()))
        message = (
            f"none of the {n} body IMU messages over {self._sensor.window_s:g} s of their "
            f"stamps was taken: {why}"
        )
        if "wrong_frame_id" in rejected:
            message += f" (body_sensor.frame_id is {self._sensor.frame_id!r})"
        values = {f"body_rejected_{r}": str(rejected[r]) for r in REJECTED}
        return [(stamp_ns, HealthStatus(NAME, WARN, message, values))]
