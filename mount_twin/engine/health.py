"""Health of the running twin over a diagnostics period: the window's figures (input,
integration, attitude, mounts), gathered until a report is due; the statuses it reports are
worded by `health_statuses` (the input status by `input_status`), in the texts of
`health_texts`."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from mount_twin.engine.batch import HealthReport, MountEvent
from mount_twin.engine.delay_line import filter_bands
from mount_twin.engine.estimate import N_FIGURES, ErrorEstimate, accumulate
from mount_twin.engine.gyro_filter import Design
from mount_twin.engine.health_statuses import HealthStatuses
from mount_twin.engine.tilt import tilt_from_cos, tilt_from_quaternions
from mount_twin.physics import pose_row
from mount_twin.scene.description import Scene
from mount_twin.scene.reader import kept_text

HOLE = 1.5
"""A stamp interval longer than HOLE nominal intervals is a hole: samples were lost."""
WRONG_FRAMES_COUNTED = 1000
"""Distinct wrong frame_ids a period keeps (each as `kept_text` keeps it) to name and count; a
period with more says 'over' that many. A hostile publisher varying its frame_id at every
message cannot make a period hold more than these."""


class HealthWindow(HealthStatuses):
    """Accumulates figures between diagnostics and builds the reports when one is due."""

    def __init__(self, scene: Scene, method: str) -> None:
        self.scene = scene
        self.method = method
        self.period = scene.outputs.diagnostics_period_s
        self.origin_s = 0
        """Whole seconds to add to engine stamps in texts, so they read as header stamps."""
        self._next_due: float | None = None
        self._reset()
        self._last_counts: Counter[str] = Counter()
        self.estimate_run = np.zeros(N_FIGURES)
        """The error estimate's figures over the whole run (`engine.estimator`)."""
        self.intervals_run = 0
        """Input intervals integrated over the whole run (`add_steps`): none, the integration
        has not run (NOT_RUN, NO_INTERVAL_RUN)."""
        self.stopped_at: float | None = None
        """Stamp (s) from which the twin follows no more (a given initial motion whose stepper
        failed, a start without equilibrium) until a restart; each report says so at ERROR."""
        self.stopped_why = ""
        """Why it stopped (`stop`)."""
        self.gathering: tuple[int, int] | None = None
        """(samples gathered, samples a start takes) while samples are gathered toward a start
        (`starts.Starts.gather`); None otherwise."""
        self.last_wrong_frame_id: str | None = None
        """header.frame_id of the last sample rejected as wrong_frame (any period), as
        `kept_text` keeps it (a hostile one shortened, with its length)."""
        self.latency: tuple[int, float] | None = None if filter_bands(scene.input) else (0, 0.0)
        """Samples and seconds by which outputs follow their input (the gyro delay); None until
        the `linear_phase` filter is designed (NOT_DESIGNED), the others have none."""

    def _reset(self) -> None:
        self.published = False
        """Whether rows were published in this window."""
        self.wall = 0.0
        self.err_max = 0.0
        self.estimate = np.zeros(N_FIGURES)
        self.substeps = 0
        self.samples = 0
        """Input intervals integrated in this window (`add_steps`: one per sample reached)."""
        self.tilt_max = 0.0
        self.failures: list[tuple[float, str]] = []
        """(stamp s, cause) of each stepper failure."""
        self.forced: list[tuple[float, str]] = []
        """(stamp s, why) of each start forced away from equilibrium under the input."""
        self.wrench_peak = np.zeros((len(self.scene.mounts), 6))
        self.events: list[MountEvent] = []
        self.steps: list[np.ndarray] = []
        self.n_steps = 0
        self.skipped: list[tuple[int, int]] = []
        """(position among this window's steps, samples rejected within that interval)."""
        self.wrong_frames: dict[str, None] = {}
        """The distinct wrong frame_ids of this window in arrival order, as `kept_text` keeps
        them, at most WRONG_FRAMES_COUNTED: a 100 kB frame id kept whole until the report, at
        10 kHz, held a gigabyte a second."""
        self.wrong_frames_uncounted = False
        """Whether this window saw distinct wrong frame_ids beyond those kept."""
        self.starts: list[tuple[float, float, float, list[tuple[int, str]]]] = []
        """(stamp s, |f0| m/s², tilt of f0 rad, findings (level, text)) per start."""
        self.notes: list[str] = []
        """Warnings on how the input is taken (a gyro filter the sample rate cannot carry)."""

    def pending(self, counts: Counter[str]) -> bool:
        """Whether anything happened since the last report: an input sample received (the
        engine's `counts`; samples merely gathered toward a start leave nothing else) or
        anything recorded."""
        new = counts["received"] - self._last_counts["received"]
        return bool(
            new or self.samples or self.events or self.failures or self.starts or self.published
        )

    def gyro_designed(self, stamp: float, design: Design) -> None:
        """The gyro filter designed at the interval into `stamp` (s): its latency from now on;
        a fallback to the raw gyro is a warning of this period."""
        self.latency = (design.delay, design.delay_s)
        if design.note:
            self.notes.append(f"{self.origin_s + stamp:.6f} s: {design.note}")

    def add_steps(self, step_log: np.ndarray) -> int:
        """Per-sample stepper figures: (error norm, accepted, rejected substeps); returns the
        substeps they took (the engine counts them too)."""
        if not step_log.shape[0]:
            return 0
        substeps = int(step_log[:, 1:].sum())
        self.err_max = max(self.err_max, float(step_log[:, 0].max()))
        self.substeps += substeps
        self.samples += step_log.shape[0]
        self.intervals_run += step_log.shape[0]
        return substeps

    def add_estimate(self, figures: np.ndarray) -> None:
        """The error estimate's figures since the last call (`engine.estimator`)."""
        accumulate(self.estimate, figures)
        accumulate(self.estimate_run, figures)

    def run_estimate(self) -> ErrorEstimate:
        """The error estimate over the run so far (no figures before an interval was
        integrated)."""
        return ErrorEstimate.of(self.estimate_run, self.intervals_run)

    def add_outputs(self, stamps: np.ndarray, pose: np.ndarray, wrenches: np.ndarray) -> None:
        """Published rows: their stamps (s), poses and mount wrenches (N, N·m, mount axes)."""
        if stamps.shape[0] == 0:
            return
        tilt = float(tilt_from_quaternions(pose[:, pose_row.QUATERNION_COLS]).max())
        self._add_peaks(np.abs(wrenches).max(axis=0), tilt)

    def add_output_peaks(self, wrench_abs_max: np.ndarray, cos_tilt_min: float) -> None:
        """`add_outputs` from the figures of published rows that the compiled loop folds in
        (`kernel.Published`): the largest |wrench component| per mount (n, 6; N, N·m) and the
        smallest cos θ (R₃₃)."""
        self._add_peaks(wrench_abs_max, float(tilt_from_cos(cos_tilt_min)))

    def _add_peaks(self, wrench_abs_max: np.ndarray, tilt_max_rad: float) -> None:
        """Published rows' largest |wrench component| per mount (n, 6; N, N·m) and largest
        tilt (rad)."""
        np.maximum(self.wrench_peak, wrench_abs_max, out=self.wrench_peak)
        self.published = True
        self.tilt_max = max(self.tilt_max, tilt_max_rad)

    def add_intervals(self, steps: np.ndarray, skipped: dict[int, int]) -> None:
        """Stamp intervals (s) into samples with a plain ACCEPT or a gap verdict (a gap is input
        lost too), each from the previous taken sample, in order; `skipped`: position in
        `steps` → samples received within that interval but rejected (where not 0)."""
        if steps.shape[0]:
            self.skipped.extend((self.n_steps + i, n) for i, n in skipped.items())
            self.steps.append(steps)
            self.n_steps += steps.shape[0]

    def add_wrong_frames(self, frame_ids: list[str]) -> None:
        """header.frame_id of samples rejected as wrong_frame, in arrival order: kept as
        published (`kept_text`), the distinct ones up to WRONG_FRAMES_COUNTED."""
        for kept in map(kept_text, dict.fromkeys(frame_ids)):
            if kept in self.wrong_frames:
                continue
            if len(self.wrong_frames) < WRONG_FRAMES_COUNTED:
                self.wrong_frames[kept] = None
            else:
                self.wrong_frames_uncounted = True
        if frame_ids:
            self.last_wrong_frame_id = kept_text(frame_ids[-1])

    def lost_estimate(self) -> tuple[int, float]:
        """Samples lost in this window, estimated from its stamp intervals, and the nominal
        interval (s; NaN without intervals).

        An interval of k nominal intervals (rounded; a hole past HOLE of them) lost k − 1
        samples, less those received in it and rejected. The nominal interval is the mean of
        the intervals within (2 − HOLE, HOLE) times their median: free of the median's
        granularity, so that the window's whole span can be counted in it too. Stamps taken by
        the host at sending rather than by the sensor show a hole where a sample was merely
        late, and the held-back samples crowd in behind it; the span counts no sample lost
        there, so the estimate is at most what the span holds beyond the window's samples.
        Windows of the same samples give the same figures however the samples were pushed.
        """
        steps = self._intervals()
        if not steps.shape[0]:
            return 0, math.nan
        median = _median(steps)
        regular = (steps > (2.0 - HOLE) * median) & (steps < HOLE * median)
        n_regular = int(np.count_nonzero(regular))
        nominal = float(steps[regular].sum()) / n_regular if n_regular else median
        hole = steps > HOLE * nominal
        if not hole.any():
            return 0, nominal
        skipped = np.zeros(steps.shape[0])
        for i, n in self.skipped:
            skipped[i] = n
        missing = np.maximum(np.rint(steps[hole] / nominal) - 1.0 - skipped[hole], 0.0).sum()
        beyond_span = np.rint(steps.sum() / nominal) - steps.shape[0] - skipped.sum()
        return int(min(missing, max(beyond_span, 0.0))), nominal

    def _input_rate(self) -> float:
        """Samples per second of input stamps in this window, as `ros2 topic hz` counts them:
        the samples its stamp intervals lead into (those rejected within an interval too) over
        the intervals' sum, a hole's included; NaN without intervals. Not the accepted count
        over the outputs' span, which the gyro delay shifts and which holds one interval fewer
        than samples: 1040.5, 1001.0 and 964.3 Hz for a 1 kHz input."""
        total = self._stamp_seconds()
        samples = self.n_steps + sum(n for _, n in self.skipped)
        return samples / total if total > 0.0 else math.nan

    def _stamp_seconds(self) -> float:
        """The input's stamp time this window's intervals cover, s (0 without intervals): the
        time the twin advanced over them, a hole's included."""
        return float(self._intervals().sum())  # one array: any batching, one sum

    def _intervals(self) -> np.ndarray:
        """This window's stamp intervals (`add_intervals`), s, as one array (kept so)."""
        if len(self.steps) != 1:
            self.steps = [np.concatenate([np.zeros(0), *self.steps])]
        return self.steps[0]

    def restart_cadence(self) -> None:
        """Make the next accepted sample start the report cadence afresh (after a stall)."""
        self._next_due = None

    def add_wall(self, wall_s: float) -> None:
        """Wall time spent on the samples of this window, s."""
        self.wall += wall_s

    def add_events(self, events: list[MountEvent]) -> None:
        """Mount events of this window."""
        self.events.extend(events)

    def start_checked(
        self, stamp: float, magnitude: float, tilt: float, notes: list[tuple[int, str]]
    ) -> None:
        """A (re)start at `stamp` (s) under a specific force of `magnitude` (m/s²) at `tilt`
        (rad) from +z of F, with the start checks' findings (level, text)."""
        self.starts.append((stamp, magnitude, tilt, notes))

    def stop(self, stamp: float, why: str) -> None:
        """The twin follows no more from `stamp` (s), because `why`."""
        self.stopped_at, self.stopped_why = stamp, why

    def failure(self, stamp: float, text: str) -> None:
        """A stepper failure at `stamp` (s), its cause."""
        self.failures.append((stamp, text))

    def forced_start(self, stamp: float, text: str) -> None:
        """A start at `stamp` (s) away from equilibrium under the input (none found), why."""
        self.forced.append((stamp, text))

    def tick(self, stamp: float) -> bool:
        """An accepted sample at `stamp` (s): is a report due once it is processed?

        Reports come one period of stamps apart; a stamp before the current window (a bag
        played in a loop) starts the cadence afresh.
        """
        if self._next_due is None or stamp < self._next_due - self.period:
            self._next_due = stamp + self.period
            return False
        if stamp < self._next_due:
            return False
        self._next_due = stamp + self.period
        return True

    def ticks(self, stamps: np.ndarray) -> list[int]:
        """`tick` for accepted samples in increasing order after the last ticked one: the
        positions after which reports are due (one search per report, not a loop per sample)."""
        due: list[int] = []
        start = 0
        if self._next_due is None:
            self._next_due = float(stamps[0]) + self.period
            start = 1
        while True:
            k = start + int(np.searchsorted(stamps[start:], self._next_due, side="left"))
            if k >= stamps.shape[0]:
                return due
            due.append(k)
            self._next_due = float(stamps[k]) + self.period
            start = k + 1

    def report(
        self,
        stamp: float,
        sample: int,
        counts: Counter[str],
        utilisation: np.ndarray,
        active: dict[str, list[tuple[str, bool]]],
        *,
        lost_from_stamps: int = 0,
        nominal_interval_s: float = math.nan,
        stalled_s: float | None = None,
        ended: bool = False,
    ) -> HealthReport:
        """Statuses at `stamp` (s), after pushed sample `sample`, for the window so far, which
        then starts anew.

        Counts are cumulative; rejections, gaps, losses, stepper figures, mount peaks and events
        are this window's. `utilisation`: peak per mount, in scene order (NaN: no rating);
        `active`:
        the conditions holding now per mount (event name, is an error), e.g. a broken bolt,
        which keep the mount's level after the events themselves have been reported.
        `lost_from_stamps`, `nominal_interval_s` (s): `lost_estimate` of this window (already
        added to counts["lost_estimated"]). `stalled_s`: set by a live adapter's stall timer,
        the clock time (s) since the last report, or `ENDED` when the input ended (a bag) with
        no sample accepted since; the input status is then an ERROR. `ended`: the stream's
        last report (a run whose twin never started then says so at ERROR).
        """
        new = counts - self._last_counts
        self._last_counts = counts.copy()
        inp = self._input_status(
            new, counts, self._input_rate(), lost_from_stamps, nominal_interval_s, stalled_s
        )
        step = self._integration_status(counts, new, self._stamp_seconds(), ended)
        why = self._not_computed(counts, new)
        if why is not None:  # no utilisation either
            utilisation = np.full_like(utilisation, math.nan)
        unpublished = why or self._not_published()
        att = self._attitude_status(unpublished)
        mounts = self._mount_statuses(utilisation, active, unpublished)
        self._reset()
        return HealthReport(stamp, sample, [inp, step, att, *mounts])


def _median(values: np.ndarray) -> float:
    """np.median of a non-empty 1-D array, the same number, by one partition (np.median's
    generic reduction cost most of a report's lost-sample estimate)."""
    n = values.shape[0]
    half = n // 2
    if n % 2:
        return float(np.partition(values, half)[half])
    low, high = np.partition(values, (half - 1, half))[half - 1 : half + 1]
    return float((low + high) / 2.0)
