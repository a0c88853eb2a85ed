"""Input intake: a pushed batch's samples screened, rotated into F and judged.

Each sample gets a verdict: taken (ACCEPT, a START or restart, a gap bridged or reset), held
back (HOLD: a stamp jump to confirm), or rejected for a reason (non_finite, wrong_frame,
duplicate_stamp, ...). Taken samples are grouped into runs split at restarts; the stamp
intervals into them feed the lost-sample estimate; readings at the sensor's full scale or on a
plateau are flagged. The twin itself is not touched here (`engine.TwinEngine` drives it).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Mapping
from typing import NamedTuple

import numpy as np

from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.delay_line import Run
from mount_twin.engine.health import HealthWindow
from mount_twin.engine.health_statuses import PLATEAU_G, SATURATION_SHARE
from mount_twin.engine.health_texts import NO_SAMPLE_ACCEPTED
from mount_twin.model.assemble import Model
from mount_twin.scene.description import InputSpec

ACCEPT, START, JUMPED_BACK, GAP_RESET, GAP_BRIDGED = (
    "accept",
    "start",
    "jumped_back",
    "gap_reset",
    "gap_bridged",
)
"""Verdicts on a sample besides the rejection reasons (non_finite, wrong_frame, ...)."""
HOLD = "hold"
"""The last sample of a push whose stamp jumped forward: kept for the next push to confirm."""
JUMP_FACTOR = 2.0
"""A stamp interval more than this many times the previous one is a jump to confirm: taken if
the next stamp is later still, rejected as `stamp_glitch` if the next one falls back before it
(one bad stamp then costs that one sample, not the samples until time catches up with it). At
2, a stamp glitched forward by 3 intervals or more is caught (at 20, one of 18 ms on a 1 kHz
stream was taken and the 17 valid samples after it rejected as going back); a jump followed by
later stamps, jitter included, only delays its sample by one when it ends a push."""

RESTARTS = frozenset((START, JUMPED_BACK, GAP_RESET))
"""Verdicts whose sample (re)starts the twin."""
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

READING_LIMIT = 1e150
"""Largest |component| of an accepted reading, m/s² or rad/s: a larger one (a garbled message) is
rejected as non_finite, and the rotation into F cannot overflow."""


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


def counted_text(counts: Mapping[str, int], prefix: str = "") -> str:
    """The non-zero counts of `counts` whose key starts with `prefix`, as a reader takes them:
    'non_finite 3, wrong_frame 40' (the prefix off), or 'none'."""
    kept = [(k, v) for k, v in counts.items() if k.startswith(prefix) and v]
    return ", ".join(f"{k.removeprefix(prefix)} {v}" for k, v in kept) or "none"


def nothing_accepted(
    counts: Mapping[str, int],
    wrong_frame_id: str | None = None,
    frame_id_setting: str = "input.frame_id",
) -> str:
    """Why no input sample was accepted, from an engine's `counts` ('' if some were): how many
    were received and why each was rejected, and the last `wrong_frame_id` rejected if any,
    pointing at what set the frame id expected (`frame_id_setting`: the scene's key, the
    option that replaced it, or both where that cannot be told). A run like that has no
    figures: a peak of 0 N would read as a machine at rest."""
    if counts.get("accepted", 0):
        return ""
    detail = ""
    if wrong_frame_id is not None:
        from mount_twin.scene.reader import shown_text  # a 1 MB frame id, shortened

        said = shown_text(wrong_frame_id)
        detail = f"; the bag's header.frame_id is {said}: see {frame_id_setting}"
    why = (
        f"{counts.get('received', 0)} received, rejected: "
        f"{counted_text(counts, 'rejected_')}{detail}"
    )
    return f"{NO_SAMPLE_ACCEPTED} ({why})"


def rotated(rows: np.ndarray, rot: np.ndarray) -> np.ndarray:
    """rows (n, 3) · rotᵀ, as three elementwise products: each row's bits are the same whatever
    the batch (a BLAS product may pick its kernel by size), and no BLAS thread wakes to spin
    beside the compiled loop on a two-core machine."""
    return rows[:, 0:1] * rot[:, 0] + rows[:, 1:2] * rot[:, 1] + rows[:, 2:3] * rot[:, 2]


def _any_axis(mask: np.ndarray) -> np.ndarray:
    """(n,) rows of an (n, 3) bool mask with any axis true: three elementwise operations,
    which cost a quarter of numpy's reduction along so short a last axis."""
    return mask[:, 0] | mask[:, 1] | mask[:, 2]


def _all_axes(mask: np.ndarray) -> np.ndarray:
    """(n,) rows of an (n, 3) bool mask with every axis true (see `_any_axis`)."""
    return mask[:, 0] & mask[:, 1] & mask[:, 2]


def readable(accel: np.ndarray, gyro: np.ndarray) -> np.ndarray:
    """(n,) which samples' (n, 3) readings (m/s², rad/s) are all within ±READING_LIMIT (NaN
    and ±inf are not): the others the intake rejects as non_finite."""
    return _all_axes(np.abs(accel) <= READING_LIMIT) & _all_axes(np.abs(gyro) <= READING_LIMIT)


def provided(
    accel: np.ndarray, gyro: np.ndarray, unprovided: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray]:
    """The (n, 3) readings with those their message marks not provided (`unprovided`, (n, 2):
    acceleration, angular velocity; REP-145: to be disregarded) zeroed: never read as values,
    nor judged as not finite; the sample's screening says whether it can do without them."""
    if unprovided is None:
        return accel, gyro
    return np.where(unprovided[:, :1], 0.0, accel), np.where(unprovided[:, 1:], 0.0, gyro)


def disregarded(unprovided: np.ndarray | None, n: int, reads_rate: bool = True) -> np.ndarray:
    """(n,) which samples lack a reading that is read: their acceleration marked not provided,
    or (`reads_rate`) their angular velocity (`unprovided`, (n, 2), None: none is marked)."""
    if unprovided is None:
        return np.zeros(n, bool)
    return unprovided[:, 0] | (unprovided[:, 1] & reads_rate)


def reading_rejections(
    accel: np.ndarray, gyro: np.ndarray, unprovided: np.ndarray | None, reads_rate: bool
) -> np.ndarray:
    """(n,) the rejection each sample earns at the intake by its readings alone ('' none), as
    `Intake` judges them, first first: non_finite (a reading not within ±READING_LIMIT, those
    marked not provided disregarded: `provided`), no_acceleration, no_angular_velocity (where
    the twin `reads_rate`; `unprovided` as `disregarded` takes it). For an analysis of a record
    to leave out what the twin did not take."""
    n = accel.shape[0]
    reasons = np.full(n, "", dtype=object)
    if unprovided is not None:
        reasons[unprovided[:, 1] & reads_rate] = "no_angular_velocity"
        reasons[unprovided[:, 0]] = "no_acceleration"
    reasons[~readable(*provided(accel, gyro, unprovided))] = "non_finite"
    return reasons


def rising(stamps: np.ndarray, keep: np.ndarray, last: int) -> np.ndarray:
    """Of the samples `keep` marks, those (bool mask) whose integer stamp is after `last` and
    after every kept stamp before it (one going back is not after the others either, so the
    running maximum over all kept ones is the same as over the rising ones)."""
    return keep & (stamps > _latest_before(stamps, keep, last))


def _latest_before(stamps: np.ndarray, keep: np.ndarray, last: int) -> np.ndarray:
    """Per sample, the latest of `last` and the stamps `keep` marks before it."""
    kept = np.where(keep, stamps, np.iinfo(np.int64).min)
    return np.maximum.accumulate(np.concatenate([[last], kept]))[:-1]


def rising_or_back(
    stamps: np.ndarray, keep: np.ndarray, last: int, reset: int
) -> tuple[np.ndarray, np.ndarray]:
    """`rising`, except that a kept stamp more than `reset` before `last` and every kept stamp
    before it starts afresh, as a stamp jumping back by more than input.back_jump_reset_s
    restarts the twin (`stamp_verdict`'s JUMPED_BACK: a bag played with --loop): (taken, of
    them those that jumped back) bool masks (`last`, `reset` and the stamps in one unit)."""
    taken = np.zeros(stamps.shape[0], bool)
    jumped = np.zeros(stamps.shape[0], bool)
    start = 0
    while True:
        part, kept = stamps[start:], keep[start:]
        before = _latest_before(part, kept, last)
        back = np.flatnonzero(kept & (part < before - reset))
        stop = int(back[0]) if back.shape[0] else part.shape[0]
        taken[start : start + stop] = (kept & (part > before))[:stop]
        if not back.shape[0]:
            return taken, jumped
        taken[start + stop] = jumped[start + stop] = True
        last, start = int(part[stop]), start + stop + 1


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


def stamp_verdict(
    spec: InputSpec, t: float, last_t: float, last_step: float | None, next_t: float | None
) -> str:
    """Verdict on a readable sample of stamp t (s) by its stamp alone: after the last taken
    sample's `last_t`, into which the interval was `last_step` (None: it was a start), and
    before the next sample's `next_t` (None: it ends the push)."""
    if t == last_t:
        return "duplicate_stamp"
    if t < last_t - spec.back_jump_reset_s:
        return JUMPED_BACK
    if t < last_t:
        return "stamp_went_back"
    if (
        last_step is not None
        and t - last_t > JUMP_FACTOR * last_step
        and (next_t is None or last_t < next_t < t)
    ):
        return HOLD if next_t is None else "stamp_glitch"
    if t - last_t > spec.max_gap_s:
        return GAP_RESET if spec.gap_policy == "reset" else GAP_BRIDGED
    return ACCEPT


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
                saturated |= _any_axis(np.abs(reading) >= SATURATION_SHARE * full_scale)
        before = np.concatenate([self._last_reading[None, :], accel[:-1]])
        plateau = _all_axes(accel == before)  # repeated exactly; beyond PLATEAU_G too:
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
