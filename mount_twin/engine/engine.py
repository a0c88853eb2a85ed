"""TwinEngine: validates input samples, advances the twin, and produces outputs and health.

Knows nothing of ROS or files: adapters decode messages into `SampleBatch` and encode the
`OutputBatch` it returns. Bad samples are counted, reported and skipped; the twin keeps running.
"""

from __future__ import annotations

import math
import time
from collections import Counter
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from mount_twin.engine import companion, estimator
from mount_twin.engine.auto_method import (
    REEXAMINE_S,
    Choice,
    after_event,
    at_start,
    tangent_rate,
)
from mount_twin.engine.batch import (
    ERROR,
    WARN,
    HealthReport,
    MountEvent,
    OutputBatch,
    SampleBatch,
)
from mount_twin.engine.companion import Companion, new_companion
from mount_twin.engine.delay_line import Frame, GyroDelay, Run, filter_bands
from mount_twin.engine.estimate import ErrorEstimate
from mount_twin.engine.estimator import Estimator, new_estimator
from mount_twin.engine.gyro_filter import Design
from mount_twin.engine.health import ENDED, PLATEAU_G, SATURATION_SHARE, HealthWindow
from mount_twin.engine.kernel import (
    AT_EVENT,
    Integrator,
    Published,
    RunOptions,
    Samples,
    Watch,
    new_watch,
    run_samples,
)
from mount_twin.engine.restart import start_state
from mount_twin.integrate.methods import AUTO
from mount_twin.integrate.stepper import STATUS_TEXT, new_stepper, switch
from mount_twin.kinds import KINDS, N_EVENTS
from mount_twin.model.assemble import Model, initial_state
from mount_twin.model.stiffness import spectral_radius
from mount_twin.physics import pose_row
from mount_twin.physics.dynamics import INPUT_SIZE, Scratch, evaluate, mount_monitors
from mount_twin.scene.description import STANDARD_GRAVITY, InputSpec

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

_RESTARTS = frozenset((START, JUMPED_BACK, GAP_RESET))
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


GIVEN_MOTION_STOP = (
    "the stepper failed, and restarting a given initial motion would replay a motion the body "
    "is not making"
)
"""Why a scene with a given initial motion stops following at a stepper failure."""

MAX_EVENTS = 100_000
"""Mount events kept in TwinEngine.events (later ones are counted only)."""


class _Rows(NamedTuple):
    """Published rows: positions of their samples in the pushed batch, poses, wrenches; and
    where the compiled loop gave them, their largest |wrench component| per mount and smallest
    cos θ (`kernel.Published`)."""

    sample: np.ndarray
    pose: np.ndarray
    wrenches: np.ndarray
    peaks: tuple[np.ndarray, float] | None = None


class _BatchRows:
    """Output rows for a pushed batch, one per sample (row r + 1 holds sample r's; row 0 is
    before the batch): a start and a run over consecutive samples write theirs in place, so a
    push whose published rows are consecutive returns views of these rather than a
    concatenation of each run's (0.5 ms of the genset's 2,500-sample shock record)."""

    def __init__(self, n: int, n_mounts: int) -> None:
        self.pose = np.empty((n + 1, pose_row.WIDTH))
        self.wrenches = np.empty((n + 1, n_mounts, 6))

    def of_run(self, index: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """A run's buffers (row 0: the sample before index[0]) where its samples are
        consecutive; None else."""
        first, n = int(index[0]), index.shape[0] + 1
        if int(index[-1]) - first != n - 2:
            return None
        return self.pose[first : first + n], self.wrenches[first : first + n]

    def gather(self, parts: list[_Rows]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The parts' samples, poses and wrenches, in order."""
        sample = np.concatenate([r.sample for r in parts])
        n = sample.shape[0]
        if (
            n
            and int(sample[-1]) - int(sample[0]) == n - 1
            and all(np.may_share_memory(r.pose, self.pose) for r in parts)
        ):  # consecutive rows of these buffers, in place
            rows = slice(int(sample[0]) + 1, int(sample[-1]) + 2)
            return sample, self.pose[rows], self.wrenches[rows]
        return (
            sample,
            np.concatenate([r.pose for r in parts]),
            np.concatenate([r.wrenches for r in parts]),
        )


class _Intervals(NamedTuple):
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


def _start_hint(spec: InputSpec, magnitude: float) -> str:
    """Why a start specific force of `magnitude` (m/s²) may be off g: the likeliest cause."""
    g = spec.g
    if g == 0.0 and abs(magnitude - STANDARD_GRAVITY) < 0.25 * STANDARD_GRAVITY:
        return "the scene has no gravity (input.g: 0): is the input a sensor at rest on Earth?"
    if not spec.includes_gravity and abs(magnitude - 2.0 * g) < 0.25 * g:
        return "input.includes_gravity is false, so g was added: does the input include it?"
    return (
        "a start on a shock or spike, free fall, or a sensor bias? "
        "initial.gravity_samples averages the start"
    )


def _rotated(rows: np.ndarray, rot: np.ndarray) -> np.ndarray:
    """rows (n, 3) · rotᵀ, as three elementwise products: each row's bits are the same whatever
    the batch (a BLAS product may pick its kernel by size), and no BLAS thread wakes to spin
    beside the compiled loop on a two-core machine."""
    return rows[:, 0:1] * rot[:, 0] + rows[:, 1:2] * rot[:, 1] + rows[:, 2:3] * rot[:, 2]


class TwinEngine:
    """Streaming twin of one model.

    Args:
        model: the assembled scene.
        clock: wall clock for the real-time factor, s (injectable for tests).
    """

    def __init__(self, model: Model, clock: Callable[[], float] = time.perf_counter) -> None:
        scene = model.scene
        self.model = model
        self.scene = scene
        self._clock = clock
        integ = scene.integration
        self.stepper = new_stepper(
            integ.method, model.n_state, integ.rtol, integ.atol, integ.max_substeps
        )
        self._scratch = model.new_scratch()
        self._u = np.zeros(INPUT_SIZE)
        self._y = np.zeros(model.n_state)
        self._peak = np.zeros((model.n_mounts, 6))
        self._counter = np.zeros(1, dtype=np.int64)
        self._last: tuple[float, np.ndarray, np.ndarray] | None = None
        self._last_stamp: float | None = None
        self._last_step: float | None = None
        """Interval (s) into the last taken sample from the one before (None after a start)."""
        self._held: SampleBatch | None = None
        """A sample held back at the end of the last push (a jump to confirm, see JUMP_FACTOR)."""
        self._last_reading = np.full(3, np.nan)
        """The last accelerometer reading pushed and not held back (sensor frame, m/s²)."""
        self._skipped = 0
        """Samples rejected since the last taken one: they fill a stamp hole, are not lost."""
        self._gravity_up = np.array([0.0, 0.0, scene.input.g])
        spec = scene.input
        self._gyro = GyroDelay(filter_bands(spec), self._designed)
        self._pushed = 0
        """Samples pushed so far (a held one once)."""
        init = scene.initial
        self._start_samples = (
            init.gravity_samples
            if init.mode == "equilibrium" and init.gravity == "first_sample"
            else 1
        )
        self._gathered: list[np.ndarray] = []
        """Specific forces (m/s², F) of the samples taken so far toward the next start."""
        self.counts: Counter[str] = Counter()
        self.failure_causes: Counter[str] = Counter()
        """Integration failures by cause (`STATUS_TEXT`), counts["integration_failures"] in all."""
        self.health = HealthWindow(scene, integ.method)  # `auto` until it has chosen
        self._event_meta = {
            slot: (model.scene.mounts[slot].name, KINDS[model.scene.mounts[slot].kind])
            for slot in model.nonlinear_slots
        }
        stiffens = np.zeros((len(model.nonlinear_slots), N_EVENTS))
        for i, (_, kind) in enumerate(self._event_meta.values()):
            stiffens[i, : len(kind.EVENTS)] = kind.EVENT_STIFFENS
        self._watch = new_watch(len(model.nonlinear_slots), N_EVENTS, model.n_state, stiffens)
        self.events: list[MountEvent] = []
        """Every mount event so far, in time order (the first MAX_EVENTS; the rest counted)."""
        lin_slots = model.arrays.lin_slot.tolist()
        rated = model.arrays.lin_per_rating.any(axis=1)
        self._lin_rated = np.flatnonzero(rated)
        """The rated linear mounts, as indices among the linear ones (the core's order)."""
        self._rated = np.array(
            [*model.nonlinear_slots, *(lin_slots[i] for i in self._lin_rated)], dtype=np.int64
        )
        """Mounts with a utilisation: the non-linear ones (their watch), then rated linear ones."""
        self._linear_util = np.zeros(len(lin_slots))
        """Every linear mount's peak utilisation since the window's last report (the core
        folds it in at every sample; unrated ones stay 0)."""
        self._util_max = np.zeros(self._rated.shape[0])
        # Chaining the stepper's last stage into the next interval needs a continuous input
        # (first-order hold); a discrete switch of the state between samples (a bolt breaking)
        # clears the flag in the compiled loop.
        self._options = RunOptions(
            scene.input.hold == "zero_order",
            scene.outputs.decimation,
            scene.input.hold == "first_order",
        )
        st = self.stepper
        self._integ = Integrator(st.method, st.settings, st.work2d, st.work1d, st.result)
        self._estimator = self._new_estimator()
        # Fails now, at load, if the mounts cannot hold the body; and is the restart fallback.
        self._y_nominal = initial_state(model, self._gravity_up)
        self._rho: tuple[float, float] | None = None
        """Spectral radius at the nominal start and rate of the nominal tangents, rad/s, while
        `auto` has not chosen yet."""
        if integ.method == AUTO:
            self._rho = (
                spectral_radius(model, self._y_nominal, self._gravity_up),
                tangent_rate(model),
            )
            self._watch.stop_after[0] = -math.inf  # `auto` looks again after mount events

    def _use(self, choice: Choice) -> None:
        """Run `auto`'s choice from now on: the first, or a change after a mount event (its
        step history forgotten; counted)."""
        self.health.method = choice.status
        if self._rho is None:
            if choice.method == self.stepper.name:
                return
            self.counts["method_switches"] += 1
        self._rho = None
        switch(self.stepper, choice.method)
        st = self.stepper
        self._integ = Integrator(st.method, st.settings, st.work2d, st.work1d, st.result)
        if isinstance(self._estimator, Estimator):
            self._estimator = estimator.switch(self._estimator, st.method)
        elif self._estimator is not None:
            self._estimator = companion.switch(self._estimator, st.method)

    def _look_again(self, t: np.ndarray, f: np.ndarray, j: int, events: list[MountEvent]) -> None:
        """`auto` at sample j of the run just ended, which logged `events`, one of which may
        stiffen the scene (`auto_method`)."""
        self._watch.stop_after[0] = t[j] + REEXAMINE_S
        event = next((e for e in reversed(events) if self._stiffens(e)), events[-1])
        choice = after_event(self.model, self._y, f[j], float(t[j] - t[j - 1]), event)
        if choice is not None:
            self._use(choice)

    def _new_estimator(self) -> Estimator | Companion | None:
        """The live error estimate's arrays (`engine.estimator` where the mounts are linear,
        `engine.companion` where some are not: see there), or None if the scene turns it
        off."""
        integ = self.scene.integration
        if not integ.error_estimate:
            return None
        arrays = self.model.arrays
        if arrays.nl is not None:
            return new_companion(
                integ.method,
                self.model.n_state,
                integ.rtol,
                integ.atol,
                integ.max_substeps,
                self.model.new_scratch(),
                self.model.n_mounts,
                self._watch.g.shape,
            )
        return new_estimator(
            integ.method,
            integ.rtol,
            integ.atol,
            integ.max_substeps,
            self.model.new_scratch(),
            arrays.free_trans.shape[0] + arrays.free_rot.shape[0],
            self.model.n_mounts,
        )

    def _buffers(
        self,
        n: int,
        counter: np.ndarray,
        peak: np.ndarray,
        rows: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> Published:
        """Output buffers for a run of n rows, with the decimation state to carry; `rows`: the
        pose and wrench rows to write into (`_BatchRows.of_run`), else new ones."""
        nm = self.model.n_mounts
        pose, wrenches = rows or (np.empty((n, pose_row.WIDTH)), np.empty((n, nm, 6)))
        return Published(
            counter,
            peak,
            pose,
            wrenches,
            np.zeros(n, dtype=np.bool_),
            np.zeros((n, 3)),
            np.zeros((nm, 6)),
            np.ones(1),
            self._linear_util,
        )

    @property
    def state(self) -> np.ndarray:
        """Current state vector (copy); names in `model.state_names`."""
        return self._y.copy()

    @property
    def error_estimate(self) -> ErrorEstimate | None:
        """The estimated error of everything published so far (None: `error_estimate` off)."""
        return None if self._estimator is None else ErrorEstimate.of(self.health.estimate_run)

    @property
    def failure_text(self) -> str:
        """How often the integration failed and why ('' if never): a run with any failure is
        FAILED (`replay`, the sweep), whatever its diagnostics level."""
        n = self.counts["integration_failures"]
        if not n:
            return ""
        causes = ", ".join(f"{cause} ×{k}" for cause, k in self.failure_causes.most_common())
        return (
            f"integration failed {n} times ({causes}); {self.counts['restarts']} restarts, "
            f"{self.counts['samples_not_followed']} samples not followed"
        )

    @property
    def running(self) -> bool:
        """True once a sample has started the twin (and no failure has stopped it since)."""
        return self._last is not None

    @property
    def utilisation_max(self) -> dict[str, float]:
        """Peak utilisation so far of each mount that has an allowable (bolt: F_S/F_y, rubber:
        deflection/rated, key: force/allowable), by name."""
        peak = np.maximum(self._util_max, self._window_utilisation())
        names = [self.scene.mounts[i].name for i in self._rated]
        return dict(zip(names, peak.tolist(), strict=True))

    def _window_utilisation(self) -> np.ndarray:
        """Peak utilisation since the last report of the mounts in `_rated`, in its order."""
        return np.concatenate([self._watch.util_peak, self._linear_util[self._lin_rated]])

    def count(self, what: str, n: int = 1) -> None:
        """Count events found outside the engine (e.g. undecodable messages) with its own.

        `rejected_*` counters (samples received but unusable) are not lost: they are credited to
        the next stamp hole. `lost_*` counters (e.g. lost_middleware, from DDS message-lost
        events) enter the input status' lost_in_period.
        """
        self.counts[what] += n
        if what.startswith("rejected_"):
            self._skipped += n

    def push(self, batch: SampleBatch) -> OutputBatch:
        """Process samples in arrival order; return what is to be published for them.

        Diagnostics come at the stamps where they would for one sample per push, so a replay in
        chunks publishes what the live node does. An empty batch changes nothing; a malformed
        non-empty one (shapes, types: `SampleBatch.check`) raises ValueError naming the field,
        and changes nothing either.
        """
        nm = self.model.n_mounts
        if len(batch) == 0:  # whatever its arrays' shapes (a decoder's empty result may be flat)
            return OutputBatch.empty(nm)
        batch.check()
        first_id = self._pushed
        self._pushed += len(batch)
        if self._held is None:
            return self._push(batch, first_id)
        # The held sample goes first, now with the next one to confirm or refute it: positions
        # in the result count from it, so it is −1 to the caller.
        batch, self._held = SampleBatch.concat([self._held, batch]), None
        out = self._push(batch, first_id - 1)
        out.sample -= 1
        for report in out.health:
            report.sample -= 1
        return out

    def run(self, samples: SampleBatch) -> OutputBatch:
        """A whole record: `push` it, then `flush`; every row and report, positions in
        `samples` (the final report last)."""
        return self.push(samples).then(self.flush(), len(samples))

    @property
    def holding(self) -> bool:
        """Whether the last sample pushed is held back (a stamp jump to confirm): the next push
        gives its outputs, as sample −1."""
        return self._held is not None

    @property
    def lookback(self) -> int:
        """How many of the samples pushed so far, counted back from the last, later outputs
        may still answer (as negative `OutputBatch.sample`): the gyro delay's pending samples
        (`delay_line`) and a sample held back (a stamp jump to confirm)."""
        oldest = self._gyro.oldest_id
        return max(0 if oldest is None else self._pushed - oldest, int(self.holding))

    @property
    def latency(self) -> int:
        """Samples by which outputs follow their input (the gyro delay; 0 until designed)."""
        return self._gyro.delay

    def _designed(self, stamp: float, design: Design) -> None:
        """The gyro filter was designed, at the interval into `stamp` (s)."""
        self.health.gyro_designed(stamp, design)

    def _push(self, batch: SampleBatch, first_id: int) -> OutputBatch:
        """`push` of a batch that holds any held-back sample first (stream position
        `first_id`)."""
        nm = self.model.n_mounts
        f, w, finite = self._screen(batch)
        verdicts, due, intervals = self._classify(batch, finite)
        suspect = self._suspect_readings(batch)
        frame = self._gyro.frame(batch.stamps, f, w, first_id)
        rows_out = _BatchRows(len(frame.stamps), nm)
        parts: list[_Rows] = []
        reports = []
        start = 0
        for stop, report_due in [*((i + 1, True) for i in due), (len(batch), False)]:
            wall0 = self._clock()
            for what, flags in suspect.items():
                if n_flagged := int(flags[start:stop].sum()):
                    self.counts[what] += n_flagged
            if self._count(verdicts[start:stop]).get("wrong_frame"):
                self.health.add_wrong_frames(
                    [
                        batch.frame_ids[i]
                        for i in range(start, stop)
                        if verdicts[i] == "wrong_frame"
                    ]
                )
            self._add_intervals(intervals, start, stop)
            for run in self._runs(verdicts, start, stop):
                self._follow(self._gyro.feed(run, frame), frame, rows_out, parts)
            self.health.add_wall(self._clock() - wall0)
            if report_due:
                stamp = float(batch.stamps[stop - 1])
                reports.append(self._report(stamp, stop - 1, parts))
            start = stop
        self._gyro.close(frame)
        return self._outputs(frame, rows_out, parts, reports)

    def _follow(self, runs: list[Run], frame: Frame, rows: _BatchRows, parts: list[_Rows]) -> None:
        """Integrate runs of frame rows (`_integrate`), their outputs onto `parts` and into the
        health window."""
        first = len(parts)
        for run in runs:
            parts.extend(self._integrate(run, frame.stamps, frame.f, frame.w, rows))
        for published in parts[first:]:
            if published.peaks is None:
                self.health.add_outputs(
                    frame.stamps[published.sample], published.pose, published.wrenches
                )
            elif published.sample.shape[0]:
                self.health.add_output_peaks(
                    frame.stamps[published.sample[0]],
                    frame.stamps[published.sample[-1]],
                    *published.peaks,
                )

    def _outputs(
        self, frame: Frame, rows: _BatchRows, parts: list[_Rows], reports: list[HealthReport]
    ) -> OutputBatch:
        """The OutputBatch of a push's (or a flush's) published parts and reports."""
        if not parts:
            empty = OutputBatch.empty(self.model.n_mounts)
            empty.health = reports
            return empty
        sample, pose, wrenches = rows.gather(parts)
        return OutputBatch(frame.stamps[sample], frame.relative(sample), pose, wrenches, reports)

    def _add_intervals(self, intervals: _Intervals, start: int, stop: int) -> None:
        """Hand the stamp intervals of samples [start, stop) to the health window."""
        steps = intervals.steps[start:stop]
        skipped = {i - start: n for i, n in intervals.skipped.items() if start <= i < stop}
        if not intervals.plain:
            keep = ~np.isnan(steps)
            position = np.cumsum(keep) - 1  # among the kept steps
            steps = steps[keep]
            skipped = {int(position[i]): n for i, n in skipped.items()}
        self.health.add_intervals(steps, skipped)

    def _suspect_readings(self, batch: SampleBatch) -> dict[str, np.ndarray]:
        """Per sample (bool, not held back): 'saturated', a reading at the sensor's full scale;
        'plateau', an accelerometer reading beyond PLATEAU_G repeated from the sample before.
        Such samples are taken (their value is the best there is) but counted and reported."""
        spec = self.scene.input
        accel, n = batch.accel, len(batch)
        saturated = np.zeros(n, dtype=bool)
        for reading, full_scale in (
            (accel, spec.accel_range_m_s2),
            (batch.gyro, spec.gyro_range_rad_s),
        ):
            if full_scale > 0.0:
                saturated |= (np.abs(reading) >= SATURATION_SHARE * full_scale).any(axis=1)
        before = np.concatenate([self._last_reading[None, :], accel[:-1]])
        with np.errstate(invalid="ignore", over="ignore"):
            plateau = (accel == before).all(axis=1) & (
                np.linalg.norm(accel, axis=1) > PLATEAU_G * spec.g_scale
            )
        taken = np.ones(n, dtype=bool)
        if self._held is not None:  # HOLD is only ever the last sample
            taken[-1] = False
        kept = np.flatnonzero(taken)
        if kept.shape[0]:
            self._last_reading = accel[kept[-1]].copy()
        return {"saturated": saturated & taken, "plateau": plateau & taken}

    def _screen(self, batch: SampleBatch) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Specific force (m/s²) and Ω (rad/s) in F per sample, and which samples are finite:
        a finite stamp and readings within ±READING_LIMIT.

        Other readings are zeroed before the rotation, which would otherwise warn (numpy
        RuntimeWarning: inf·0, inf − inf, overflow); their samples are rejected anyway.
        """
        rot = self.model.sensor_rotation
        accel, gyro = batch.accel, batch.gyro
        finite = np.isfinite(batch.stamps)
        # NaN compares false: one test for NaN, ±inf and the absurdly large.
        if not (np.abs(accel).max() <= READING_LIMIT and np.abs(gyro).max() <= READING_LIMIT):
            readable = (np.abs(accel) <= READING_LIMIT).all(axis=1) & (
                np.abs(gyro) <= READING_LIMIT
            ).all(axis=1)
            accel = np.where(readable[:, None], accel, 0.0)
            gyro = np.where(readable[:, None], gyro, 0.0)
            finite &= readable
        f = _rotated(accel, rot)
        if not self.scene.input.includes_gravity:
            f = f + self._gravity_up
        if self.scene.input.gyro_filter == "ignore":  # the foundation's rotation neglected
            return f, np.zeros_like(f), finite
        return f, _rotated(gyro, rot), finite

    def _classify(
        self, batch: SampleBatch, finite: np.ndarray
    ) -> tuple[list[str], list[int], _Intervals]:
        """Verdict on each sample, the samples after which diagnostics are due, and the stamp
        intervals into samples with a plain ACCEPT or a gap verdict."""
        spec = self.scene.input
        last_t = self._last_stamp
        n = len(batch)
        first = int(last_t is None)  # 1: the batch's first sample starts the twin
        if (
            n > first
            and finite.all()
            and (not spec.frame_id or batch.frame_ids.count(spec.frame_id) == n)
        ):
            before = np.empty(n)
            before[0] = batch.stamps[0] if first else last_t
            before[1:] = batch.stamps[:-1]
            steps = batch.stamps - before
            prev = np.empty(n)
            prev[0] = math.inf if self._last_step is None else self._last_step
            prev[1:] = steps[:-1]
            if first:
                prev[1] = math.inf  # the start has no interval before it
            checked = steps[first:]
            # With every stamp later than the one before, no sample is a glitch (its next one
            # would fall back): only a jump into the last sample is one to hold.
            if (
                (checked > 0.0).all()
                and (checked <= spec.max_gap_s).all()
                and steps[-1] <= JUMP_FACTOR * prev[-1]
            ):
                # The usual batch, every sample in order: no per-sample Python loop.
                self._last_stamp = float(batch.stamps[-1])
                self._last_step = float(steps[-1])
                # A START has no interval, and what was skipped before it is not counted.
                before_first = {0: self._skipped} if self._skipped and not first else {}
                if first:
                    steps[0] = math.nan
                self._skipped = 0
                return (
                    [START if first else ACCEPT] + [ACCEPT] * (n - 1),
                    self.health.ticks(batch.stamps),
                    _Intervals(steps, before_first, not first),
                )
        verdicts: list[str] = []
        due: list[int] = []
        into = np.full(n, np.nan)
        skipped: dict[int, int] = {}
        stamps = batch.stamps.tolist()
        last_step = self._last_step
        for i, t in enumerate(stamps):
            if not finite[i]:
                verdict = "non_finite"
            elif spec.frame_id and batch.frame_ids[i] != spec.frame_id:
                verdict = "wrong_frame"
            elif last_t is None:
                verdict = START
            elif t == last_t:
                verdict = "duplicate_stamp"
            elif t < last_t - spec.back_jump_reset_s:
                verdict = JUMPED_BACK
            elif t < last_t:
                verdict = "stamp_went_back"
            elif (
                last_step is not None
                and t - last_t > JUMP_FACTOR * last_step
                and (i + 1 == n or last_t < stamps[i + 1] < t)
            ):
                verdict = HOLD if i + 1 == n else "stamp_glitch"
            elif t - last_t > spec.max_gap_s:
                verdict = GAP_RESET if spec.gap_policy == "reset" else GAP_BRIDGED
            else:
                verdict = ACCEPT
            verdicts.append(verdict)
            if verdict == HOLD:
                self._held = SampleBatch(
                    batch.stamps[i:], batch.accel[i:], batch.gyro[i:], batch.frame_ids[i:]
                )
                break
            if verdict not in _COUNTS:
                self._skipped += 1
                continue
            last_step = None if verdict in _RESTARTS else t - last_t
            if verdict in _INTERVALS:
                into[i] = t - last_t  # type: ignore[operator]  # not START: last_t is set
                if self._skipped:
                    skipped[i] = self._skipped
            self._skipped = 0
            last_t = t
            if self.health.tick(t):
                due.append(i)
        self._last_stamp = last_t
        self._last_step = last_step
        plain = verdicts.count(ACCEPT) == n
        return verdicts, due, _Intervals(into, skipped, plain)

    def _count(self, verdicts: list[str]) -> Counter[str]:
        """Count the verdicts of samples processed; return how many of each there were. A held
        sample is counted when the next push decides on it."""
        counts = self.counts
        tally = Counter(verdicts)
        tally.pop(HOLD, None)
        counts["received"] += tally.total()
        for verdict, n in tally.items():
            for key in _COUNTS.get(verdict, (f"rejected_{verdict}",)):
                counts[key] += n
        return tally

    @staticmethod
    def _runs(verdicts: list[str], start: int, stop: int) -> list[Run]:
        """Group the taken samples in [start, stop) into runs split at restarts."""
        segment = verdicts[start:stop]
        if not segment:
            return []
        head = segment[0]
        restart = head in _RESTARTS
        if (head == ACCEPT or restart) and segment.count(ACCEPT) == len(segment) - restart:
            # the usual cases, without a Python loop: all accepted, or a start and the rest
            return [Run(np.arange(start, stop), restart)]
        runs: list[tuple[list[int], bool]] = []
        for i in range(start, stop):
            verdict = verdicts[i]
            if verdict not in _COUNTS:
                continue
            if verdict in _RESTARTS or not runs:
                runs.append(([i], verdict in _RESTARTS))
            else:
                runs[-1][0].append(i)
        return [Run(np.array(index, dtype=np.int64), restart) for index, restart in runs]

    def _integrate(
        self, run: Run, stamps: np.ndarray, f: np.ndarray, w: np.ndarray, rows: _BatchRows
    ) -> list[_Rows]:
        """Integrate one run, its outputs into `rows` where it can; on a stepper failure
        restart at the next sample."""
        out: list[_Rows] = []
        index = run.index
        if self.health.stopped_at is not None:
            if not run.restart:
                self.counts["samples_not_followed"] += len(index)
                return out
            self.health.stopped_at = None
        if run.restart or self._last is None:
            index, gathered = self._gather(run, f)
            if not len(index):
                return out
            if not self._started(out, index, stamps, f, w, gathered, rows):
                return out
            index = index[1:]
        if len(index) and self._rho is not None:
            interval = float(stamps[index[0]]) - self._last[0]  # type: ignore[index]
            self._use(at_start(self.model, *self._rho, interval))
        # The run's samples from the last one done on: after a stop at an event the run goes on
        # with the rows it has.
        segment: Samples | None = None
        while len(index):
            if segment is None:
                t0, f0, w0 = self._last  # type: ignore[misc]
                n = len(index) + 1
                t, ff, ww = np.empty(n), np.empty((n, 3)), np.empty((n, 3))
                t[0], ff[0], ww[0] = t0, f0, w0  # row 0: the last sample done
                t[1:], ff[1:], ww[1:] = stamps[index], f[index], w[index]
                segment = Samples(t, ff, ww)
            t, ff, ww = segment
            out_buf = self._buffers(len(t), self._counter, self._peak, rows.of_run(index))
            done, status = run_samples(
                self._integ,
                self.model.arrays,
                self._scratch,
                self._u,
                self._y,
                segment,
                self._options,
                out_buf,
                self._watch,
                self._estimator,
            )
            pose, wrenches, publish = out_buf.pose, out_buf.wrenches, out_buf.publish
            step_log, abs_max, cos_tilt = (
                out_buf.step_log,
                out_buf.wrench_abs_max,
                out_buf.cos_tilt_min,
            )
            peaks = abs_max, float(cos_tilt[0])
            events = self._drain_events()
            self.health.add_steps(step_log[1 : done + 1])
            if self._estimator is not None:
                self.health.add_estimate(self._estimator.figures)
                self._estimator.figures[:] = 0.0
            self.counts["substeps"] += int(step_log[1 : done + 1, 1:3].sum())
            if done > 0:
                self._last = (float(t[done]), ff[done], ww[done])
            keep = np.flatnonzero(publish[: done + 1])  # never row 0: the previous sample
            if keep.shape[0] == done:  # every sample published: views of this run's buffers
                published = _Rows(index[:done], pose[1 : done + 1], wrenches[1 : done + 1], peaks)
            else:
                published = _Rows(index[keep - 1], pose[keep], wrenches[keep], peaks)
            out.append(published)
            if status == 0:
                break
            if status == AT_EVENT:
                self._look_again(t, ff, done, events)
                index = index[done:]
                segment = Samples(t[done:], ff[done:], ww[done:])
                continue
            segment = None  # a restart takes the rows after it afresh
            self.counts["integration_failures"] += 1
            cause = STATUS_TEXT.get(status, f"status {status}")
            self.failure_causes[cause] += 1
            self.health.failure(float(t[done + 1]), cause)
            self._last = None
            rest = index[done + 1 :]
            if self.scene.initial.mode == "given":
                # A restart would launch the given initial motion again: a motion the body is
                # not making. The twin stops following until the record restarts.
                self._stop_following(float(t[done + 1]), GIVEN_MOTION_STOP)
                self.counts["samples_not_followed"] += len(rest)
                break
            if not len(rest) or not self._started(out, rest, stamps, f, w, f[rest[:1]], rows):
                break
            index = rest[1:]
        return out

    def _started(
        self,
        out: list[_Rows],
        index: np.ndarray,
        stamps: np.ndarray,
        f: np.ndarray,
        w: np.ndarray,
        gathered: np.ndarray,
        rows: _BatchRows,
    ) -> bool:
        """Start at sample index[0] (`_start`), its outputs onto `out`; False where no
        equilibrium holds: `index` is then counted as not followed."""
        start = self._start(int(index[0]), stamps, f, w, gathered, rows)
        if start is None:
            self.counts["samples_not_followed"] += len(index)
            return False
        out.append(start)
        return True

    def flush(self) -> OutputBatch:
        """The end of the stream (end of a bag, shutdown): the outputs of the samples the gyro
        delay still holds (the rate after the last held at its value; `sample` negative, −1
        the last sample pushed), and in `health` the report of what happened since the last
        one, due or not (none if nothing was processed since; its `sample` is −1).

        A sample still held back (a stamp jump that no later sample confirmed) is counted as
        rejected_unconfirmed_jump: the record ends before it can be told from a glitch. Where
        samples were received but none ever accepted, the report (`stamp` NaN) says so at
        ERROR, and why (`health.ENDED`).
        """
        if self._held is not None:
            self._held = None
            self.count("received")
            self.count("rejected_unconfirmed_jump")
        empty = np.zeros((0, 3))
        frame = self._gyro.frame(np.zeros(0), empty, empty, self._pushed)
        rows = _BatchRows(len(frame.stamps), self.model.n_mounts)
        parts: list[_Rows] = []
        self._follow(self._gyro.drain(frame), frame, rows, parts)
        reports = []
        if self._last_stamp is not None:
            if self.health.pending:
                reports.append(self._report(self._last_stamp, -1, parts))
        elif self.counts["received"] and not self.counts["accepted"]:
            reports.append(self._report(math.nan, -1, parts, stalled_s=ENDED))
        return self._outputs(frame, rows, parts, reports)

    def report_stalled(self, waited_s: float) -> HealthReport:
        """The report a live adapter publishes when `waited_s` (s, its clock) passed without
        the stamps of accepted samples making a report due: the window so far, as `flush`
        gives it, with the input status an ERROR that says why (nothing received, everything
        rejected, or too few samples accepted). Works before any sample was accepted.

        Its `stamp` is the last accepted stamp (engine seconds, NaN if none), its `sample` −1.
        The window starts anew, and the stamp cadence restarts at the next accepted sample.
        """
        stamp = math.nan if self._last_stamp is None else self._last_stamp
        report = self._report(stamp, -1, stalled_s=waited_s)
        self.health.restart_cadence()
        return report

    def _report(
        self,
        stamp: float,
        sample: int,
        parts: list[_Rows] | None = None,
        stalled_s: float | None = None,
    ) -> HealthReport:
        """The report due at `stamp` (s), after sample `sample` and the output rows of `parts`
        (those published before it in its batch)."""
        util = self._window_utilisation()
        per_mount = np.full(self.model.n_mounts, math.nan)
        per_mount[self._rated] = util
        lost, nominal = self.health.lost_estimate()
        if lost:
            self.counts["lost_estimated"] += lost
        report = self.health.report(
            stamp,
            sample,
            self.counts,
            per_mount,
            self._active(),
            lost_from_stamps=lost,
            nominal_interval_s=nominal,
            stalled_s=stalled_s,
        )
        report.rows = sum(p.sample.shape[0] for p in parts or ())
        np.maximum(self._util_max, util, out=self._util_max)
        self._watch.util_peak[:] = 0.0
        self._linear_util[:] = 0.0
        return report

    def _active(self) -> dict[str, list[tuple[str, bool]]]:
        """Conditions holding at the last sample, per mount: (event name, is an error)."""
        g = self._watch.g
        out = {}
        for k, slot in enumerate(self.model.nonlinear_slots):
            name, kind = self._event_meta[slot]
            out[name] = [
                (event, error)
                for event, error, value in zip(kind.EVENTS, kind.EVENT_ERROR, g[k], strict=False)
                if value >= 0.0
            ]
        return out

    def _stiffens(self, event: MountEvent) -> bool:
        """Whether a mount event may stiffen the scene (its kind's EVENT_STIFFENS)."""
        kind = next(k for name, k in self._event_meta.values() if name == event.mount)
        return bool(kind.EVENT_STIFFENS[kind.EVENTS.index(event.event)])

    def _drain_events(self) -> list[MountEvent]:
        """Move the kernel's event log into MountEvents (health window and `events`); returns
        the new ones (those the log could hold)."""
        watch = self._watch
        n = int(watch.n_events[0])
        if n == 0:
            return []
        cap = watch.events.shape[0]
        if n > cap:
            self.counts["mount_events_dropped"] += n - cap
        new = []
        for t, slot, e, force in watch.events[: min(n, cap)].tolist():
            name, kind = self._event_meta[int(slot)]
            new.append(MountEvent(t, name, kind.EVENTS[int(e)], force, kind.EVENT_ERROR[int(e)]))
        watch.n_events[0] = 0
        self.counts["mount_events"] += len(new)
        room = MAX_EVENTS - len(self.events)
        self.events.extend(new[: max(room, 0)])
        self.health.add_events(new)
        return new

    def _gather(self, run: Run, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Take a run's samples toward a start (`initial.gravity_samples` of them).

        Returns the run's samples from the start sample on (none while still gathering) and
        the specific forces (m/s², F) gathered for the start, the start sample's last.
        """
        if run.restart:
            self._gathered = []
        need = self._start_samples - len(self._gathered)
        taken = run.index[:need]
        self._gathered.extend(f[taken])
        if len(self._gathered) < self._start_samples:
            return run.index[:0], np.empty((0, 3))
        gathered, self._gathered = np.array(self._gathered), []
        return run.index[len(taken) - 1 :], gathered

    def _start(
        self,
        i: int,
        stamps: np.ndarray,
        f: np.ndarray,
        w: np.ndarray,
        gathered: np.ndarray,
        rows: _BatchRows,
    ) -> _Rows | None:
        """(Re)start the twin at sample i, under the mean specific force of `gathered` (m/s²,
        F; sample i's last) as gravity and sample i's rotation rate (as the gyro policy takes
        it) where the scene starts at equilibrium under the input; its outputs are published
        (into `rows`). A restart keeps the mounts' damage (fracture, plastic elongation,
        hysteresis) and starts the machine as it is at rest in its own equilibrium
        (`restart.start_state`). None: it has none; the twin follows no more (nothing
        published) until a later restart finds one."""
        internal = self._y[2 * len(self.scene.dofs) :].copy()
        damage = internal if self.counts["starts"] and np.isfinite(internal).all() else None
        if self._last is not None or self.counts["starts"]:
            self.counts["restarts"] += 1
        self.counts["starts"] += 1
        stamp = float(stamps[i])
        f0 = gathered.mean(axis=0)
        w0 = w[i].copy()
        start = start_state(self.model, self._y_nominal, self._gravity_up, f0, w0, damage)
        self._check_start(stamp, f0, gathered)
        if start.state is None:
            self._stop_following(stamp, f"{start.note}{self._damage_text()}")
            self.counts["starts_without_equilibrium"] += 1
            return None
        if start.note is not None:
            self.counts["starts_at_nominal_gravity"] += 1
            self.health.failure(stamp, start.note)
        self._y = start.state
        self.stepper.reset()
        self._peak[:] = 0.0
        self._counter[0] = 0
        self._last = (stamp, f[i].copy(), w0)
        pose, wrenches = self._start_outputs(self._y, self._scratch, self._watch)
        if isinstance(self._estimator, Estimator):
            estimator.restart(self._estimator)
        elif self._estimator is not None:
            companion.restart(self._estimator, self._y)
        rows.pose[i + 1], rows.wrenches[i + 1] = pose[0], wrenches[0]
        return _Rows(np.array([i]), rows.pose[i + 1 : i + 2], rows.wrenches[i + 1 : i + 2])

    def _damage_text(self) -> str:
        """'; at the last sample: <mount> <condition>, ...' of the error conditions holding
        at the last sample (a broken bolt), or ''."""
        held = [f"{m} {e}" for m, now in self._active().items() for e, error in now if error]
        return f"; at the last sample: {', '.join(held)}" if held else ""

    def _stop_following(self, stamp: float, why: str) -> None:
        """Follow no more from `stamp` (s): nothing is published until a restart, and every
        report says why at ERROR."""
        self.health.stop(stamp, why)
        self._last = None

    def _check_start(self, stamp: float, f0: np.ndarray, gathered: np.ndarray) -> None:
        """Start checks on the start specific force f0 (m/s², F) and the samples it is the mean
        of: its magnitude against g, its angle from +z of F (where g > 0), and their spread (at
        rest?), in units of g (of standard gravity at g = 0: `InputSpec.g_scale`). An
        implausible sag (units?) is the scene's load-time warning (scene.checks), not repeated."""
        spec, init = self.scene.input, self.scene.initial
        g, unit, magnitude = spec.g, spec.g_scale, float(np.linalg.norm(f0))
        tilt = math.atan2(math.hypot(f0[0], f0[1]), f0[2]) if g > 0.0 else 0.0
        off = abs(magnitude - g) / unit
        spread = float(np.linalg.norm(gathered - f0, axis=1).max())
        notes: list[tuple[int, str]] = []
        if off > init.gravity_tolerance:
            notes.append(
                (
                    ERROR if off > 3.0 * init.gravity_tolerance else WARN,
                    f"start specific force |f0| = {magnitude:.4g} m/s² is "
                    f"{magnitude / unit:.3g} g{'' if g > 0.0 else ' (standard)'} "
                    f"({_start_hint(spec, magnitude)})",
                )
            )
        if tilt > init.tilt_tolerance_rad:
            notes.append(
                (
                    ERROR if tilt > 3.0 * init.tilt_tolerance_rad else WARN,
                    f"start specific force is {math.degrees(tilt):.1f}° from +z of F "
                    "(is input.sensor_rpy right?)",
                )
            )
        if spread > init.gravity_tolerance * unit:
            notes.append(
                (
                    WARN,
                    f"not at rest over the {gathered.shape[0]} start samples: they spread "
                    f"{spread:.3g} m/s² about their mean",
                )
            )
        self.health.start_checked(stamp, magnitude, tilt, notes)

    def _start_outputs(
        self, y: np.ndarray, scratch: Scratch, watch: Watch
    ) -> tuple[np.ndarray, np.ndarray]:
        """Outputs (pose, wrenches rows) of a start state y; arms the mount monitors there."""
        pose, wrenches = np.zeros((1, pose_row.WIDTH)), np.zeros((1, self.model.n_mounts, 6))
        ct = evaluate(y, self.model.arrays, scratch, pose[0], wrenches[0])
        if not math.isfinite(ct):
            msg = f"{self.scene.source}: initial_state.pose is off the α/γ/δ chart"
            raise ValueError(msg)
        nl = self.model.arrays.nl
        if nl is not None:
            watch.y_prev[:] = y
            mount_monitors(y, y, nl, scratch, watch.g_prev, watch.util)
        return pose, wrenches
