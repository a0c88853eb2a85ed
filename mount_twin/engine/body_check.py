"""The machine's body IMU against the twin, as a stream: at each body sample the twin's
prediction of that sample and the residual, and window by window how well they agree.

Three stages, each fed in stamp order; each gives the same numbers however its input comes
batched, and whichever of the two streams comes first (live = replay), within `RETAIN_S`:

1. `_Lead` predicts the body sensor at the twin's rows (`sensor_reading.predicted_reading`).
   Its rates and angular acceleration are central differences, so a row is predicted once the
   two rows after it are published (the run's first and last rows by one-sided differences):
   the prediction trails the twin by two rows.
2. `_Matcher`: a body sample stamped s measured the motion at s − lag_s; the prediction there
   is that row's where a row is at it, else interpolated linearly between the rows around it,
   once a row at or past it exists. A sample before the twin's first row, more than
   `RETAIN_S` behind the prediction, or between rows farther apart than input.max_gap_s (a
   gap, a restart) is counted and not compared.
3. `_Windows` judges the compared samples in windows of body_sensor.window_s of stamps
   (`agreement`), on a grid from the first compared sample, each field (specific force, rate)
   on the samples that provide it (a message may mark one reading not provided, REP-145);
   the last, partial window at the end of the stream if it spans half a window. A window
   with fewer than `agreement.MIN_SAMPLES` samples providing either field is judged with the
   next. Each counts the body messages not compared in it by their place in the body stream.

Where the twin restarts because the deck's stamps jumped back (more than
input.back_jump_reset_s: a bag played with --loop), its rows' stamps go back: the stages
restart with it, the body stream at its own jump back (`BodyCheck.screen`), each of its runs
matched with the twin's of the same rank (`_Matcher`), the window open at the jump closed as
the stream's last is. Where only one of them jumps back (`Apart`: the other's stamps went
on past the jump by more than back_jump_reset_s), the runs never pair again: a WARN says so
once, and the body samples past the pairing are counted `APART`, not held.

Beside them, `_Refusals` watches the body messages themselves, in windows of the same length
on their own stamps: a window in which every message was rejected (another frame_id, …) is a
WARN when the next begins, so that a body IMU the twin never takes shows live, not only at
the end of the stream. It depends on the body stream alone.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields
from itertools import pairwise

import numpy as np

from mount_twin.engine.agreement import (
    FIELDS,
    MIN_SAMPLES,
    NAME,
    OUTSIDE_THE_RUN,
    agreement,
    window_status,
)
from mount_twin.engine.batch import WARN, HealthStatus
from mount_twin.engine.intake import provided, rising_or_back
from mount_twin.engine.sensor_reading import SensorGeometry, predicted_reading
from mount_twin.physics import pose_row
from mount_twin.scene.description import BodySensor, Scene

RETAIN_S = 60.0
"""Predictions are kept this long (s of stamps) behind the newest for body samples still to
come (once body samples flow, only from the last one compared on): a body stream that trails
the foundation's by more loses those samples (counted `late`)."""
PENDING_LIMIT = 100_000
"""Most accepted body samples held waiting for the twin (its predictions; before the deck's
first message, its time base, `TwinStream`): a twin that stopped, a body stream fed far ahead
of the deck's. The oldest by arrival go first, counted `dropped_waiting`: which ones then
depends on how the two streams come (a replay feeds the body stream up to the deck's stamps)."""
REJECTED = (
    "undecodable",
    "nonpositive_stamp",
    "nonfinite",
    "wrong_frame_id",
    "no_reading",
    "stamp_back",
)
"""Why a body message was not taken (`BodyCheck.screen`, and undecodable; no_reading: both
its readings marked not provided): reported as body_rejected_<reason> in every window, zero
included."""
RESETS = "reset_stamp_jumped_back"
"""The count of body messages whose stamp jumped back by more than input.back_jump_reset_s,
each restarting the comparison (`BodyCheck.screen`)."""
UNPROVIDED = ("unprovided_acceleration", "unprovided_angular_velocity")
"""The counts of accepted body messages that mark their acceleration, their angular velocity
not provided (REP-145): compared on the other reading alone."""
APART = "jumped_back_apart"
MIDDLEWARE = "lost_middleware"
STOPPED = "lost_unprocessed_at_stop"
PROBLEMS = (
    "before_twin",
    "late",
    "in_gap",
    "unanswered",
    "dropped_waiting",
    MIDDLEWARE,
    STOPPED,
    APART,
)
"""Why a body sample accepted was not compared: before the twin's first row, behind the kept
predictions, inside a gap of the twin's rows, after its last row, held too long, or after the
body IMU's and the deck's stamps jumped back apart (`Apart`); and why a body message was
never received: lost by the middleware, or waiting unprocessed in the node's queue when it
was stopped a second time (STOPPED, `ros.node`)."""
NOT_COMPARED = (*(f"rejected_{r}" for r in REJECTED), *PROBLEMS)
"""Every reason a body message was not compared, in the order a window's status says them."""
WARNED_AT_END = {
    "dropped_waiting": "{} body IMU samples held too long waiting for the twin were dropped "
    "(counted {})",
    MIDDLEWARE: "{} body IMU messages lost by the middleware (counted {})",
    STOPPED: "{} body IMU messages waiting when the node was stopped again were not processed "
    "(counted {})",
}
"""The body samples lost that are not at a place in the stream (held too long; never read by
the node: lost by the middleware, left unprocessed at a second stop), by count: how a WARN at
the end of the stream says those no window reported (`_Windows.finish`)."""


class Apart:
    """Whether the deck's and the body IMU's stamps jumped back apart: the n-th runs of the
    two streams (their stamps split where they go back) are paired, and they are out of step
    once one stream has left run n (jumped back) and the other's stamps of run n have gone
    more than input.back_jump_reset_s past its last one there (a body IMU on another clock
    than the deck, a recorder restarted). In a bag played with --loop both streams jump back
    within a few ms of stamps of each other: in step. Stamps alone decide, so the answer is
    the same however the streams come batched or interleaved. The body's stamps are taken
    less body_sensor.lag_s (the motion they measured)."""

    def __init__(self, reset_s: float, lag_s: float) -> None:
        self._reset, self._lag = reset_s, lag_s
        self._run = {"deck": 0, "body": 0}
        self._ends: dict[str, dict[int, float]] = {"deck": {}, "body": {}}
        """Per stream, the latest stamp (s) of each run not yet found in step."""
        self._paired = 0
        """The first run not yet found in step."""
        self.found: tuple[str, int, float] | None = None
        """(the stream that jumped back first, 'deck' or 'body'; the run it left; its last
        stamp there, s) once out of step (None: in step so far)."""

    def add(self, stream: str, t: np.ndarray) -> None:
        """Stamps (s, on the twin's time base) of `stream` ('deck', 'body'), in its order: a
        stamp before the one before it starts a new run."""
        if not t.shape[0] or self.found is not None:
            return
        t = t - self._lag if stream == "body" else t
        ends, last = self._ends[stream], self._ends[stream].get(self._run[stream], -math.inf)
        run = self._run[stream] + np.cumsum(t < np.concatenate([[last], t[:-1]]))
        for r in np.unique(run).tolist():
            ends[r] = float(t[run == r][-1])
        self._run[stream] = int(run[-1])
        self._check()

    def _check(self) -> None:
        run = self._paired
        while self.found is None:
            left = {s: self._run[s] > run for s in self._run}
            for first, other in (("deck", "body"), ("body", "deck")):
                end = self._ends[first].get(run, math.inf) if left[first] else math.inf
                if self._ends[other].get(run, -math.inf) > end + self._reset:
                    self.found = (first, run, end)
            if self.found is not None or not all(left.values()):
                break
            for ends in self._ends.values():
                ends.pop(run, None)
            run = self._paired = run + 1

    def beyond(self, t: np.ndarray, run: np.ndarray) -> np.ndarray:
        """Of body samples (stamps s, runs), those (bool) past the pairing: in a run after the
        one the streams went apart at, or in it more than back_jump_reset_s past the deck's
        last stamp there (all False while in step)."""
        if self.found is None:
            return np.zeros(t.shape[0], bool)
        _, n, _ = self.found
        deck = self._ends["deck"].get(n, math.inf)
        return (run > n) | ((run == n) & (t - self._lag > deck + self._reset))

    def message(self) -> str:
        """What the streams did, once out of step."""
        assert self.found is not None
        first, run, end = self.found
        names = {"deck": "the deck's", "body": "the body IMU's"}
        other = names["body" if first == "deck" else "deck"]
        return (
            f"the body IMU's and the deck's stamps jumped back apart: {names[first]} jumped "
            f"back at {end:.3f} s (after its run {run}), {other} went on past "
            f"{end + self._reset:.3f} s (input.back_jump_reset_s later; the body's less "
            f"body_sensor.lag_s, s of the twin's time base): their runs no longer pair"
        )


@dataclass
class _Rows:
    """Published rows of the twin: stamps (s), pose rows, (k, n, 6) wrenches, the
    foundation's rate Ω_F at each (rad/s, F)."""

    t: np.ndarray
    pose: np.ndarray
    wrenches: np.ndarray
    rate: np.ndarray

    def __len__(self) -> int:
        return int(self.t.shape[0])

    def then(self, later: _Rows) -> _Rows:
        return _Rows(
            np.concatenate([self.t, later.t]),
            np.concatenate([self.pose, later.pose]),
            np.concatenate([self.wrenches, later.wrenches]),
            np.concatenate([self.rate, later.rate]),
        )

    def part(self, start: int, stop: int) -> _Rows:
        """Rows [start, stop) (views)."""
        return _Rows(
            self.t[start:stop],
            self.pose[start:stop],
            self.wrenches[start:stop],
            self.rate[start:stop],
        )

    def tail(self, n: int) -> _Rows:
        """The last n rows (copies: the engine reuses its buffers)."""
        k = len(self) - n
        return _Rows(
            self.t[k:].copy(), self.pose[k:].copy(), self.wrenches[k:].copy(), self.rate[k:].copy()
        )


Predict = Callable[[_Rows], np.ndarray]
_NO_PREDICTION = (np.zeros(0), np.zeros((0, 6)))


class _Lead:
    """Predictions of rows as soon as their difference stencils are whole (two rows on)."""

    HELD = 4
    """Rows kept for the next batch's stencils: two predicted already, two not yet."""

    def __init__(self, predict: Predict) -> None:
        self._predict = predict
        self._held: _Rows | None = None
        self._at_start = True

    def add(self, rows: _Rows) -> tuple[np.ndarray, np.ndarray]:
        """(stamps s, (k, 6) predictions) of the rows that `rows` completes."""
        window = rows.tail(len(rows)) if self._held is None else self._held.then(rows)
        n = len(window)
        if n < self.HELD + 1:
            self._held = window
            return _NO_PREDICTION
        first = 0 if self._at_start else 2
        values = self._predict(window)
        self._held, self._at_start = window.tail(self.HELD), False
        return window.t[first : n - 2], values[first : n - 2]

    def finish(self) -> tuple[np.ndarray, np.ndarray]:
        """The rows still held, the last by one-sided differences (fewer than 3 rows in the
        whole run: none): the end of the stream, or of the twin's run (the rows after it
        start afresh)."""
        window, self._held = self._held, None
        first = 0 if self._at_start else 2
        self._at_start = True
        if window is None or len(window) < 3:
            return _NO_PREDICTION
        return window.t[first:], self._predict(window)[first:]


class _Series:
    """A growing (stamps, (k, 6) values) series whose oldest part is dropped in place."""

    def __init__(self) -> None:
        self._t = np.zeros(1024)
        self._v = np.zeros((1024, 6))
        self._start = self._end = 0
        self.first: float | None = None
        """The first stamp ever appended (None: none yet)."""

    @property
    def t(self) -> np.ndarray:
        return self._t[self._start : self._end]

    @property
    def v(self) -> np.ndarray:
        return self._v[self._start : self._end]

    def append(self, t: np.ndarray, v: np.ndarray) -> None:
        k = t.shape[0]
        if k and self.first is None:
            self.first = float(t[0])
        if self._end + k > self._t.shape[0]:
            n = self._end - self._start
            size = max(2 * (n + k), 1024)
            self._t = np.concatenate([self.t, np.zeros(size - n)])
            self._v = np.concatenate([self.v, np.zeros((size - n, 6))])
            self._start, self._end = 0, n
        self._t[self._end : self._end + k], self._v[self._end : self._end + k] = t, v
        self._end += k

    def drop_before(self, i: int) -> None:
        """Drop the first i entries."""
        self._start += i


@dataclass
class _Taken:
    """Accepted body samples out of the matcher, in order: stamps (ns, s), measured (k, 6),
    which readings each provides ((k, 2): specific force, rate), the prediction at each (where
    compared), why each was not compared ('' where it was: `PROBLEMS`), each one's place
    among the accepted samples, and the body stream's run it is in (its stamps' jumps back
    before it)."""

    ns: np.ndarray
    t: np.ndarray
    measured: np.ndarray
    present: np.ndarray
    predicted: np.ndarray
    why: np.ndarray
    place: np.ndarray
    run: np.ndarray

    @classmethod
    def none(cls) -> _Taken:
        empty = np.zeros((0, 6))
        return cls(
            np.zeros(0, np.int64),
            np.zeros(0),
            empty,
            np.zeros((0, 2), bool),
            empty,
            np.zeros(0, object),
            np.zeros(0, np.int64),
            np.zeros(0, np.int64),
        )

    def select(self, k: np.ndarray | slice) -> _Taken:
        """Those `k` selects."""
        return _Taken(*(getattr(self, f.name)[k] for f in fields(self)))

    def compared(self) -> _Taken:
        """Those compared."""
        return self.select(self.why == "")


_Waiting = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]
"""Body samples waiting for the twin: stamps ns, stamps s, measured (k, 6), readings provided
(k, 2), the body stream's run of each."""


class _Matcher:
    """Body samples matched to the prediction at the motion they measured, run by run: the
    twin restarts where its rows' stamps go back (`_Lead` finishes the run before), the body
    stream where its stamps jump back (`BodyCheck.screen`), and the n-th run of the body
    stream is matched with the n-th run of the twin's. A body sample past the last row of a
    run the twin has ended is unanswered, as one past the stream's last row is (the two
    recorders never stop together); one of a run the twin never had a row in, before_twin."""

    def __init__(
        self, lag_s: float, max_gap_s: float, problems: Counter[str], apart: Apart
    ) -> None:
        self._lag, self._max_gap, self._problems = lag_s, max_gap_s, problems
        self._apart = apart
        self.first_apart_ns: int | None = None
        """The stamp of the first body sample counted APART, ns (None: none yet)."""
        self._pred: dict[int, _Series] = {0: _Series()}
        """The predictions of each of the twin's runs a body sample may still need."""
        self._rows_run = 0
        """The twin's run the rows come in."""
        self._body_run = 0
        """The body stream's run of the last body sample added."""
        self._last_ns = 0
        """The stamp of the last body sample added, ns."""
        self._body: list[_Waiting] = []
        self.taken = 0
        """Accepted body samples taken out so far (compared, or counted not compared): the
        place among them of the first one waiting."""

    def add_predictions(self, t: np.ndarray, v: np.ndarray) -> None:
        series = self._pred.get(self._rows_run)
        if t.shape[0] and series is not None and self._apart.found is None:
            # (None: the body stream is past this run; apart: no body sample will need it)
            series.append(t, v)

    def restart_rows(self) -> None:
        """The twin's rows start a new run (their stamps went back)."""
        self._rows_run += 1
        if self._rows_run >= self._oldest():
            self._pred[self._rows_run] = _Series()

    def add_body(self, ns: np.ndarray, t: np.ndarray, v: np.ndarray, present: np.ndarray) -> None:
        """Accepted body samples, in order (a stamp before the last starts a new run)."""
        if not ns.shape[0]:
            return
        back = ns < np.concatenate([[self._last_ns], ns[:-1]])
        run = self._body_run + np.cumsum(back)
        self._body_run, self._last_ns = int(run[-1]), int(ns[-1])
        self._body.append((ns, t, v, present, run))
        waiting = sum(c[0].shape[0] for c in self._body)
        if waiting > PENDING_LIMIT:
            cut = waiting - PENDING_LIMIT
            self._problems["dropped_waiting"] += cut
            self.taken += cut
            ns, t, v, present, run = self._waiting()
            self._body = [(ns[cut:], t[cut:], v[cut:], present[cut:], run[cut:])]

    def _waiting(self) -> _Waiting:
        """The waiting body samples in one chunk."""
        ns, t, v, present, run = (np.concatenate(a) for a in zip(*self._body, strict=True))
        return ns, t, v, present, run

    def take(self, final: bool = False) -> _Taken:
        """The body samples the predictions now decide, in order (`final`: the end of the
        stream, the rest are counted unanswered)."""
        if not self._body:
            self._forget()
            return _Taken.none()
        ns, t, v, present, run = self._waiting()
        tau = t - self._lag
        why = np.full(t.shape[0], "", dtype=object)
        pred = np.zeros((t.shape[0], 6))
        paired = int(np.argmax(beyond)) if (beyond := self._apart.beyond(t, run)).any() else None
        done = 0  # the samples decided: a prefix
        for r in np.unique(run[:paired]).tolist():
            stop = done + int((run[done:paired] == r).sum())  # runs rise
            series = self._pred.get(r) if r <= self._rows_run else None
            ended = r < self._rows_run
            if series is None or series.first is None:
                if not ended:
                    break
                why[done:stop] = "before_twin"  # the twin had no row in that run
                done = stop
                continue
            covered = done + int((tau[done:stop] <= series.t[-1]).sum())  # accepted stamps rise
            self._match(series, tau[done:covered], why[done:covered], pred[done:covered])
            if ended:
                why[covered:stop] = "unanswered"  # the twin restarted before them
                covered = stop
            done = covered
            if done < stop:
                break
        if paired is not None and done == paired:  # the rest (a suffix) will never pair
            why[paired:] = APART
            done = t.shape[0]
            if self.first_apart_ns is None:
                self.first_apart_ns = int(ns[paired])
        left = t.shape[0] - done
        if final:
            self._problems["unanswered"] += left
        rest = (ns[done:], t[done:], v[done:], present[done:], run[done:])
        self._body = [rest] if left and not final else []
        first = self.taken
        self.taken += done + (left if final else 0)
        for reason in ("before_twin", "late", "in_gap", "unanswered", APART):
            self._problems[reason] += int((why[:done] == reason).sum())
        self._forget()
        return _Taken(
            ns[:done],
            t[:done],
            v[:done],
            present[:done],
            pred[:done],
            why[:done],
            first + np.arange(done),
            run[:done],
        )

    def _match(self, series: _Series, tau: np.ndarray, why: np.ndarray, pred: np.ndarray) -> None:
        """The predictions (into `pred`, (k, 6)) of body samples measuring the motion at `tau`
        (s, rising, none past the run's last row), or why each is not compared (into `why`)."""
        if not tau.shape[0]:
            return
        assert series.first is not None
        pt, pv = series.t, series.v
        why[tau < series.first] = "before_twin"
        why[(why == "") & (tau < pt[0])] = "late"
        kept = np.flatnonzero(why == "")
        after = np.searchsorted(pt, tau[kept], side="right")
        at_row = pt[after - 1] == tau[kept]  # (after ≥ 1: tau ≥ the first row)
        # A sample at a row takes that row's prediction whichever rows come after it (were it
        # interpolated toward the next row, the row after a gap would make it in_gap or not by
        # whether that row was already published: by how the two streams came interleaved).
        pred[kept[at_row]] = pv[after[at_row] - 1]
        between = kept[~at_row]  # tau < the last row: rows on both sides
        j = after[~at_row]
        if between.shape[0]:
            t0, t1 = pt[j - 1], pt[j]
            w = ((tau[between] - t0) / (t1 - t0))[:, None]
            pred[between] = (1.0 - w) * pv[j - 1] + w * pv[j]
            why[between[(t1 - t0) > self._max_gap]] = "in_gap"
        if kept.shape[0]:
            _trim(series, float(tau[kept][-1]))

    def _oldest(self) -> int:
        """The earliest run a body sample still to be matched may be in."""
        return int(self._body[0][4][0]) if self._body else self._body_run

    def _forget(self) -> None:
        """Drop the predictions no future body sample needs: the runs before the first body
        sample waiting (none waiting: before the last added), and in each run kept those
        more than RETAIN_S behind its newest."""
        oldest = math.inf if self._apart.found is not None else self._oldest()
        for r in [r for r in self._pred if r < oldest]:
            del self._pred[r]
        for series in self._pred.values():
            _trim(series, None)


def _trim(series: _Series, last_tau: float | None) -> None:
    """Drop the predictions of `series` no future body sample needs: those before the one at
    or before the last sample compared (`last_tau`, s), and those more than RETAIN_S behind
    the newest."""
    pt = series.t
    if not pt.shape[0]:
        return
    cut = int(np.searchsorted(pt, pt[-1] - RETAIN_S, side="left"))
    if last_tau is not None:
        cut = max(cut, int(np.searchsorted(pt, last_tau, side="right")) - 1)
    series.drop_before(min(cut, pt.shape[0] - 1))


def not_compared(counts: Mapping[str, int]) -> dict[str, int]:
    """The counts of body messages not compared, by reason (`PROBLEMS`, rejected_<reason>)."""
    return {k: v for k, v in counts.items() if k in PROBLEMS or k.startswith("rejected_")}


@dataclass
class _Window:
    """The window being filled: chunks of its compared samples (stamps ns, seconds, measured,
    residual, readings provided), and the body messages not compared in it, by reason."""

    index: int
    chunks: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]]
    problems: Counter[str]


CUT_BY_END = "the last window, closed by the end of the stream"
CUT_BY_JUMP = "the last window before the body IMU's stamps jumped back"
"""How a window cut short is said (`_Windows._close`)."""
LOOSE = ("unanswered", *WARNED_AT_END)
"""Not compared for the stream's sake, not at a place in it (left at its end, held too long,
lost by the middleware, never processed at a second stop; the node counts the last two as it
learns of them): reported in the window judged next (unanswered at the end of a run the twin
restarted after: at its place; the others, WARNED_AT_END, that no window reports: in the
WARN at the end, `_Windows.finish`; unanswered at the end of the stream, said, not warned of:
in the last window where it is judged, else in that WARN where one goes out, else in the
run's counts alone)."""


class _Windows:
    """The agreement of compared samples, window by window of body stamps, and the body
    messages not compared in each: a sample where its stamp falls, a rejected message where the
    accepted sample after it does (its place in the body stream), so that neither depends on
    how the two streams come interleaved; before the first window, in the first; in a window
    too short to judge, in the next. Where the body stream's stamps jump back (a new run,
    `_Matcher`), the window open ends as the stream's last does, and the grid starts again
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

    def add(self, taken: _Taken, residual: np.ndarray) -> list[tuple[int, HealthStatus]]:
        """Reports (stamp ns, status) of the windows these samples (all taken out of the
        matcher, the compared ones' `residual` beside them) close."""
        for key in LOOSE:  # those at a place: said there
            self._loose_reported[key] += int((taken.why == key).sum())
        reports = []
        start = k = 0  # into the samples, the compared ones
        for run in np.unique(taken.run).tolist():
            stop = start + int((taken.run[start:] == run).sum())  # runs rise
            part = taken.select(slice(start, stop))
            n = int((part.why == "").sum())
            if run != self._run:
                reports += self._close(CUT_BY_JUMP)
                self._origin, self._run = None, run
            reports += self._add_run(part, residual[k : k + n])
            start, k = stop, k + n
        return reports

    def _add_run(self, taken: _Taken, residual: np.ndarray) -> list[tuple[int, HealthStatus]]:
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
        for i in np.unique(index).tolist():
            part = index == i
            if self._window is not None and self._window.index != i:
                reports += self._close()
            if self._window is None:
                self._window, self._carried = _Window(i, [], self._carried), Counter()
            window = self._window
            window.problems.update(taken.why[part & ~compared].tolist())
            self._attribute(int(taken.place[part][-1]), window.problems)
            n = int((part & compared).sum())
            if n:
                window.chunks.append(
                    (
                        taken.ns[part & compared],
                        taken.t[part & compared],
                        taken.measured[part & compared],
                        residual[k : k + n],
                        taken.present[part & compared],
                    )
                )
                k += n
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


class _Refusals:
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


@dataclass
class BodyComparison:
    """The body IMU's samples compared, and the windows judged.

    Attributes:
        stamps_ns: (k,) the compared body samples' header stamps, ns.
        predicted: (k, 6) the twin's prediction: specific force (m/s²), rate (rad/s), in the
            sensor's axes.
        residual: (k, 6) measured − predicted (nan for a reading the sample does not provide).
        present: (k, 2) which readings (specific force, rate) each sample provides.
        reports: (stamp ns, status) of each window closed.
    """

    stamps_ns: np.ndarray
    predicted: np.ndarray
    residual: np.ndarray
    present: np.ndarray
    reports: list[tuple[int, HealthStatus]]


class BodyCheck:
    """The body IMU against the twin (module docstring).

    Attributes:
        counts: body messages received, accepted and compared (and compared on each field,
            compared_<field> of `agreement.FIELDS`), the accepted ones marking a reading not
            provided (`UNPROVIDED`), and why others were not compared (`PROBLEMS`; the stream
            counts its rejections here too, as rejected_<reason>).
    """

    def __init__(self, scene: Scene, sensor: BodySensor) -> None:
        self.sensor = sensor
        compared = ("received", "accepted", "compared", *(f"compared_{f}" for f in FIELDS))
        self.counts: Counter[str] = Counter(
            dict.fromkeys((*compared, *NOT_COMPARED, *UNPROVIDED, RESETS), 0)
        )  # every key from the start: the order (of a WARN's values) never that of the feeding
        self._back_ns = round(scene.input.back_jump_reset_s * 1e9)
        self.last_ns = 0
        """The last accepted body stamp, ns (0: none yet)."""
        self._last_row_t = -np.inf
        """The stamp of the twin's last row, s."""
        self.seen_ns = 0
        """The latest stamp of any body message screened, ns (0: none with a stamp)."""
        self._accepted_screened = 0
        """Body messages screened and accepted so far, in the body stream's order."""

        geometry = SensorGeometry.of(scene, sensor)

        def predict(rows: _Rows) -> np.ndarray:
            pose = (rows.pose[:, pose_row.POSITION_COLS], rows.pose[:, pose_row.QUATERNION_COLS])
            f, w = predicted_reading(geometry, rows.t, pose, rows.wrenches, rows.rate)
            return np.hstack([f, w])

        self._lead = _Lead(predict)
        self._apart = Apart(scene.input.back_jump_reset_s, sensor.lag_s)
        self._said_apart = False
        self._matcher = _Matcher(sensor.lag_s, scene.input.max_gap_s, self.counts, self._apart)
        self._windows = _Windows(sensor, self.counts)
        self._refusals = _Refusals(sensor, self._back_ns)

    def screen(
        self,
        stamps_ns: np.ndarray,
        measured: np.ndarray,
        frame_ids: list[str],
        unprovided: np.ndarray | None = None,
    ) -> np.ndarray:
        """Why each body message (stamps ns, (k, 6) readings, header.frame_ids, and which
        readings (k, 2) its message marks not provided, `Decoded.unprovided`) cannot be
        compared ('' where it can; the caller counts the others with `reject`, at their place
        in the stream): an unset or pre-1970 stamp, a value not finite (a reading marked not
        provided is not read), a frame_id other than body_sensor.frame_id ("": any), both its
        acceleration and its rate marked not provided (REP-145: to be disregarded; a sample
        that provides one is compared on it), a stamp not after every one accepted before
        it, unless it is more than input.back_jump_reset_s before them (the body stream's run
        restarts, as the twin does where the deck's stamps jump back so: counted
        reset_stamp_jumped_back)."""
        expected = self.sensor.frame_id
        accel, rate = provided(measured[:, :3], measured[:, 3:], unprovided)
        marked = np.zeros((stamps_ns.shape[0], 2), bool) if unprovided is None else unprovided
        reasons = {
            "nonpositive_stamp": stamps_ns <= 0,
            "nonfinite": ~(np.isfinite(accel).all(axis=1) & np.isfinite(rate).all(axis=1)),
            "wrong_frame_id": np.array(
                [bool(expected) and f != expected for f in frame_ids], bool
            ),
            "no_reading": marked[:, 0] & marked[:, 1],
        }
        why = np.full(stamps_ns.shape[0], "", dtype=object)
        for reason, bad in reasons.items():
            why[bad & (why == "")] = reason
        keep = why == ""
        taken, jumped = rising_or_back(stamps_ns, keep, self.last_ns, self._back_ns)
        why[keep & ~taken] = "stamp_back"
        self.counts[RESETS] += int(jumped.sum())
        keep = why == ""
        if keep.any():
            self.last_ns = int(stamps_ns[keep][-1])
        self.seen_ns = max(self.seen_ns, int(stamps_ns.max(initial=0)))
        return why

    def screened(self, stamps_ns: np.ndarray, why: np.ndarray) -> BodyComparison:
        """Every body message as it came (stamps ns, 0 where unknown; why each was rejected,
        '' where not): each rejected one marked at its place in the body stream, and the
        windows of stamps in which none was taken, reported (nothing compared)."""
        accepted = why == ""
        before = self._accepted_screened + np.cumsum(accepted) - accepted
        self._windows.mark(before[~accepted], why[~accepted])
        self._accepted_screened += int(accepted.sum())
        empty = np.zeros((0, 6))
        return BodyComparison(
            np.zeros(0, np.int64),
            empty,
            empty,
            np.zeros((0, 2), bool),
            self._refusals.add(stamps_ns, why),
        )

    def reject(self, reason: str, n: int) -> None:
        """Count n body messages not compared, because `reason` (one of REJECTED)."""
        if reason not in REJECTED:
            raise ValueError(f"body messages rejected for {reason!r}, not one of {REJECTED}")
        self.counts[f"rejected_{reason}"] += n

    def over_limit(self, held: int) -> int:
        """How many of `held` accepted body samples, held before the twin has a time base (no
        deck message yet: `TwinStream`), are past PENDING_LIMIT: the oldest, dropped and
        counted `dropped_waiting`, as those waiting for its predictions are (`_Matcher`)."""
        cut = max(held - PENDING_LIMIT, 0)
        self.counts["dropped_waiting"] += cut
        self._matcher.taken += cut  # (their places in the body stream: before any it holds)
        return cut

    def add_rows(
        self, t: np.ndarray, pose: np.ndarray, wrenches: np.ndarray, rate: np.ndarray
    ) -> BodyComparison:
        """The twin's published rows: stamps (s), pose rows, wrenches and the foundation's
        rate (rad/s, F) at each; a row stamped before the one before it starts a new run of
        the twin (a restart where the deck's stamps jumped back)."""
        rows = _Rows(t, pose, wrenches, rate)
        self._apart.add("deck", t)
        back = set(np.flatnonzero(t < np.concatenate([[self._last_row_t], t[:-1]])).tolist())
        if t.shape[0]:
            self._last_row_t = float(t[-1])
        for start, stop in pairwise([*sorted({0, *back}), t.shape[0]]):
            if start in back:  # the twin restarted (its stamps jumped back): its run ended
                self._matcher.add_predictions(*self._lead.finish())
                self._matcher.restart_rows()
            self._matcher.add_predictions(*self._lead.add(rows.part(start, stop)))
        return self._compared()

    def add_body(
        self, ns: np.ndarray, t: np.ndarray, measured: np.ndarray, present: np.ndarray
    ) -> BodyComparison:
        """Accepted body samples: stamps (ns and s on the twin's base), (k, 6) readings, which
        of them each provides ((k, 2): specific force, rate; `screen` takes none with
        neither)."""
        self.counts["accepted"] += int(ns.shape[0])
        for key, given in zip(UNPROVIDED, present.T, strict=True):
            self.counts[key] += int((~given).sum())
        self._apart.add("body", t)
        self._matcher.add_body(ns, t, measured, present)
        return self._compared()

    def finish(self, stamp_ns: int) -> BodyComparison:
        """The end of both streams: the last rows predicted, every sample left compared or
        counted, the last window judged. A WARN of the end (`_Windows.finish`) is stamped with
        the latest body stamp seen, else (no body message read with a stamp: every one lost,
        say) `stamp_ns`, the twin's end (ns)."""
        self._matcher.add_predictions(*self._lead.finish())
        out = self._compared(final=True)
        out.reports += self._windows.finish(self.counts, self.seen_ns or stamp_ns)
        return out

    def _compared(self, final: bool = False) -> BodyComparison:
        taken = self._matcher.take(final)
        compared = taken.compared()
        self.counts["compared"] += int(compared.ns.shape[0])
        for field, given in zip(FIELDS, compared.present.T, strict=True):
            self.counts[f"compared_{field}"] += int(given.sum())
        residual = compared.measured - compared.predicted
        residual[~np.repeat(compared.present, 3, axis=1)] = np.nan
        reports = self._windows.add(taken, residual)
        stamp_ns = self._matcher.first_apart_ns
        if stamp_ns is not None and not self._said_apart:
            self._said_apart = True
            message = self._apart.message() + (
                f": the body IMU is not compared from there on (counted {APART})"
            )
            assert self._apart.found is not None
            first, _, end = self._apart.found
            values = {"jumped_back_first": first, "jumped_back_at_s": f"{end:.3f}"}
            reports.append((stamp_ns, HealthStatus(NAME, WARN, message, values)))
        return BodyComparison(compared.ns, compared.predicted, residual, compared.present, reports)
