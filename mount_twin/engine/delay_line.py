"""The delay line of `input.gyro_filter: linear_phase`: Ω filtered, f delayed alike.

A sample's filtered rate needs the N samples after it (`gyro_filter.fir_rows`), so the twin
integrates each accepted sample once N more of its run have come: the motion it integrates, Ω,
Ω′ and f of sample k, is the deck's at stamp t_k (Ω delayed by the filter's N samples, f by the
same N samples exactly), and its outputs carry sample k's stamp, N samples late.

Run edges: before a run's first sample the rate is taken as that sample's, held (a start is at
rest); at its end (a restart, a gap reset, the end of the stream) the pending samples are
integrated with the rate after them held at the last one, so every accepted sample has its
output. The filter is designed once, from the stream's first intervals (`DESIGN_SAMPLES`,
`gyro_filter.design`).

Everything depends on the accepted samples alone, in order: any batching gives the same bits.
The engine works on a `Frame` per push: the samples still pending from earlier pushes, then the
pushed ones.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

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


@dataclass
class Run:
    """Accepted samples to integrate in one go (rows of a Frame); `restart`: the first one
    starts a new state."""

    index: np.ndarray  # int64
    restart: bool


@dataclass
class Frame:
    """The samples of one push, after those still pending from earlier pushes (`offset` of
    them): stamps (s), specific force f (m/s², F), Ω (rad/s, F: the filtered rate once a row
    is integrated, raw before) per row; `stored_ids` the stream positions (among all pushed
    samples) of the pending rows, `first_id` that of the push's first sample."""

    stamps: np.ndarray
    f: np.ndarray
    w: np.ndarray
    offset: int
    stored_ids: np.ndarray
    first_id: int

    def relative(self, rows: np.ndarray) -> np.ndarray:
        """The positions of rows' samples relative to the push's first sample (negative: a
        sample of an earlier push)."""
        rel = rows - self.offset
        early = rows < self.offset
        rel[early] = self.stored_ids[rows[early]] - self.first_id
        return rel


class GyroDelay:
    """Filters Ω of accepted samples and releases them N samples late (see the module).

    Args:
        bands: (passband, stopband) edges, Hz, for `linear_phase`; None: raw (no delay).
        designed: told the design (and the stamp, s, of the interval it came from) once made.
    """

    def __init__(
        self,
        bands: tuple[float, float] | None,
        designed: Callable[[float, Design], None],
    ) -> None:
        self._bands = bands
        self._designed = designed
        self.design: Design | None = None if bands else RAW
        self._pending = np.zeros(0, dtype=np.int64)
        """Rows of the current frame accepted but not yet released, in order."""
        self._raw = np.zeros((0, 3))
        """Raw Ω of the pending samples and of up to N samples of their run before them."""
        self._restart = False
        """The pending samples' first starts a new state (its run's first release)."""
        self._stored: Frame | None = None

    @property
    def delay(self) -> int:
        """N, the delay in samples (0 until designed)."""
        return 0 if self.design is None else self.design.delay

    @property
    def pending_ids(self) -> np.ndarray:
        """The stream positions of the pending samples, in order (int64)."""
        return np.zeros(0, np.int64) if self._stored is None else self._stored.stored_ids

    def frame(self, stamps: np.ndarray, f: np.ndarray, w: np.ndarray, first_id: int) -> Frame:
        """The frame of a push: pending samples, then these (w: raw Ω, rad/s, filtered in
        place as samples are released)."""
        old = self._stored
        self._stored = None
        if old is None:
            return Frame(stamps, f, w, 0, self._pending, first_id)
        self._pending = np.arange(old.offset)
        return Frame(
            np.concatenate([old.stamps, stamps]),
            np.concatenate([old.f, f]),
            np.concatenate([old.w, w]),
            old.offset,
            old.stored_ids,
            first_id,
        )

    def close(self, frame: Frame) -> None:
        """Keep the pending rows of `frame` for the next push."""
        p = self._pending
        if p.shape[0]:
            ids = frame.first_id + p - frame.offset
            early = p < frame.offset
            ids[early] = frame.stored_ids[p[early]]
            self._stored = Frame(frame.stamps[p], frame.f[p], frame.w[p], p.shape[0], ids, 0)

    def feed(self, run: Run, frame: Frame) -> list[Run]:
        """Take a run of accepted samples (batch positions); the runs now ready to integrate
        (frame rows, their Ω filtered in frame.w)."""
        rows = run.index + frame.offset
        if self.delay == 0 and self.design is not None and not self._pending.shape[0]:
            return [Run(rows, run.restart)] if rows.shape[0] else []
        ready = self.drain(frame) if run.restart else []
        if run.restart:
            self._restart, self._raw = True, np.zeros((0, 3))
        self._pending = np.concatenate([self._pending, rows])
        self._raw = np.concatenate([self._raw, frame.w[rows]])
        self._design(frame, DESIGN_SAMPLES)
        if self.design is not None:
            ready.extend(self._release(self._pending.shape[0] - self.delay, frame, end=False))
        return ready

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
        rate_hz = 1.0 / float(np.median(np.diff(stamps)))
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
        half = (self.design or RAW).half
        delay = half.shape[0] - 1
        raw, pending = self._raw, self._pending
        before = raw.shape[0] - pending.shape[0]
        parts = [np.repeat(raw[:1], delay - before, axis=0), raw]
        if end:
            parts.append(np.repeat(raw[-1:], delay, axis=0))
        out = np.empty((3, n))
        fir_rows(np.ascontiguousarray(np.concatenate(parts).T), half, out)
        rows = pending[:n]
        frame.w[rows] = out.T
        self._pending = pending[n:]
        self._raw = raw[max(0, before + n - delay) :]
        released = Run(rows, self._restart)
        self._restart = False
        return [released]
