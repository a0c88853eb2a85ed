"""The delay line of `input.gyro_filter: linear_phase`: Ω filtered, f delayed alike; and a
start's gravity window held back until it has come.

A sample's filtered rate needs the N samples after it (`gyro_filter.fir_rows`), so the twin
integrates each accepted sample once N more of its run have come: the motion it integrates, Ω,
Ω′ and f of sample k, is the deck's at stamp t_k (Ω delayed by the filter's N samples, f by the
same N samples exactly), and its outputs carry sample k's stamp, N samples late.

Run edges: before a run's first sample the rate is taken as that sample's, held (a start is at
rest); at its end (a restart, a gap reset, the end of the stream) the pending samples are
integrated with the rate after them held at the last one, so every accepted sample has its
output. A run's first release waits, besides, until its start's gravity window has come
(`initial_state.gravity_window_s`, `starts.start_takes`), so that the start takes the same
samples in any batching: those of the window still in the filter's delay go with it
(`Run.ahead`), so the hold is the longer of the window and the delay, not their sum; without
a filter (no delay) the window is the only hold. The filter is
designed once, from the stream's first intervals (`DESIGN_SAMPLES`, `gyro_filter.design`).

Everything depends on the accepted samples alone, in order: any batching gives the same bits.
The engine works on a `Frame` per push: the samples still pending from earlier pushes, then the
pushed ones. A live node pushes a few samples at a time, so neither is copied whole per push:
the pending samples wait in arrays with room after them (`Backlog`), a push of a few samples
is appended there, and the raw Ω the filter reads likewise (`RawWindow`); both move to their
arrays' start only when the room is used up, into smaller arrays there once a large push's
samples are gone (`Extent`).
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from mount_twin.engine.gyro_filter import Design, design, fir_rows
from mount_twin.scene.description import InputSpec

RAW = Design(np.ones(1), math.nan, "")
"""No filter, no delay (`gyro_filter: none` and `ignore`)."""
DESIGN_SAMPLES = 8
"""The filter is designed from the median interval of the stream's first this many accepted
samples (fewer if its first run ends sooner): one odd interval, a stamp 1e-16 s after the one
before, cannot set it (it did: a 4.5e15 Hz design asked for petabytes)."""
MAX_RATE_HZ = 1.0e6
"""Above this sample rate (no shock or motion sensor samples faster) the gyro is taken raw,
with a note, rather than filtered by a design of that many taps."""
ROOM = 256
"""Samples of room a store keeps beside its contents, at least, when it moves them to its
arrays' start: a push of one sample moves the pending ones once every ROOM pushes or less
often (`Extent`)."""
STAMP_SLACK_S = 1e-9
"""s: a sample this much past `initial_state.gravity_window_s` after a start sample is within
the start's window (a ROS stamp's resolution: float stamps lose a few ulps in differences)."""
LARGE = 4096
"""A push of more samples than this gets a frame of its own (the pending samples and these
concatenated: one copy of each either way), not a backlog that large kept between pushes."""


class Extent:
    """How many samples a store's arrays (`Backlog`, `RawWindow`) are to hold, decided when
    its contents move to their start (the room used up): twice the most a push has asked
    them to hold since the last move, plus ROOM, where they are smaller than what this move
    needs with ROOM to spare (they grow) or more than twice that (they shrink back); else
    their size. Moves come once the room is used up, so the arrays shrink after as many
    samples as a large push left room for (a replay chunk of 100 000: the 100 000 after it),
    and pushes of mixed sizes keep them at the largest (a large push after small ones finds
    its room, or asks at its move): they never grow and shrink at every push."""

    def __init__(self) -> None:
        self._peak = 0
        """The most a push has asked the arrays to hold since their last move (samples)."""

    def asked(self, need: int) -> None:
        """A push asks the arrays to hold `need` samples (its own and those kept)."""
        self._peak = max(self._peak, need)

    def moved(self, need: int, have: int) -> int:
        """The samples to give arrays of `have` at a move that must hold `need`."""
        fit = 2 * max(self._peak, need) + ROOM
        self._peak = 0
        return have if need + ROOM <= have <= 2 * fit else fit


def filter_bands(spec: InputSpec) -> tuple[float, float] | None:
    """(passband, stopband) edges, Hz, of the scene's `linear_phase` filter; None: no filter."""
    if spec.gyro_filter != "linear_phase":
        return None
    return spec.gyro_passband_hz, spec.gyro_stopband_hz


def delay_samples(spec: InputSpec, rate_hz: float) -> int:
    """Samples by which the scene's gyro conditioning delays the outputs of a `rate_hz` stream
    (what a live caller gets only at the end of the stream, `TwinEngine.flush`)."""
    bands = filter_bands(spec)
    return 0 if bands is None else design(rate_hz, *bands).delay


def conditioned_rates(
    bands: tuple[float, float], stamps: np.ndarray, w: np.ndarray, restarts: Sequence[int] = ()
) -> np.ndarray:
    """Ω of a whole record (rad/s, (n, 3), in any fixed axes) as the delay line hands it to the
    twin where every sample is accepted and the twin restarts at the samples `restarts`
    (positions, increasing): filtered by the design `bands` (`filter_bands`) makes from the
    record's first intervals, each run's edges held (`GyroDelay`: the same code); w is not
    changed."""
    delay = GyroDelay(bands, lambda stamp, design: None)
    out = np.array(w, dtype=np.float64)
    frame = delay.frame(stamps, np.zeros_like(out), out, 0)
    for run in np.split(np.arange(out.shape[0]), list(restarts)):
        delay.feed(Run(run, restart=True), frame)
    delay.drain(frame)
    return out


_NO_ROWS = np.zeros(0, dtype=np.int64)
"""No frame rows (a `Run` with none ahead)."""


def _consecutive(rows: np.ndarray) -> slice | np.ndarray:
    """Frame rows (increasing) as a slice where they are consecutive, as they are wherever
    every sample is accepted: a view rather than a gather or scatter of their rows (29 µs of
    a 2500-row run)."""
    n = rows.shape[0]
    if n and int(rows[-1]) - int(rows[0]) == n - 1:
        return slice(int(rows[0]), int(rows[0]) + n)
    return rows


@dataclass
class Run:
    """Accepted samples to integrate in one go (rows of a Frame); `restart`: the first one
    starts a new state; `ahead`: at a restart, the rows of its run's samples still pending
    after it (the gyro filter's N), whose specific forces a start's gravity window may take."""

    index: np.ndarray  # int64
    restart: bool
    ahead: np.ndarray = field(default_factory=lambda: _NO_ROWS)


@dataclass
class Frame:
    """The samples of one push, after those still pending from earlier pushes (`offset` of
    them): stamps (s), specific force f (m/s², F), Ω (rad/s, F: the filtered rate once a row
    is integrated, raw before) per row; `ids` their stream positions (among all pushed
    samples, int64), `first_id` that of the push's first sample."""

    stamps: np.ndarray
    f: np.ndarray
    w: np.ndarray
    offset: int
    ids: np.ndarray
    first_id: int

    def relative(self, rows: np.ndarray) -> np.ndarray:
        """The positions of rows' samples relative to the push's first sample (negative: a
        sample of an earlier push)."""
        return self.ids[rows] - self.first_id


class Backlog:
    """The samples pending between pushes (stamps s, f m/s², Ω rad/s and stream positions)
    in arrays with room after them, and the frame of a push: the pushed samples appended
    into that room (a push of up to LARGE samples), so a push costs its own samples' copies,
    not the pending ones'. A frame built here is valid until `keep`."""

    def __init__(self) -> None:
        self._t = np.empty(0)
        self._f = np.empty((0, 3))
        self._w = np.empty((0, 3))
        self._ids = np.empty(0, np.int64)
        self._lo = 0
        """Row of the arrays where the pending samples (or the frame) start."""
        self._n = 0
        """Samples pending (0 once a frame has taken them)."""
        self._framed = False
        """The last frame lies in these arrays, from row `_lo`."""
        self._extent = Extent()

    @property
    def ids(self) -> np.ndarray:
        """The stream positions of the pending samples, in order (int64, a copy)."""
        return self._ids[self._lo : self._lo + self._n].copy()

    def frame(self, stamps: np.ndarray, f: np.ndarray, w: np.ndarray, first_id: int) -> Frame:
        """The frame of a push: the pending samples (taken: none are pending until `keep`),
        then these: the pushed arrays themselves where none are pending, else copies."""
        n, m = self._n, stamps.shape[0]
        self._n, self._framed = 0, False
        ids = np.arange(first_id, first_id + m)
        if not n:
            return Frame(stamps, f, w, 0, ids, first_id)
        lo = self._lo
        kept = slice(lo, lo + n)
        if m > LARGE:
            return Frame(
                np.concatenate([self._t[kept], stamps]),
                np.concatenate([self._f[kept], f]),
                np.concatenate([self._w[kept], w]),
                n,
                np.concatenate([self._ids[kept], ids]),
                first_id,
            )
        self._extent.asked(n + m)
        lo = self._room(n, m)
        hi = lo + n + m
        new = slice(lo + n, hi)
        self._t[new], self._f[new], self._w[new], self._ids[new] = stamps, f, w, ids
        self._framed = True
        return Frame(self._t[lo:hi], self._f[lo:hi], self._w[lo:hi], n, self._ids[lo:hi], first_id)

    def keep(self, frame: Frame, rows: np.ndarray) -> None:
        """Keep the rows `rows` (increasing) of the last frame pending: where they are its
        last rows and it lies here, where they are; else copied to the arrays' start."""
        k, size = rows.shape[0], frame.stamps.shape[0]
        self._n = k
        if not k:
            return
        if self._framed and int(rows[0]) == size - k:
            self._lo += size - k
            return
        t, f, w, ids = frame.stamps[rows], frame.f[rows], frame.w[rows], frame.ids[rows]
        self._lo = 0
        self._room(0, k)
        self._t[:k], self._f[:k], self._w[:k], self._ids[:k] = t, f, w, ids

    def _room(self, n: int, m: int) -> int:
        """Room for m samples after the n from row `_lo`: they are moved to row 0 (into
        arrays of another size where `Extent` says) unless the room is there; returns their
        row."""
        lo = self._lo
        if lo + n + m <= self._t.shape[0]:
            return lo
        old = (self._t, self._f, self._w, self._ids)
        size = self._extent.moved(n + m, self._t.shape[0])
        if size != self._t.shape[0]:
            self._t, self._f, self._w = np.empty(size), np.empty((size, 3)), np.empty((size, 3))
            self._ids = np.empty(size, np.int64)
        for a, b in zip((self._t, self._f, self._w, self._ids), old, strict=True):
            a[:n] = b[lo : lo + n]
        self._lo = 0
        return 0


class RawWindow:
    """Raw Ω (rad/s, (3, ·): one row per axis, as `fir_rows` reads it) of the pending
    samples and of up to N of their run before them, in arrays with room before and after
    (the run's first sample held before it, its last after it at the end), so that a push
    appends its own samples and the filter reads one copy."""

    def __init__(self) -> None:
        self._raw = np.empty((3, 0))
        self._lo = 0
        self._hi = 0
        self._extent = Extent()

    @property
    def size(self) -> int:
        """Samples in the window."""
        return self._hi - self._lo

    def clear(self) -> None:
        """A new run: nothing before its first sample."""
        self._hi = self._lo

    def append(self, w: np.ndarray) -> None:
        """Append samples (n, 3) of Ω (rad/s)."""
        m = w.shape[0]
        self._extent.asked(self.size + m)
        self._room(0, m)
        self._raw[:, self._hi : self._hi + m] = w.T
        self._hi += m

    def filtered(self, half: np.ndarray, n: int, before: int, *, end: bool) -> np.ndarray:
        """Ω filtered by `half` (N + 1 taps) of the n samples after the window's first
        `before` (3, n): the run's first sample held before it where fewer than N are
        before them, its last after them with `end`. The n leave the window's filter
        history: N samples are left before the rest."""
        delay = half.shape[0] - 1
        front, back = delay - before, delay if end else 0
        self._room(front, back)
        raw, lo, hi = self._raw, self._lo, self._hi
        if front:
            raw[:, lo - front : lo] = raw[:, lo : lo + 1]
        if back:
            raw[:, hi : hi + back] = raw[:, hi - 1 : hi]
        self._lo = lo - front
        out = np.empty((3, n))
        fir_rows(raw[:, self._lo : self._lo + n + 2 * delay].copy(), half, out)
        self._lo += n
        return out

    def _room(self, front: int, back: int) -> None:
        """Room for `front` samples before the window and `back` after it: the window moved
        to column `front` (into arrays of another size where `Extent` says) unless the room
        is there."""
        lo, hi = self._lo, self._hi
        if lo >= front and hi + back <= self._raw.shape[1]:
            return
        old, size = self._raw, hi - lo
        columns = self._extent.moved(front + size + back, old.shape[1])
        if columns != old.shape[1]:
            self._raw = np.empty((3, columns))
        self._raw[:, front : front + size] = old[:, lo:hi]
        self._lo, self._hi = front, front + size


class GyroDelay:
    """Filters Ω of accepted samples and releases them N samples late (see the module); a
    run's first release waits until its start's samples have come.

    Args:
        bands: (passband, stopband) edges, Hz, for `linear_phase`; None: raw (no delay).
        designed: told the design (and the stamp, s, of the interval it came from) once made.
        takes: (samples, s) a start's gravity is the mean of (`starts.start_takes`): where
            s > 0, a run is held back until a sample lies more than s (and STAMP_SLACK_S)
            after its start sample (the samples-th), or the run ends, so that the start has
            every sample of its window in any batching (those still pending in `Run.ahead`).
    """

    def __init__(
        self,
        bands: tuple[float, float] | None,
        designed: Callable[[float, Design], None],
        takes: tuple[int, float] = (1, 0.0),
    ) -> None:
        self._bands = bands
        self._designed = designed
        self._takes = takes
        self.design: Design | None = None if bands else RAW
        self._pending = np.zeros(0, dtype=np.int64)
        """Rows of the current frame accepted but not yet released, in order."""
        self._raw = RawWindow()
        """Raw Ω of the pending samples and of up to N samples of their run before them."""
        self._restart = False
        """The pending samples' first starts a new state (its run's first release)."""
        self._backlog = Backlog()

    @property
    def delay(self) -> int:
        """N, the delay in samples (0 until designed)."""
        return 0 if self.design is None else self.design.delay

    @property
    def pending_ids(self) -> np.ndarray:
        """The stream positions of the pending samples, in order (int64)."""
        return self._backlog.ids

    def frame(self, stamps: np.ndarray, f: np.ndarray, w: np.ndarray, first_id: int) -> Frame:
        """The frame of a push: pending samples, then these (w: raw Ω, rad/s, filtered in
        place as samples are released). Valid until `close`."""
        frame = self._backlog.frame(stamps, f, w, first_id)
        self._pending = np.arange(frame.offset)
        return frame

    def close(self, frame: Frame) -> None:
        """Keep the pending rows of `frame` for the next push (the last use of `frame`: its
        arrays may be written over after this)."""
        self._backlog.keep(frame, self._pending)

    def feed(self, run: Run, frame: Frame) -> list[Run]:
        """Take a run of accepted samples (batch positions); the runs now ready to integrate
        (frame rows, their Ω filtered in frame.w)."""
        rows = run.index + frame.offset
        direct = not (run.restart and self._takes[1] > 0.0)
        if self.delay == 0 and self.design is not None and not self._pending.shape[0] and direct:
            return [Run(rows, run.restart)] if rows.shape[0] else []
        ready = self.drain(frame) if run.restart else []
        if run.restart:
            self._restart = True
            self._raw.clear()
        self._pending = np.concatenate([self._pending, rows])
        self._raw.append(frame.w[_consecutive(rows)])
        self._design(frame, DESIGN_SAMPLES)
        if self.design is not None:
            ready.extend(self._release(self._releasable(frame), frame, end=False))
        return ready

    def _releasable(self, frame: Frame) -> int:
        """Pending samples that may go: all but the last N (the filter's), and none of a run
        not yet released before one lies past its start's window (`takes`): the window's
        samples are then those released and those still pending (`Run.ahead`), so the start
        waits for the longer of the window and the filter's delay, not for both."""
        n = self._pending.shape[0] - self.delay
        samples, window_s = self._takes
        if not (self._restart and window_s > 0.0) or n <= 0:
            return n
        if n <= samples:
            return 0
        stamps = frame.stamps
        start, last = stamps[self._pending[samples - 1]], stamps[self._pending[-1]]
        return n if last > start + window_s + STAMP_SLACK_S else 0

    def drain(self, frame: Frame) -> list[Run]:
        """Release every pending sample, the rate after the last held at its value (a run's
        end)."""
        self._design(frame, 2)
        return self._release(self._pending.shape[0], frame, end=True)

    def _design(self, frame: Frame, samples: int) -> None:
        """Design the filter, once, from the median interval of the first DESIGN_SAMPLES
        pending samples, once `samples` of them are there (2 at a run's end)."""
        if self.design is not None or self._pending.shape[0] < samples:
            return
        stamps = frame.stamps[self._pending[:DESIGN_SAMPLES]]
        rate_hz = 1.0 / statistics.median(np.diff(stamps).tolist())  # np.median's number
        if rate_hz > MAX_RATE_HZ:
            note = (
                f"sample rate {rate_hz:.4g} Hz is above {MAX_RATE_HZ:g} Hz: the gyro is taken raw"
            )
            self.design = Design(np.ones(1), rate_hz, note)
        else:
            self.design = design(rate_hz, *self._bands)  # type: ignore[misc]
        self._designed(float(stamps[-1]), self.design)

    def _release(self, n: int, frame: Frame, *, end: bool) -> list[Run]:
        """The first n pending samples, their Ω filtered into frame.w."""
        if n <= 0:
            return []
        pending = self._pending
        before = self._raw.size - pending.shape[0]
        out = self._raw.filtered((self.design or RAW).half, n, before, end=end)
        rows = pending[:n]
        frame.w[_consecutive(rows)] = out.T
        self._pending = pending[n:]
        released = Run(rows, self._restart, self._pending if self._restart else _NO_ROWS)
        self._restart = False
        return [released]
