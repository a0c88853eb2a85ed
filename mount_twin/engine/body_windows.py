"""The agreement of the compared body samples with the twin, window by window of body stamps
(`Windows`), the third stage of the body IMU's check (`body_check`), with the body messages not
compared in each; at the end, a WARN for those no window said."""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from mount_twin.engine.agreement import (
    MIN_SAMPLES,
    NAME,
    OUTSIDE_THE_RUN,
    agreement,
    window_status,
)
from mount_twin.engine.batch import WARN, HealthStatus
from mount_twin.engine.body_counts import NOT_COMPARED, RESETS, WARNED_AT_END, not_compared
from mount_twin.engine.body_matching import Taken
from mount_twin.scene.description import BodySensor

_Chunk = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]
"""Compared samples of a window: stamps ns, seconds, measured, residual, readings provided."""


@dataclass
class _Window:
    """The window being filled: chunks of its compared samples (stamps ns, seconds, measured,
    residual, readings provided), and the body messages not compared in it, by reason."""

    index: int
    chunks: list[_Chunk]
    problems: Counter[str]


CUT_BY_END = "the last window, closed by the end of the stream"
CUT_BY_JUMP = "the last window before the body IMU's stamps jumped back"
"""How a window cut short is said (`Windows._close`)."""
LOOSE = ("unanswered", *WARNED_AT_END)
"""Not compared for the stream's sake, not at a place in it (left at its end, held too long,
lost by the middleware, never processed at a second stop; the node counts the last two as it
learns of them): reported in the window judged next (unanswered at the end of a run the twin
restarted after: at its place; the others, WARNED_AT_END, that no window reports: in the
WARN at the end, `Windows.finish`; unanswered at the end of the stream, said, not warned of:
in the last window where it is judged, else in that WARN where one goes out, else in the
run's counts alone)."""


class Windows:
    """The agreement of compared samples, window by window of body stamps, and the body
    messages not compared in each: a sample where its stamp falls, a rejected message where the
    accepted sample after it does (its place in the body stream), so that neither depends on
    how the two streams come interleaved; before the first window, in the first; in a window
    too short to judge, in the next. Where the body stream's stamps jump back (a new run,
    `Matcher`), the window open ends as the stream's last does, and the grid starts again
    from the run's first compared sample."""

    def __init__(self, sensor: BodySensor, totals: Counter[str]) -> None:
        self._sensor, self._totals = sensor, totals
        self._origin: float | None = None
        self._window: _Window | None = None
        self._carried: Counter[str] = Counter()
        self._marks: list[tuple[int, str]] = []
        """(place among the accepted samples of the one after it, rejected_<reason>) of each
        rejected message not yet in a window."""
        self._loose_reported: Counter[str] = Counter()
        self._judged = False
        self._run = 0
        """The body stream's run the windows are in (its stamps' jumps back so far)."""

    def mark(self, places: np.ndarray, reasons: np.ndarray) -> None:
        """Rejected messages (reasons of REJECTED), each before the accepted sample at its
        place."""
        self._marks += [
            (p, f"rejected_{r}") for p, r in zip(places.tolist(), reasons, strict=True)
        ]

    def add(self, taken: Taken, residual: np.ndarray) -> list[tuple[int, HealthStatus]]:
        """Reports (stamp ns, status) of the windows these samples (all taken out of the
        matcher, the compared ones' `residual` beside them) close."""
        origin = self._origin
        one = len(taken) == 1 and taken.why[0] == "" and taken.run[0] == self._run
        if one and origin is not None:  # the live stream's one sample compared: no arrays
            # `_add_run`'s window index of it, as Python floats (the same bits)
            index = math.floor((float(taken.t[0]) - origin) / self._sensor.window_s)
            chunk = (taken.ns, taken.t, taken.measured, residual, taken.present)
            return self._into(max(index, 0), int(taken.place[0]), [], chunk)
        said = Counter(taken.why.tolist())
        for key in LOOSE:  # those at a place: said there
            self._loose_reported[key] += said[key]
        reports = []
        start = k = 0  # into the samples, the compared ones
        for run in sorted(set(taken.run.tolist())):
            stop = start + int((taken.run[start:] == run).sum())  # runs rise
            whole = start == 0 and stop == len(taken)
            part = taken if whole else taken.select(slice(start, stop))
            n = int((part.why == "").sum())
            if run != self._run:
                reports += self._close(CUT_BY_JUMP)
                self._origin, self._run = None, run
            reports += self._add_run(part, residual[k : k + n])
            start, k = stop, k + n
        return reports

    def _add_run(self, taken: Taken, residual: np.ndarray) -> list[tuple[int, HealthStatus]]:
        """`add` of samples of the run the windows are in."""
        if not taken.t.shape[0]:
            return []
        compared = taken.why == ""
        if self._origin is None:
            if not compared.any():
                self._carried.update(taken.why.tolist())
                self._attribute(int(taken.place[-1]), self._carried)
                return []
            self._origin = float(taken.t[compared][0])
        index = np.floor((taken.t - self._origin) / self._sensor.window_s).astype(np.int64)
        index = np.maximum(index, 0)  # not compared before the first window: in it
        reports = []
        k = 0  # into the compared ones
        cuts = np.flatnonzero(index[1:] != index[:-1]) + 1  # (the windows rise: stamps do)
        for start, stop in pairwise([0, *cuts.tolist(), index.shape[0]]):
            these = compared[start:stop]
            n = int(these.sum())
            part: slice | np.ndarray = slice(start, stop)
            problems: list[str] = []
            if n < stop - start:  # (all compared: the rows themselves, no copy)
                problems = taken.why[start:stop][~these].tolist()
                part = np.flatnonzero(these) + start
            chunk = None
            if n:
                chunk = (
                    taken.ns[part],
                    taken.t[part],
                    taken.measured[part],
                    residual[k : k + n],
                    taken.present[part],
                )
                k += n
            reports += self._into(int(index[start]), int(taken.place[stop - 1]), problems, chunk)
        return reports

    def _into(
        self,
        index: int,
        place: int,
        problems: list[str],
        chunk: _Chunk | None,
    ) -> list[tuple[int, HealthStatus]]:
        """Samples of the run in window `index` (the last at `place` among the accepted ones):
        the reasons of those not compared, and the compared ones' `chunk` (None: none); the
        reports of the window they close."""
        reports = []
        if self._window is not None and self._window.index != index:
            reports += self._close()
        if self._window is None:
            self._window, self._carried = _Window(index, [], self._carried), Counter()
        window = self._window
        window.problems.update(problems)
        self._attribute(place, window.problems)
        if chunk is not None:
            window.chunks.append(chunk)
        return reports

    def _attribute(self, place: int, into: Counter[str]) -> None:
        """The rejected messages before the accepted sample at `place` (and it), into `into`."""
        n = 0
        while n < len(self._marks) and self._marks[n][0] <= place:
            into[self._marks[n][1]] += 1
            n += 1
        del self._marks[:n]

    def finish(self, counts: Counter[str], stamp_ns: int) -> list[tuple[int, HealthStatus]]:
        """The last, partial window's report, if it spans half a window (with the rejected
        messages after its last sample); if no window was judged over the run although body
        messages came (`counts`), a WARN saying why, stamped `stamp_ns`: silence would read
        as a check passed. Where body messages not compared are in no window reported (the
        last too short to judge; WARNED_AT_END: never at a place in the stream), a WARN
        saying them, as a window judged would: only those `OUTSIDE_THE_RUN` (unanswered at
        the end, the recorders never stop together) make none, said only in its message where
        one goes out for the others."""
        last = np.iinfo(np.int64).max
        self._attribute(last, self._carried if self._window is None else self._window.problems)
        reports = self._close(CUT_BY_END)
        values = {f"body_{k}": str(v) for k, v in counts.items()}
        if not (reports or self._judged or not counts["received"]):
            missed = ", ".join(f"{k} {v}" for k, v in not_compared(counts).items() if v)
            message = (
                f"no window of the body IMU was judged over the run: {counts['compared']} of "
                f"{counts['received']} messages compared (a window needs {MIN_SAMPLES} "
                f"providing a reading over half its {self._sensor.window_s:g} s)"
                + (f"; not compared: {missed}" if missed else "")
            )
            return [(stamp_ns, HealthStatus(NAME, WARN, message, values))]
        unsaid = self._carried + Counter(
            {k: counts[k] - self._loose_reported[k] for k in LOOSE}
        )  # (Counter's + keeps the counts above 0)
        if not set(unsaid) - OUTSIDE_THE_RUN:
            return reports
        said = [WARNED_AT_END[k].format(unsaid.pop(k), k) for k in WARNED_AT_END if k in unsaid]
        if unsaid:
            placed = ", ".join(f"{k} {unsaid[k]}" for k in NOT_COMPARED if k in unsaid)
            n = unsaid.total()
            said.append(
                f"{n} body IMU messages not compared after the last window judged: {placed}"
            )
        reports.append((stamp_ns, HealthStatus(NAME, WARN, "; ".join(said), values)))
        return reports

    def _close(self, cut: str = "") -> list[tuple[int, HealthStatus]]:
        """The window open closed by the next beginning, or cut short (`cut`: `CUT_BY_END`,
        `CUT_BY_JUMP`; judged if it spans half a window, else its messages said with the next)."""
        window, self._window = self._window, None
        if window is None:
            return []
        if not window.chunks:
            self._carried.update(window.problems)
            return []
        ns, t, measured, residual, present = (
            np.concatenate(a) for a in zip(*window.chunks, strict=True)
        )
        short = bool(cut) and t[-1] - t[0] < 0.5 * self._sensor.window_s
        if present.sum(axis=0).max() < MIN_SAMPLES or short:
            self._carried.update(window.problems)  # too short to judge: said with the next
            return []
        for key in LOOSE:
            window.problems[key] += self._totals[key] - self._loose_reported[key]
            self._loose_reported[key] = self._totals[key]
        problems = {key: window.problems[key] for key in NOT_COMPARED}
        figures = agreement(t, measured, residual, self._sensor, present)
        span = (float(t[-1] - t[0]), int(t.shape[0]))
        status = window_status(figures, self._sensor, span, problems)
        status.values[f"body_{RESETS}"] = str(self._run)
        if cut:
            status.message += f" ({cut})"
        self._judged = True
        return [(int(ns[-1]), status)]
