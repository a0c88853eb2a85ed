"""The body sensor's reading predicted at the twin's published rows as they come (`Lead`),
the first stage of the body IMU's check (`body_check`): its rates and angular acceleration are
central differences, so a row is predicted once the two rows after it are published (a run's
first and last rows by one-sided differences)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass
class TwinRows:
    """Published rows of the twin: stamps (s), pose rows, (k, n, 6) wrenches, the
    foundation's rate Ω_F at each (rad/s, F)."""

    t: np.ndarray
    pose: np.ndarray
    wrenches: np.ndarray
    rate: np.ndarray

    def __len__(self) -> int:
        return int(self.t.shape[0])

    def then(self, later: TwinRows) -> TwinRows:
        return TwinRows(
            np.concatenate([self.t, later.t]),
            np.concatenate([self.pose, later.pose]),
            np.concatenate([self.wrenches, later.wrenches]),
            np.concatenate([self.rate, later.rate]),
        )

    def part(self, start: int, stop: int) -> TwinRows:
        """Rows [start, stop) (views)."""
        return TwinRows(
            self.t[start:stop],
            self.pose[start:stop],
            self.wrenches[start:stop],
            self.rate[start:stop],
        )

    def tail(self, n: int) -> TwinRows:
        """The last n rows (copies: the engine reuses its buffers)."""
        k = len(self) - n
        return TwinRows(
            self.t[k:].copy(), self.pose[k:].copy(), self.wrenches[k:].copy(), self.rate[k:].copy()
        )


Predict = Callable[[TwinRows, slice], np.ndarray]
"""The (k, 6) predictions of the rows a slice selects of a window of rows."""
_NO_PREDICTION = (np.zeros(0), np.zeros((0, 6)))


class Lead:
    """Predictions of rows as soon as their difference stencils are whole (two rows on)."""

    HELD = 4
    """Rows kept for the next batch's stencils: two predicted already, two not yet."""

    def __init__(self, predict: Predict) -> None:
        self._predict = predict
        self._held: TwinRows | None = None
        self._at_start = True

    def add(self, rows: TwinRows) -> tuple[np.ndarray, np.ndarray]:
        """(stamps s, (k, 6) predictions) of the rows that `rows` completes."""
        # the window is a copy either way (the engine reuses its buffers): what is held, views
        window = rows.tail(len(rows)) if self._held is None else self._held.then(rows)
        n = len(window)
        if n < self.HELD + 1:
            self._held = window
            return _NO_PREDICTION
        first = 0 if self._at_start else 2
        values = self._predict(window, slice(first, n - 2))
        self._held, self._at_start = window.part(n - self.HELD, n), False
        return window.t[first : n - 2], values

    def finish(self) -> tuple[np.ndarray, np.ndarray]:
        """The rows still held, the last by one-sided differences (fewer than 3 rows in the
        whole run: none): the end of the stream, or of the twin's run (the rows after it
        start afresh)."""
        window, self._held = self._held, None
        first = 0 if self._at_start else 2
        self._at_start = True
        if window is None or len(window) < 3:
            return _NO_PREDICTION
        return window.t[first:], self._predict(window, slice(first, None))
