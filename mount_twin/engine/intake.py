"""Input intake: a pushed batch's samples screened, rotated into F and judged, push by push.

Each sample gets a verdict (`stamp_verdicts`): taken (ACCEPT, a START or restart, a gap
bridged or reset), held back (HOLD: a stamp jump to confirm), or rejected for a reason
(non_finite, wrong_frame, duplicate_stamp, ...; its readings by `reading_screen`). Taken
samples are grouped into runs split at restarts; the stamp intervals into them feed the
lost-sample estimate; readings at the sensor's full scale or on a plateau are flagged; the
verdicts are counted. The twin itself is not touched here (`engine.TwinEngine` drives it).
"""

from __future__ import annotations

import math
from collections import Counter
from typing import NamedTuple

import numpy as np

from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.delay_line import Run
from mount_twin.engine.health import HealthWindow
from mount_twin.engine.input_status import PLATEAU_G, SATURATION_SHARE
from mount_twin.engine.reading_screen import (
    READING_LIMIT,
    all_axes,
    any_axis,
    provided,
    readable,
    rotated,
)
from mount_twin.engine.stamp_verdicts import (
    ACCEPT,
    GAP_BRIDGED,
    GAP_RESET,
    HOLD,
    JUMP_FACTOR,
    JUMPED_BACK,
    RESTARTS,
    START,
    stamp_verdict,
)
from mount_twin.model.assemble import Model

_INTERVALS = frozenset((ACCEPT, GAP_RESET, GAP_BRIDGED))
"""Verdicts whose interval from the previous taken sample enters the lost-sample estimate: a
gap is input lost (the samples a sensor would have sent in it), however the twin goes on."""

_COUNTS = {
    ACCEPT: ("accepted",),
    START: ("accepted",),
    JUMPED_BACK: ("accepted", "reset_stamp_jumped_back"),
    GAP_RESET: ("accepted", "gaps"),
    GAP_BRIDGED: ("accepted", "gaps"),
}
"""Counters each taken verdict increments; a rejection increments rejected_<reason>."""


class Intervals(NamedTuple):
    """Stamp intervals of a pushed batch, for the lost-sample estimate.

    steps: (n,) per sample with a plain ACCEPT or a gap verdict (`_INTERVALS`), the interval (s)
        from the previous taken sample; NaN for the other samples.
    skipped: sample → samples rejected since the previous taken one, where not 0 (those
        samples only).
    plain: every sample has a plain ACCEPT verdict (no NaN in steps).
    """

    steps: np.ndarray
    skipped: dict[int, int]
    plain: bool

    def between(self, start: int, stop: int) -> tuple[np.ndarray, dict[int, int]]:
        """The intervals into the taken samples in [start, stop) and the rejected samples
        before them (keyed by position among those intervals), as the health window takes
        them."""
        steps = self.steps[start:stop]
        skipped = {i - start: n for i, n in self.skipped.items() if start <= i < stop}
        if self.plain:
            return steps, skipped
        keep = ~np.isnan(steps)
        position = np.cumsum(keep) - 1  # among the kept steps
        return steps[keep], {int(position[i]): n for i, n in skipped.items()}


class Judged(NamedTuple):
    """A pushed batch as intake judged it.

    f, w: (n, 3) specific force (m/s²) and Ω (rad/s) in F per sample (zero where unreadable).
    verdicts: per sample (the last may be HOLD).
    due: the samples after which a diagnostics report is due.
    intervals: the stamp intervals for the lost-sample estimate.
    suspect: per flag ('saturated', 'plateau'), (n,) bool of the samples it flags.
    """

    f: np.ndarray
    w: np.ndarray
    verdicts: list[str]
    due: list[int]
    intervals: Intervals
    suspect: dict[str, np.ndarray]


def runs(verdicts: list[str], start: int, stop: int) -> list[Run]:
    """Group the taken samples in [start, stop) into runs split at restarts."""
    segment = verdicts[start:stop]
    if not segment:
        return []
    head = segment[0]
    restart = head in RESTARTS
    if (head == ACCEPT or restart) and segment.count(ACCEPT) == len(segment) - restart:
        # the usual cases, without a Python loop: all accepted, or a start and the rest
        return [Run(np.arange(start, stop), restart)]
    grouped: list[tuple[list[int], bool]] = []
    for i in range(start, stop):
        verdict = verdicts[i]
        if verdict not in _COUNTS:
            continue
        if verdict in RESTARTS or not grouped:
            grouped.append(([i], verdict in RESTARTS))
        else:
            grouped[-1][0].append(i)
    return [Run(np.array(index, dtype=np.int64), restart) for index, restart in grouped]


class Intake:
    """Judges the samples of a stream, push by push, for one model.

    Args:
        model: the assembled scene (its input spec and sensor rotation).
        health: the health window: its report cadence, and where intervals and wrong frames go.
        counts: the engine's counters (received, accepted, rejected_<reason>, ...).
    """

    def __init__(self, model: Model, health: HealthWindow, counts: Counter[str]) -> None:
        self.spec = model.scene.input
        self._rot = model.sensor_rotation
        self._aligned = bool(np.array_equal(self._rot, np.eye(3)))
        """The sensor's axes are F's: readings are taken as they are (as floats, copied)."""
        self._gravity_up = np.array([0.0, 0.0, self.spec.g])
        self._health = health
        self._counts = counts
        self.last_stamp: float | None = None
        """Stamp (s) of the last taken sample (None before the first)."""
        self._last_step: float | None = None
        """Interval (s) into the last taken sample from the one before (None after a start)."""
        self.held: SampleBatch | None = None
        """A sample held back at the end of the last push (a jump to confirm, see JUMP_FACTOR)."""
        self._last_reading = np.full(3, np.nan)
        """The last accelerometer reading pushed and not held back (sensor frame, m/s²)."""
        self.skipped = 0
        """Samples rejected since the last taken one: they fill a stamp hole, are not lost."""

    def judge(self, batch: SampleBatch) -> Judged:
        """Screen, classify and flag a non-empty batch (any held sample first)."""
        f, w, finite = self.screen(batch)
        verdicts, due, intervals = self._classify(batch, finite)
        return Judged(f, w, verdicts, due, intervals, self._suspect_readings(batch))

    def tally(self, batch: SampleBatch, judged: Judged, start: int, stop: int) -> None:
        """Count the verdicts and flags of samples [start, stop) and hand their stamp
        intervals and wrong frames to the health window."""
        for what, flags in judged.suspect.items():
            if n_flagged := int(np.count_nonzero(flags[start:stop])):  # a quarter of .sum()'s
                self._counts[what] += n_flagged
        verdicts = judged.verdicts
        if self._count(verdicts[start:stop]):
            self._health.add_wrong_frames(
                [batch.frame_ids[i] for i in range(start, stop) if verdicts[i] == "wrong_frame"]
            )
        self._health.add_intervals(*judged.intervals.between(start, stop))

    def screen(self, batch: SampleBatch) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Specific force (m/s²) and Ω (rad/s) in F per sample, and which samples are finite:
        a finite stamp and readings within ±READING_LIMIT (a reading marked not provided is
        taken as 0 here: the sample's verdict says whether it can do without it).

        Other readings are zeroed before the rotation, which would otherwise warn (numpy
        RuntimeWarning: inf·0, inf − inf, overflow); their samples are rejected anyway.
        """
        accel, gyro = provided(batch.accel, batch.gyro, batch.unprovided)  # `_verdict` judges
        finite = np.isfinite(batch.stamps)
        # NaN compares false: one test for NaN, ±inf and the absurdly large.
        if not (np.abs(accel).max() <= READING_LIMIT and np.abs(gyro).max() <= READING_LIMIT):
            ok = readable(accel, gyro)
            accel = np.where(ok[:, None], accel, 0.0)
            gyro = np.where(ok[:, None], gyro, 0.0)
            finite &= ok
        f = self._into_f(accel)
        if not self.spec.includes_gravity:
            f = f + self._gravity_up
        if not self.spec.reads_rate:  # the foundation's rotation neglected
            return f, np.zeros_like(f), finite
        return f, self._into_f(gyro), finite

    def _into_f(self, rows: np.ndarray) -> np.ndarray:
        """(n, 3) sensor-frame readings in F: a new float array (the gyro's is filtered in
        place later), rotated unless the sensor is aligned with F."""
        return np.array(rows, dtype=np.float64) if self._aligned else rotated(rows, self._rot)

    def _suspect_readings(self, batch: SampleBatch) -> dict[str, np.ndarray]:
        """Per sample (bool, not held back): 'saturated', a reading at the sensor's full scale;
        'plateau', an accelerometer reading beyond PLATEAU_G repeated from the sample before.
        Such samples are taken (their value is the best there is) but counted and reported."""
        spec = self.spec
        accel, n = batch.accel, len(batch)
        saturated = np.zeros(n, dtype=bool)
        for reading, full_scale in (
            (accel, spec.accel_range_m_s2),
            (batch.gyro, spec.gyro_range_rad_s),
        ):
            if full_scale > 0.0:
                saturated |= any_axis(np.abs(reading) >= SATURATION_SHARE * full_scale)
        before = np.concatenate([self._last_reading[None, :], accel[:-1]])
        plateau = all_axes(accel == before)  # repeated exactly; beyond PLATEAU_G too:
        if plateau.any():
            with np.errstate(invalid="ignore", over="ignore"):
                beyond = np.linalg.norm(accel[plateau], axis=1) > PLATEAU_G * spec.g_scale
            plateau[plateau] = beyond
        taken = n - (self.held is not None)  # HOLD is only ever the last sample
        if taken:
            self._last_reading = accel[taken - 1].copy()
        saturated[taken:] = False
        plateau[taken:] = False
        return {"saturated": saturated, "plateau": plateau}

    def _classify(
        self, batch: SampleBatch, finite: np.ndarray
    ) -> tuple[list[str], list[int], Intervals]:
        """Verdict on each sample, the samples after which diagnostics are due, and the stamp
        intervals into samples with a plain ACCEPT or a gap verdict."""
        usual = self._classify_in_order(batch, finite)
        return usual if usual is not None else self._classify_each(batch, finite)

    def _classify_in_order(
        self, batch: SampleBatch, finite: np.ndarray
    ) -> tuple[list[str], list[int], Intervals] | None:
        """`_classify` of the usual batch, every sample readable and in order, without a
        per-sample Python loop; None where the batch is not that."""
        spec, last_t, n = self.spec, self.last_stamp, len(batch)
        first = int(last_t is None)  # 1: the batch's first sample starts the twin
        if not (
            n > first
            and batch.unprovided is None
            and finite.all()
            and (not spec.frame_id or batch.frame_ids.count(spec.frame_id) == n)
        ):
            return None
        before = np.empty(n)
        before[0] = batch.stamps[0] if first else last_t
        before[1:] = batch.stamps[:-1]
        steps = batch.stamps - before
        if n - first > 1:  # the interval into the last sample's predecessor
            prev = float(steps[-2])
        elif first:  # the start has no interval before it
            prev = math.inf
        else:
            prev = math.inf if self._last_step is None else self._last_step
        checked = steps[first:]
        # With every stamp later than the one before, no sample is a glitch (its next one
        # would fall back): only a jump into the last sample is one to hold. (The stamps are
        # finite: min and max judge them as the comparisons did, in two reductions not four.)
        if not (
            checked.min() > 0.0
            and checked.max() <= spec.max_gap_s
            and steps[-1] <= JUMP_FACTOR * prev
        ):
            return None
        self.last_stamp = float(batch.stamps[-1])
        self._last_step = float(steps[-1])
        # A START has no interval, and what was skipped before it is not counted.
        before_first = {0: self.skipped} if self.skipped and not first else {}
        if first:
            steps[0] = math.nan
        self.skipped = 0
        return (
            [START if first else ACCEPT] + [ACCEPT] * (n - 1),
            self._health.ticks(batch.stamps),
            Intervals(steps, before_first, not first),
        )

    def _verdict(
        self, batch: SampleBatch, finite: np.ndarray, i: int, last_step: float | None
    ) -> str:
        """Verdict on sample i of `batch` after the taken samples before it (the last one's
        stamp `self.last_stamp`, the interval into it `last_step`)."""
        if not finite[i]:
            return "non_finite"
        if self.spec.frame_id and batch.frame_ids[i] != self.spec.frame_id:
            return "wrong_frame"
        if batch.unprovided is not None:  # REP-145: a reading to disregard
            if batch.unprovided[i, 0]:
                return "no_acceleration"
            if batch.unprovided[i, 1] and self.spec.reads_rate:
                return "no_angular_velocity"
        if self.last_stamp is None:
            return START
        next_t = float(batch.stamps[i + 1]) if i + 1 < len(batch) else None
        return stamp_verdict(self.spec, float(batch.stamps[i]), self.last_stamp, last_step, next_t)

    def _classify_each(
        self, batch: SampleBatch, finite: np.ndarray
    ) -> tuple[list[str], list[int], Intervals]:
        """`_classify`, sample by sample."""
        n = len(batch)
        verdicts: list[str] = []
        due: list[int] = []
        into = np.full(n, np.nan)
        skipped: dict[int, int] = {}
        last_step = self._last_step
        for i in range(n):
            verdict = self._verdict(batch, finite, i, last_step)
            verdicts.append(verdict)
            if verdict == HOLD:
                self.held = batch.part(slice(i, None))
                break
            if verdict not in _COUNTS:
                self.skipped += 1
                continue
            t = float(batch.stamps[i])
            last_t = self.last_stamp
            last_step = None if verdict in RESTARTS else t - last_t  # type: ignore[operator]
            if verdict in _INTERVALS:
                into[i] = t - last_t  # type: ignore[operator]  # not START: last_t is set
                if self.skipped:
                    skipped[i] = self.skipped
            self.skipped = 0
            self.last_stamp = t
            if self._health.tick(t):
                due.append(i)
        self._last_step = last_step
        plain = verdicts.count(ACCEPT) == n
        return verdicts, due, Intervals(into, skipped, plain)

    def _count(self, verdicts: list[str]) -> int:
        """Count the verdicts of samples processed; return how many were wrong_frame. A held
        sample is counted when the next push decides on it."""
        counts = self._counts
        if verdicts and verdicts.count(ACCEPT) == len(verdicts):  # the usual: no Counter (2 µs)
            counts["received"] += len(verdicts)
            counts["accepted"] += len(verdicts)
            return 0
        tally = Counter(verdicts)
        tally.pop(HOLD, None)
        counts["received"] += tally.total()
        for verdict, n in tally.items():
            for key in _COUNTS.get(verdict, (f"rejected_{verdict}",)):
                counts[key] += n
        return tally["wrong_frame"]
