"""Body samples matched to the twin's prediction at the motion they measured (`Matcher`), the
second stage of the body IMU's check (`body_check`): run by run, at a row or interpolated
between the rows around it, else counted not compared (`body_counts.PROBLEMS`); predictions kept
`RETAIN_S` behind the newest, body samples held waiting at most `PENDING_LIMIT`."""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, fields

import numpy as np

from mount_twin.engine.body_counts import APART
from mount_twin.engine.stamp_runs import Apart

RETAIN_S = 60.0
"""Predictions are kept this long (s of stamps) behind the newest for body samples still to
come (once body samples flow, only from the last one compared on): a body stream that trails
the foundation's by more loses those samples (counted `late`)."""
PENDING_LIMIT = 100_000
"""Most accepted body samples held waiting for the twin (its predictions; before the deck's
first message, its time base, `TwinStream`): a twin that stopped, a body stream fed far ahead
of the deck's. The oldest by arrival go first, counted `dropped_waiting`: which ones then
depends on how the two streams come (a replay feeds the body stream up to the deck's stamps)."""


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
class Taken:
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
    def none(cls) -> Taken:
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

    def __len__(self) -> int:
        return int(self.t.shape[0])

    def select(self, k: np.ndarray | slice) -> Taken:
        """Those `k` selects."""
        return Taken(*(getattr(self, f.name)[k] for f in fields(self)))

    def compared(self) -> Taken:
        """Those compared (all of them, as they usually are: these)."""
        compared = self.why == ""
        return self if compared.all() else self.select(compared)


_Waiting = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]
"""Body samples waiting for the twin: stamps ns, stamps s, measured (k, 6), readings provided
(k, 2), the body stream's run of each."""


class Matcher:
    """Body samples matched to the prediction at the motion they measured, run by run: the
    twin restarts where its rows' stamps go back (`Lead` finishes the run before), the body
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
        self._held = 0
        """Body samples waiting (in `_body`)."""
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
        self._held += ns.shape[0]
        if self._held > PENDING_LIMIT:
            cut, self._held = self._held - PENDING_LIMIT, PENDING_LIMIT
            self._problems["dropped_waiting"] += cut
            self.taken += cut
            ns, t, v, present, run = self._waiting()
            self._body = [(ns[cut:], t[cut:], v[cut:], present[cut:], run[cut:])]

    def _waiting(self) -> _Waiting:
        """The waiting body samples in one chunk."""
        ns, t, v, present, run = (np.concatenate(a) for a in zip(*self._body, strict=True))
        return ns, t, v, present, run

    def take(self, final: bool = False) -> Taken:
        """The body samples the predictions now decide, in order (`final`: the end of the
        stream, the rest are counted unanswered)."""
        if not (self._body and (final or self._decides())):
            self._forget()
            return Taken.none()
        if not final:
            one = self._take_one()
            if one is not None:
                return one
        ns, t, v, present, run = self._waiting()
        tau = t - self._lag
        why = np.full(t.shape[0], "", dtype=object)
        pred = np.zeros((t.shape[0], 6))
        paired = int(np.argmax(beyond)) if (beyond := self._apart.beyond(t, run)).any() else None
        done = 0  # the samples decided: a prefix
        for r in sorted(set(run[:paired].tolist())):
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
        self._held = left if not final else 0
        first = self.taken
        self.taken += done + (left if final else 0)
        for reason, n in Counter(why[:done].tolist()).items():
            if reason:
                self._problems[reason] += n
        self._forget()
        return Taken(
            ns[:done],
            t[:done],
            v[:done],
            present[:done],
            pred[:done],
            why[:done],
            first + np.arange(done),
            run[:done],
        )

    def _take_one(self) -> Taken | None:
        """`take` where the predictions decide the first body sample waiting and not the next
        (the live stream's usual case: a wake-up's row decides the sample it reaches), its run
        the twin's run the rows come in, the streams in step (None: otherwise, for `take` to
        decide): `_match` on it alone, the others left waiting as they are, without `take`'s
        concatenation of the waiting chunks."""
        all_ns, all_t, all_v, all_present, all_run = self._body[0]
        ns, t, v, present, run = all_ns[:1], all_t[:1], all_v[:1], all_present[:1], all_run[:1]
        series = self._pred.get(self._rows_run)
        if self._apart.found is not None or int(run[0]) != self._rows_run or series is None:
            return None
        assert series.first is not None  # (`_decides`: the run has rows, one at or past it)
        pt = series.t
        rest = (all_ns[1:], all_t[1:], all_v[1:], all_present[1:], all_run[1:])
        waiting = ([rest] if rest[0].shape[0] else []) + self._body[1:]
        if waiting:  # the next decided too? (if not, none after it: a run's stamps rise)
            _, t_next, _, _, run_next = waiting[0]
            if run_next[0] == run[0] and float(t_next[0]) - self._lag <= pt[-1]:
                return None
        why = np.array([""], object)
        predicted = np.zeros((1, 6))
        self._match(series, t - self._lag, why, predicted)
        if why[0]:
            self._problems[why[0]] += 1
        self._body, self._held = waiting, self._held - 1
        place = np.array([self.taken])
        self.taken += 1
        self._forget()
        return Taken(ns, t, v, present, predicted, why, place, run)

    def _decides(self) -> bool:
        """Whether the predictions may decide the first body sample waiting now (False: the
        streams in step, and its run's rows not yet at the motion it measured, or none yet)."""
        if self._apart.found is not None:
            return True
        _, t, _, _, run = self._body[0]
        r = int(run[0])
        if r < self._rows_run:  # the twin ended its run
            return True
        series = self._pred.get(r) if r == self._rows_run else None
        if series is None or series.first is None:
            return False
        return float(t[0]) - self._lag <= series.t[-1]  # (the run's stamps rise)

    def _match(self, series: _Series, tau: np.ndarray, why: np.ndarray, pred: np.ndarray) -> None:
        """The predictions (into `pred`, (k, 6)) of body samples measuring the motion at `tau`
        (s, rising, none past the run's last row), or why each is not compared (into `why`)."""
        if not tau.shape[0]:
            return
        assert series.first is not None
        pt, pv = series.t, series.v
        before = tau < series.first
        late = ~before & (tau < pt[0])
        why[before] = "before_twin"
        why[late] = "late"
        kept = np.flatnonzero(~(before | late))
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
