"""Health of the running twin over a diagnostics period: input, integration, attitude."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from mount_twin.engine.batch import ERROR, OK, WARN, HealthReport, HealthStatus, MountEvent
from mount_twin.engine.delay_line import filter_bands
from mount_twin.engine.estimate import (
    FORCE_SCALE,
    N_FIGURES,
    WARN_FORCE_ERROR_REL,
    ErrorEstimate,
    accumulate,
)
from mount_twin.engine.gyro_filter import Design
from mount_twin.physics import pose_row
from mount_twin.physics.rotations import angle_text
from mount_twin.scene.description import Scene
from mount_twin.scene.reader import kept_text, shown_text

PREFIX = "mount_twin"
INTEGRATION = f"{PREFIX}: integration"
"""Name of the integration status."""
INPUT = f"{PREFIX}: input"
"""Name of the input status."""
ATTITUDE = f"{PREFIX}: attitude"
"""Name of the attitude status."""
MOUNT = f"{PREFIX}: mount "
"""A mount status' name: MOUNT + the mount's name."""
NO_SAMPLE_ACCEPTED = "no input sample was accepted"
"""Why a run computed nothing at all (NOT_RUN, NOT_COMPUTED; the replay's summary)."""
NOT_RUN = f"not run: {NO_SAMPLE_ACCEPTED}"
"""The integration status' text while no input sample has been accepted (it had read "ok",
as if the twin had integrated the run clean)."""
NO_INTERVAL_RUN = "not run: no input interval was integrated"
"""The integration status' text while samples were accepted but no interval between two was
integrated (one sample: it had read "ok", as if the twin had integrated the run clean)."""
NOT_COMPUTED = f"not computed: {NO_SAMPLE_ACCEPTED}"
"""The attitude and mount statuses' text while no input sample has been accepted, their
figures "n/a" (they had read "ok" with a tilt and peaks of 0, as a machine at rest)."""
NOT_COMPUTED_HERE = "not computed in this period"
"""The attitude and mount statuses' text, with why, for a period that computed no motion and
no mount load after samples were accepted before it (a stall, a twin that follows no more)."""
NOT_RUN_HERE = "not run in this period"
"""The integration status' text, with why, for a period that integrated no input interval in a
run that integrated some before it (a stall, a restart gathering its samples): its stepper
figures "n/a" (it had read "ok")."""
NOT_PUBLISHED_HERE = "no row published in this period"
"""The attitude and mount statuses' text, with why, for a period that integrated samples but
published none of them (`outputs.decimation` above its samples): its tilt and peaks, figures of
published rows, "n/a" (they had read 0, a machine at rest), the utilisation its own."""
NEVER_STARTED = "the twin never started"
"""What a run that accepted samples but ended before a start says (`HealthWindow.never_started`):
fewer samples than `initial_state.gravity_samples` (it had written no report at all, and its
replay read OK)."""
NOT_DESIGNED = (
    "the gyro filter was never designed: no two input samples were accepted without a restart "
    "between them"
)
"""Why a run of `input.gyro_filter: linear_phase` has no latency figure (`HealthWindow.latency`
None): the filter is designed at the rate of its first accepted samples (it had read 0 s, as
if the outputs followed their input at once)."""

PEAK_KEYS = tuple(f"peak_{axis}" for axis in ("fx_N", "fy_N", "fz_N", "tx_Nm", "ty_Nm", "tz_Nm"))
"""A mount status' keys of its peak wrench components in this period (N, N·m, mount axes)."""
TILT_KEY = "tilt_max_rad"
"""The attitude status' key of the largest tilt in this period (rad)."""
UTILISATION_KEY = "utilisation_max"
"""A mount status' key of its largest utilisation in this period ("n/a": none rated)."""
EVENTS_KEY = "events"
"""A mount status' key of the number of its events in this period."""
NOW_KEY = "now"
"""A mount status' key of the conditions holding at the report ("none": none)."""
HOLE = 1.5
"""A stamp interval longer than HOLE nominal intervals is a hole: samples were lost."""
LOST_ERROR = 0.01
"""Fraction of (accepted + lost) samples lost in a period past which the input is an ERROR."""
NOT_UNUSABLE = ("duplicate_stamp", "wrong_frame")
"""Rejection reasons that are not the sensor's readings unusable: a repeat, another sensor's."""
REJECTED_ERROR = 0.1
"""Fraction of the readings received in a period (`NOT_UNUSABLE` aside) rejected past which
the input is an ERROR: a sensor a tenth of whose readings are unusable is broken (a record 90 %
NaN read WARN, and its replay exited 0 under --fail-on error)."""
SATURATION_SHARE = 0.999
"""A reading at this share of `input.accel_range_m_s2` (or `gyro_range_rad_s`) is saturated."""
PLATEAU_G = 2.0
"""A reading repeated exactly, sample after sample, beyond this many g (`InputSpec.g_scale`) is a
plateau: a clipped or stuck sensor (real vibration never repeats to the last bit)."""
ENDED = math.inf
"""`HealthWindow.report`'s `stalled_s` when the input ended with no sample accepted since the
last report (`TwinEngine.flush`)."""
NAMED_FRAMES = 3
"""Wrong frame_ids named in a message (the rest are counted)."""
WRONG_FRAMES_COUNTED = 1000
"""Distinct wrong frame_ids a period keeps (each as `kept_text` keeps it) to name and count; a
period with more says 'over' that many. A hostile publisher varying its frame_id at every
message cannot make a period hold more than these."""


def ratio_text(value: float, spec: str = ".3g", limit: float = 1.0) -> str:
    """A utilisation (or another ratio judged against `limit`) as text, `format(value, spec)`
    with more digits where rounding would carry it onto or across the limit: 0.99983 reads
    0.9998, not 1 (the limit, whose reaching is an ERROR, said of a mount at WARN)."""
    text = format(value, spec)
    kind = spec[-1]
    digits = int(spec[1:-1])
    while (float(text) >= limit) != (value >= limit) and digits < 17:
        digits += 1
        text = format(value, f".{digits}{kind}")
    return text


def tilt_from_quaternions(quat: np.ndarray) -> np.ndarray:
    """Tilt θ of body z from the vertical of F, rad, for (k, 4) quaternions (x, y, z, w)."""
    return tilt_from_cos(1.0 - 2.0 * (quat[:, 0] ** 2 + quat[:, 1] ** 2))  # R₃₃ = cos θ


def tilt_from_cos(cos_tilt: np.ndarray | float) -> np.ndarray:
    """Tilt θ, rad, from cos θ = R₃₃ (clipped to [−1, 1]: rounding may step past it)."""
    if isinstance(cos_tilt, float):  # a live push's one figure: np.clip of a float takes 2 µs
        return np.arccos(min(max(cos_tilt, -1.0), 1.0))  # NaN stays NaN, as np.clip keeps it
    return np.arccos(np.clip(cos_tilt, -1.0, 1.0))


def why_none(nothing: str) -> str:
    """A run's reason for having followed none of its input (`nothing`: no sample accepted,
    or NEVER_STARTED and its details) without the details, after "none, " or "no figure: "."""
    return NEVER_STARTED if nothing.startswith(NEVER_STARTED) else NO_SAMPLE_ACCEPTED


class HealthWindow:
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

    def gathered_text(self) -> str:
        """'3 of the initial_state.gravity_samples 5 gathered toward a start', or '' where no
        start is gathered (`gathering`)."""
        if self.gathering is None:
            return ""
        k, n = self.gathering
        return f"{k} of the initial_state.gravity_samples {n} gathered toward a start"

    def never_started(self, counts: Counter[str]) -> str:
        """Why the twin never started though input samples were accepted ('' if it started,
        or none was accepted: NOT_RUN says that): NEVER_STARTED, the samples accepted and
        those gathered toward the start. Said at the input's end, a run's verdict."""
        n = counts["accepted"]
        if counts["starts"] or not n:
            return ""
        gathered = self.gathered_text()
        return f"{NEVER_STARTED}: {_samples(n)} accepted{', ' if gathered else ''}{gathered}"

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

    def _not_computed(self, counts: Counter[str], new: Counter[str]) -> str | None:
        """Why this window computed no motion and no mount load, for the attitude and mount
        statuses (None: it did): it published no row and integrated no input interval. The
        input status carries a stall's ERROR, the integration status a stop's."""
        if self.published or self.samples:
            return None
        if not counts["accepted"]:
            return NOT_COMPUTED
        return f"{NOT_COMPUTED_HERE}: {self._idle_why(new)}"

    def _not_published(self) -> str | None:
        """Why this window, which integrated samples, has no tilt nor peak of its own (None: it
        published rows, the figures' source): `outputs.decimation` published none of them, and
        the peaks since the last row go into the next one (`driver.CoreDriver.close_run`)."""
        if self.published:
            return None
        d = self.scene.outputs.decimation
        return (
            f"{NOT_PUBLISHED_HERE}: {_samples(self.samples)} integrated, outputs.decimation "
            f"{d} publishes one in {d}; their peak loads go into the next row published"
        )

    def _idle_why(self, new: Counter[str]) -> str:
        """Why this window integrated no input interval where samples were accepted before it
        or in it (`new`: this window's counts): none accepted in it, the twin follows no more,
        a start gathering its samples (`gathered_text`), or the gyro delay still holds them."""
        if not new["accepted"]:
            return "no input sample was accepted in it"
        if self.stopped_at is not None:
            return f"the twin follows no more since {self.origin_s + self.stopped_at:.6f} s"
        return self.gathered_text() or "none of its samples was integrated yet"

    def _integration_status(
        self, counts: Counter[str], new: Counter[str], span: float, ended: bool
    ) -> HealthStatus:
        """The integration status of this window (`span`: the stamp time its input intervals
        cover, s; over its wall time, the real-time factor): stepper failures and
        a stop (ERROR), notes on how the input is taken and an estimated error past
        WARN_FORCE_ERROR_REL (WARN); the solver's settings and figures as values ("n/a" where
        this window integrated no interval). Before any input interval is integrated, NOT_RUN
        or NO_INTERVAL_RUN, NOT_RUN_HERE for a later window that integrated none (`_not_run`);
        at the input's end (`ended`) a twin that never started is an ERROR (`never_started`)."""
        integ = self.scene.integration
        rtf = span / self.wall if self.wall > 0 and span > 0 else math.nan
        level, step_text = self._stepper_status(counts, new, ended)
        estimate = self._estimate_values()
        warning = estimate_warning(self.run_estimate()) if estimate else None
        for note in (*self.notes, warning):
            if note is not None:
                level = max(level, WARN)
                step_text = note + ("" if step_text == "ok" else f"; {step_text}")
        return HealthStatus(
            INTEGRATION,
            level,
            step_text,
            {
                "method": self.method,
                "rtol": f"{integ.rtol:g}",
                "atol": f"{integ.atol:g}",
                **estimate,
                "error_norm_max": f"{self.err_max:.3g}" if self.samples else "n/a",
                "substeps_per_sample": f"{self.substeps / self.samples:.2f}"
                if self.samples
                else "n/a",
                "real_time_factor": f"{rtf:.1f}",
                "failures_total": str(counts["integration_failures"]),
                "method_switches_total": str(counts["method_switches"]),
                "latency_samples": "n/a" if self.latency is None else str(self.latency[0]),
                "latency_s": "n/a" if self.latency is None else f"{self.latency[1]:.6g}",
            },
        )

    def _stepper_status(
        self, counts: Counter[str], new: Counter[str], ended: bool
    ) -> tuple[int, str]:
        """Level and text of the stepper in this window: ERROR with its failures and forced
        starts (stamps in s) or a stop, or a twin that never started by the input's end
        (`ended`), else OK (`_not_run` where this window integrated no interval)."""

        def listed(what: list[tuple[float, str]]) -> str:
            return "; ".join(f"{self.origin_s + t:.6f} s: {m}" for t, m in what)

        said = []
        if self.failures:
            said.append(f"stepper failed and the twin restarted: {listed(self.failures)}")
        if self.forced:
            said.append(f"started away from equilibrium: {listed(self.forced)}")
        if self.stopped_at is not None:
            step_text = (
                f"not following since {self.origin_s + self.stopped_at:.6f} s: "
                f"{self.stopped_why}; no pose, angles or wrenches until a restart (a gap or "
                "the stamps jumping back) finds a state to start from"
                + (f" ({'; '.join(said)})" if said else "")
            )
        elif ended and (never := self.never_started(counts)):
            said.append(never)
            step_text = "; ".join(said)
        else:
            step_text = "; ".join(said) or self._not_run(counts, new) or "ok"
        return (ERROR if said or self.stopped_at is not None else OK), step_text

    def _not_run(self, counts: Counter[str], new: Counter[str]) -> str | None:
        """Why this window integrated no input interval (None: it integrated one): NOT_RUN
        where no input sample was accepted, NO_INTERVAL_RUN where the run integrated none yet
        (one sample, or all gathered toward a start), else NOT_RUN_HERE and why
        (`_idle_why`)."""
        if self.samples:
            return None
        n = counts["accepted"]
        if not n:
            return NOT_RUN
        if not self.intervals_run:
            gathered = self.gathered_text()
            return (
                f"{NO_INTERVAL_RUN} ({_samples(n)} accepted{', ' if gathered else ''}{gathered})"
            )
        return f"{NOT_RUN_HERE}: {self._idle_why(new)}"

    def _attitude_status(self, no_rows: str | None) -> HealthStatus:
        """The attitude status of this window: WARN past `outputs.tilt_warn_rad` of tilt, where
        the α/γ/δ chart degrades; `no_rows` (`_not_computed`, `_not_published`: why it has no
        published row) at OK, tilt "n/a"."""
        if no_rows is not None:
            return HealthStatus(ATTITUDE, OK, no_rows, {TILT_KEY: "n/a"})
        warn = self.scene.outputs.tilt_warn_rad
        return HealthStatus(
            ATTITUDE,
            WARN if self.tilt_max > warn else OK,
            f"tilt {angle_text(self.tilt_max)} past outputs.tilt_warn_rad {warn:.4g}: the α/γ/δ "
            f"chart degrades toward {angle_text(math.pi / 2)}"
            if self.tilt_max > warn
            else "ok",
            {TILT_KEY: f"{self.tilt_max:.6g}"},
        )

    def _estimate_values(self) -> dict[str, str]:
        """The estimated errors of the period and, `_run`, of the run so far as diagnostic
        values (none: the estimate is off).

        The relative force error is the largest |ΔF| (of the period, of the run so far) over
        the largest |F| component of the run so far: the run's figure is the one the replay
        summary gives at the end (`TwinEngine.error_estimate`), and the period's never exceeds
        it."""
        if not self.scene.integration.error_estimate:
            return {}
        period = self.estimate.copy()
        period[FORCE_SCALE] = self.estimate_run[FORCE_SCALE]
        est, run = ErrorEstimate.of(period, self.samples), self.run_estimate()
        return {
            "est_force_error_rel": f"{est.force_error_rel:.2g}",
            "est_force_error_n": f"{est.force_error_n:.3g}",
            "est_attitude_error_rad": f"{est.attitude_error_rad:.2g}",
            "est_failed_checks": str(est.failed_checks),
            "est_uncarried_states": str(est.uncarried_states),
            "est_force_error_rel_run": f"{run.force_error_rel:.2g}",
            "est_force_error_n_run": f"{run.force_error_n:.3g}",
            "est_attitude_error_rad_run": f"{run.attitude_error_rad:.2g}",
        }

    def _mount_statuses(
        self,
        utilisation: np.ndarray,
        active: dict[str, list[tuple[str, bool]]],
        no_rows: str | None,
    ) -> list[HealthStatus]:
        """One status per mount: peak wrench per axis, utilisation (NaN: none), events by
        name, and the conditions holding now; `no_rows` (`_not_computed`, `_not_published`:
        why the window has no published row) said beside them, "ok" aside, the peaks "n/a"
        (the conditions holding keep their level)."""
        warn_at = 1.0 - self.scene.outputs.alarm_margin
        events: dict[str, list[MountEvent]] = {}
        for event in self.events:
            events.setdefault(event.mount, []).append(event)
        out = []
        for mount, u, peak in zip(
            self.scene.mounts, utilisation.tolist(), self.wrench_peak.tolist(), strict=True
        ):
            mine = events.get(mount.name, [])
            now = active.get(mount.name, [])
            if any(e.error for e in mine) or any(err for _, err in now) or u > 1.0:
                level = ERROR
            elif mine or now or u >= warn_at:
                level = WARN
            else:
                level = OK
            values = {
                key: "n/a" if no_rows else f"{v:.6g}"
                for key, v in zip(PEAK_KEYS, peak, strict=True)
            }
            values[UTILISATION_KEY] = "n/a" if math.isnan(u) else f"{u:.6g}"
            values[EVENTS_KEY] = str(len(mine))
            values.update(_event_values(mine, self.origin_s))
            values[NOW_KEY] = ", ".join(name for name, _ in now) or "none"
            text = _events_text(mine, u, self.origin_s)
            if no_rows:
                text = no_rows if text == "ok" else f"{text}; {no_rows}"
            if now:
                text = f"now: {values[NOW_KEY]}" + ("" if text == "ok" else f"; {text}")
            out.append(HealthStatus(MOUNT + mount.name, level, text, values))
        return out

    def _input_status(
        self,
        new: Counter[str],
        counts: Counter[str],
        rate_hz: float,
        lost_from_stamps: int,
        nominal_s: float,
        stalled_s: float | None,
    ) -> HealthStatus:
        """The input status of this window: rejections and gaps (WARN; ERROR where the
        readings rejected, duplicates aside, pass REJECTED_ERROR of those received), lost samples
        (WARN, ERROR past LOST_ERROR of the samples due), a stall (ERROR)."""
        new_rejected = {
            k.removeprefix("rejected_"): v
            for k, v in sorted(new.items())
            if k.startswith("rejected_")
        }
        n_rejected = sum(new_rejected.values())
        # Adapter counters (lost_middleware, ...) and stamp holes see the same lost samples (a
        # message lost in DDS leaves a hole in the stamps): the larger figure is the estimate.
        reported = {
            k: v for k, v in sorted(new.items()) if k.startswith("lost_") and k != "lost_estimated"
        }
        lost = max(lost_from_stamps, sum(reported.values()))

        parts: list[str] = []
        level = OK
        all_rejected = False
        if stalled_s is not None:
            level = ERROR
            stall, all_rejected = self._stall_text(new, counts, new_rejected, stalled_s)
            parts.append(stall)
        for stamp, _, _, notes in self.starts:
            for note_level, text in notes:
                level = max(level, note_level)
                parts.append(f"start at {self.origin_s + stamp:.6f} s: {text}")
        if (n_rejected and not all_rejected) or new["gaps"]:
            # readings of the sensor the twin could not use (a duplicate stamp loses none,
            # another sensor's on the topic are not this one's)
            unseen = n_rejected - sum(new_rejected.get(r, 0) for r in NOT_UNUSABLE)
            share = unseen / (new["accepted"] + unseen) if unseen else 0.0
            level = max(level, ERROR if share > REJECTED_ERROR else WARN)
            detail = ""
            if "wrong_frame" in new_rejected:
                detail = f" ({self._reason('wrong_frame', new_rejected['wrong_frame'])})"
            if share > REJECTED_ERROR:
                detail += f", {share:.3g} of the readings"
            parts.append(
                f"{n_rejected} samples rejected{detail}, {new['gaps']} gaps in this period"
            )
        for finding in self._sensor_findings(new):
            level = max(level, WARN)
            parts.append(finding)
        if lost:
            share = lost / (new["accepted"] + lost)
            level = max(level, ERROR if share > LOST_ERROR else WARN)
            parts.append(_lost_text(lost, share, lost_from_stamps, nominal_s, reported))
        values = self._input_values(counts, rate_hz, lost, nominal_s, stalled_s)
        return HealthStatus(INPUT, level, "; ".join(parts) or "ok", values)

    def _stall_text(
        self,
        new: Counter[str],
        counts: Counter[str],
        new_rejected: dict[str, int],
        stalled_s: float,
    ) -> tuple[str, bool]:
        """What a stall (`stalled_s`: s since the last report, or ENDED) found in this window,
        and whether every sample received was rejected (`new_rejected`: count per reason);
        `counts`: the run's, to say what came before the window at the stream's end."""
        waited = "by the end of the input" if stalled_s == ENDED else f"for {_seconds(stalled_s)}"
        if not new["received"]:
            if stalled_s == ENDED and counts["received"]:  # not "over the run": the values
                # say what came before (a stall report took it)
                return (
                    f"no input received since the last report, {waited} ({counts['received']} "
                    f"received before it, {counts['accepted']} accepted)",
                    False,
                )
            return f"no input received {waited}", False
        if not new["accepted"]:
            all_rejected = sum(new_rejected.values()) > 0
            why = ", ".join(self._reason(r, n) for r, n in new_rejected.items())
            text = f"no sample accepted {waited}: {new['received']} received, " + (
                f"all rejected ({why})" if all_rejected else "none accepted"
            )
            return text, all_rejected
        # a stall report comes after a stall period without an accepted sample (the adapter's
        # condition): these came before it; the input stopped or paused (it read "input
        # stalled: only 499 samples accepted in 1.0 s" after the tail of a stream at full rate)
        n = new["accepted"]
        return f"no sample accepted {waited} ({n} before it in this period)", False

    def _sensor_findings(self, new: Counter[str]) -> list[str]:
        """Warnings on the readings of this window: samples at the sensor's range (clipped)
        and readings repeated exactly beyond PLATEAU_G (clipped or stuck)."""
        found = []
        if new["saturated"]:
            spec = self.scene.input
            ranges = " or ".join(
                f"{v:g} {unit}"
                for v, unit in ((spec.accel_range_m_s2, "m/s²"), (spec.gyro_range_rad_s, "rad/s"))
                if v > 0.0
            )
            found.append(
                f"{new['saturated']} samples at the sensor's range ({ranges}): clipped, the true "
                "peaks were higher"
            )
        if new["plateau"]:
            found.append(
                f"{new['plateau']} readings beyond {PLATEAU_G:g} g repeated exactly from the "
                "sample before "
                "(a clipped or stuck sensor?)"
            )
        return found

    def _input_values(
        self,
        counts: Counter[str],
        rate_hz: float,
        lost: int,
        nominal_s: float,
        stalled_s: float | None,
    ) -> dict[str, str]:
        """The input status' values: the topic and the header.frame_id expected there (the
        scene's, or what `replay --topic`, `--frame-id` put in their place: a report names the
        run's), the rate of this window (`_input_rate`), the cumulative counts, the samples
        `lost` in this window at the nominal interval `nominal_s` (s), the time since the last
        report (`stalled_s`, s) and the last start's specific force (m/s²) and tilt (rad)."""
        values = {
            "topic": self.scene.input.topic,
            "frame_id": self.scene.input.frame_id,
            "rate_hz": "n/a" if math.isnan(rate_hz) else f"{rate_hz:.1f}",
            **{k: str(counts[k]) for k in ("received", "accepted", "gaps", "restarts")},
            **{k: str(v) for k, v in sorted(counts.items()) if k.startswith("rejected_")},
            "reset_stamp_jumped_back": str(counts["reset_stamp_jumped_back"]),
            "saturated": str(counts["saturated"]),
            "plateau": str(counts["plateau"]),
            "lost_estimated": str(counts["lost_estimated"]),
            "lost_in_period": str(lost),
            "nominal_interval_s": "n/a" if math.isnan(nominal_s) else f"{nominal_s:.6g}",
            **{
                k: str(v)
                for k, v in sorted(counts.items())
                if k.startswith("lost_") and k != "lost_estimated"
            },
        }
        if counts["rejected_wrong_frame"] and self.last_wrong_frame_id is not None:
            values["last_wrong_frame_id"] = self.last_wrong_frame_id
        if stalled_s is not None and stalled_s != ENDED:
            values["since_last_report_s"] = f"{stalled_s:.6g}"
        if self.starts:
            _, magnitude, tilt, _ = self.starts[-1]
            values["start_specific_force_m_s2"] = f"{magnitude:.6g}"
            values["start_tilt_rad"] = f"{tilt:.6g}"
        return values

    def _reason(self, reason: str, n: int) -> str:
        """'non_finite 3', or for wrong frames "wrong_frame 3: expected frame_id 'a', got 'b'"."""
        if reason != "wrong_frame" or not self.wrong_frames:
            return f"{reason} {n}"
        seen = list(self.wrong_frames)
        got = ", ".join(shown_text(f) for f in seen[:NAMED_FRAMES])  # a hostile one shortened
        if len(seen) > NAMED_FRAMES:
            over = "over " if self.wrong_frames_uncounted else ""
            got += f" and {over}{len(seen) - NAMED_FRAMES} more"
        expected = shown_text(self.scene.input.frame_id)
        return f"{reason} {n}: expected frame_id {expected}, got {got}"


def estimate_warning(run: ErrorEstimate) -> str | None:
    """The integration status' warning on the estimated error of everything published so far
    (`run`), None while it is within WARN_FORCE_ERROR_REL of the largest force: the figure of
    the diagnostics and of the replay summary, one definition."""
    if not run.force_error_rel > WARN_FORCE_ERROR_REL:  # NaN: nothing estimated yet
        return None
    return (
        f"estimated mount-force error {run.force_error_rel:.2g} of the largest force over the "
        "run so far: tighten integration.rtol"
    )


def _median(values: np.ndarray) -> float:
    """np.median of a non-empty 1-D array, the same number, by one partition (np.median's
    generic reduction cost most of a report's lost-sample estimate)."""
    n = values.shape[0]
    half = n // 2
    if n % 2:
        return float(np.partition(values, half)[half])
    low, high = np.partition(values, (half - 1, half))[half - 1 : half + 1]
    return float((low + high) / 2.0)


def _samples(n: int) -> str:
    """'1 sample', '3 samples'."""
    return f"{n} sample{'' if n == 1 else 's'}"


def _seconds(t: float) -> str:
    """A duration for a message: '1.0 s', '12.5 s', '250 ms'."""
    return f"{t:.1f} s" if t >= 1.0 else f"{t * 1e3:.0f} ms"


def _lost_text(
    lost: int, share: float, from_stamps: int, nominal_s: float, reported: dict[str, int]
) -> str:
    """'~12 samples lost in this period (1.2 %, from stamp gaps at a 1.000 ms nominal interval;
    reported lost_middleware 3)': `share` of the samples due, `from_stamps` of them estimated
    from the stamps at the nominal interval `nominal_s` (s), `reported` by the adapter."""
    sources = []
    if from_stamps:
        sources.append(f"from stamp gaps at a {nominal_s * 1e3:.3f} ms nominal interval")
    if reported:
        sources.append("reported " + ", ".join(f"{k} {v}" for k, v in reported.items()))
    return f"~{lost} samples lost in this period ({100.0 * share:.1f} %, {'; '.join(sources)})"


def _by_kind(events: list[MountEvent]) -> dict[str, list[MountEvent]]:
    """The events by kind, kinds in the order of their first event."""
    kinds: dict[str, list[MountEvent]] = {}
    for event in events:
        kinds.setdefault(event.event, []).append(event)
    return kinds


def _event_values(events: list[MountEvent], origin_s: int) -> dict[str, str]:
    """Per event kind of the period, in full: `<event>.count`, `<event>.first_stamp_ns` (the
    header stamp of its first, ns) and `<event>.force_max_N` (the largest |F|, N, repr)."""
    values = {}
    for name, same in _by_kind(events).items():
        values[f"{name}.count"] = str(len(same))
        values[f"{name}.first_stamp_ns"] = str(origin_s * 10**9 + round(same[0].stamp * 1e9))
        values[f"{name}.force_max_N"] = repr(max(e.force for e in same))
    return values


def _events_text(events: list[MountEvent], utilisation: float, origin_s: int) -> str:
    """'joint_opened ×3 (first 1.234567 s, |F| max 4.5e+04 N); …', or the utilisation."""
    if not events:
        return "ok" if not utilisation > 0.0 else f"utilisation {ratio_text(utilisation)}"
    parts = []
    for name, same in _by_kind(events).items():
        parts.append(
            f"{name} ×{len(same)} (first {origin_s + same[0].stamp:.6f} s, "
            f"|F| max {max(e.force for e in same):.4g} N)"
        )
    return "; ".join(parts)
