"""TwinEngine: a stream of input samples in, what the twin publishes out.

Knows nothing of ROS or files: adapters decode messages into `SampleBatch` and encode the
`OutputBatch` it returns. Bad samples are counted, reported and skipped; the twin keeps running.

The engine composes four parts, each in its own module, and owns only the order they act in
and what a failure does:
- `intake.Intake`: screens each sample, rotates it into F and gives its verdict;
- `starts.Starts`: gathers samples toward a start, checks it and puts the twin there;
- `driver.CoreDriver`: the twin's state and the compiled core's arrays, advanced run by run;
- `reporting.Reporting`: published rows into the health window, the OutputBatch and reports.
The gyro's delay line (`delay_line.GyroDelay`) sits between intake and the driver.
"""

from __future__ import annotations

import math
import time
from collections import Counter
from collections.abc import Callable

import numpy as np

from mount_twin.engine.batch import HealthReport, MountEvent, OutputBatch, SampleBatch
from mount_twin.engine.count_texts import nothing_accepted
from mount_twin.engine.delay_line import Frame, GyroDelay, Run, filter_bands
from mount_twin.engine.driver import CoreDriver
from mount_twin.engine.estimate import ErrorEstimate
from mount_twin.engine.gyro_filter import Design
from mount_twin.engine.health import HealthWindow
from mount_twin.engine.input_status import ENDED
from mount_twin.engine.intake import Intake, Judged, runs
from mount_twin.engine.kernel import AT_EVENT, Samples
from mount_twin.engine.reporting import Reporting
from mount_twin.engine.rows import BatchRows, Part, Tail
from mount_twin.engine.starts import Starts, start_takes
from mount_twin.errors import require
from mount_twin.integrate.stepper import STATUS_TEXT
from mount_twin.model.assemble import Model

GIVEN_MOTION_STOP = (
    "the stepper failed, and restarting a given initial motion would replay a motion the body "
    "is not making"
)
"""Why a scene with a given initial motion stops following at a stepper failure."""


def _segment(
    last: tuple[float, np.ndarray, np.ndarray] | None, index: np.ndarray, frame: Frame
) -> Samples:
    """The samples `index` of `frame` after the `last` sample done (row 0), as the core takes
    a run."""
    if last is None:
        msg = "a run continues from the last sample done, and the twin has none (not started)"
        raise RuntimeError(msg)
    n = len(index) + 1
    before = int(index[0]) - 1
    if int(index[-1]) - before == n - 1 and _holds(last, frame, before):
        rows = slice(before, before + n)  # consecutive rows after it: the frame's own
        return Samples(frame.stamps[rows], frame.f[rows], frame.w[rows])
    t, f, w = np.empty(n), np.empty((n, 3)), np.empty((n, 3))
    t[0], f[0], w[0] = last
    t[1:], f[1:], w[1:] = frame.stamps[index], frame.f[index], frame.w[index]
    return Samples(t, f, w)


def _holds(last: tuple[float, np.ndarray, np.ndarray], frame: Frame, row: int) -> bool:
    """Whether `frame`'s row `row` is the `last` sample done, to the bit, in arrays the core
    takes as they are (float64, C-contiguous, writable): a run of the rows after it then
    needs no copy (the 5000 rows of a 5 s record at 1 kHz: 0.1 ms)."""
    if row < 0:
        return False
    arrays = (frame.stamps, frame.f, frame.w)
    for a in arrays:
        flags = a.flags
        if a.dtype != np.float64 or not (flags.c_contiguous and flags.writeable):
            return False
    stamp, f, w = last
    return (
        frame.stamps[row : row + 1].tobytes() == np.float64(stamp).tobytes()
        and frame.f[row].tobytes() == f.tobytes()
        and frame.w[row].tobytes() == w.tobytes()
    )


class TwinEngine:
    """Streaming twin of one model.

    Constructing it only checks and allocates (the model solved its nominal start state at
    assembly); the first pushed samples start the twin.

    Args:
        model: the assembled scene.
        clock: wall clock for the real-time factor, s (injectable for tests).
    """

    def __init__(self, model: Model, clock: Callable[[], float] = time.perf_counter) -> None:
        require(model, Model, "TwinEngine(model)")
        self.model = model
        self.scene = model.scene
        self._clock = clock
        self.counts: Counter[str] = Counter()
        self.failure_causes: Counter[str] = Counter()
        """Integration failures by cause (`STATUS_TEXT`), counts["integration_failures"] in all."""
        # `auto` until it has chosen
        self.health = HealthWindow(self.scene, self.scene.integration.method)
        self._intake = Intake(model, self.health, self.counts)
        self._driver = CoreDriver(model, self.health, self.counts)
        self._starts = Starts(model, self._driver, self.health, self.counts)
        self._reporting = Reporting(self._driver, self.health, self.counts)
        self._gyro = GyroDelay(
            filter_bands(self.scene.input), self._designed, start_takes(self.scene.initial)
        )
        self._pushed = 0
        """Samples pushed so far (a held one once)."""
        self._done_at = (0, math.nan)
        """(position among the samples pushed, stamp s) of the last sample the twin did,
        where decimation left it unpublished (`CoreDriver.tail_pending`)."""

    @property
    def state(self) -> np.ndarray:
        """Current state vector (copy); names in `model.state_names`."""
        return self._driver.y.copy()

    @property
    def events(self) -> list[MountEvent]:
        """Every mount event so far, in time order (the first `driver.MAX_EVENTS`; the rest
        counted): a copy, as `state` is."""
        return list(self._driver.events)

    @property
    def error_estimate(self) -> ErrorEstimate | None:
        """The estimated error of everything published so far (None: `error_estimate` off)."""
        if self._driver.estimator is None:
            return None
        return self.health.run_estimate()

    @property
    def followed_nothing(self) -> str:
        """Why the twin followed none of the input ('' if it did): no sample accepted
        (`count_texts.nothing_accepted`), or too few to start it (`HealthWindow.never_started`). A
        run like that has no figures: a sweep's case or an accuracy run is FAILED, not a
        machine at rest."""
        counts = self.counts
        return nothing_accepted(counts) or self.health.never_started(counts)

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
        return self._driver.last is not None

    @property
    def utilisation_max(self) -> dict[str, float]:
        """Peak utilisation so far of each mount that has an allowable (bolt: F_S/F_y, rubber:
        deflection/rated, key: force/allowable), by name."""
        names = [self.scene.mounts[i].name for i in self._driver.rated]
        return dict(zip(names, self._driver.utilisation_max().tolist(), strict=True))

    def stiffens(self, event: MountEvent) -> bool:
        """Whether a mount event may stiffen the scene (its kind's EVENT_STIFFENS)."""
        return self._driver.stiffens(event)

    def count(self, what: str, n: int = 1) -> None:
        """Count events found outside the engine (e.g. undecodable messages) with its own.

        `rejected_*` counters (samples received but unusable) are not lost: they are credited to
        the next stamp hole. `lost_*` counters (e.g. lost_middleware, from DDS message-lost
        events) enter the input status' lost_in_period.
        """
        self.counts[what] += n
        if what.startswith("rejected_"):
            self._intake.skipped += n

    def push(self, batch: SampleBatch) -> OutputBatch:
        """Process samples in arrival order; return what is to be published for them.

        Diagnostics come at the stamps where they would for one sample per push, so a replay in
        chunks publishes what the live node does. An empty batch changes nothing; a malformed
        non-empty one (shapes, types: `SampleBatch.check`) raises ValueError naming the field,
        and changes nothing either.
        """
        require(batch, SampleBatch, "TwinEngine.push(batch)")
        if len(batch) == 0:  # whatever its arrays' shapes (a decoder's empty result may be flat)
            return OutputBatch.empty(self.model.n_mounts)
        first_id = self._accept(batch)
        held = self._intake.held
        if held is None:
            return self._push(batch, first_id)
        # The held sample goes first, now with the next one to confirm or refute it: positions
        # in the result count from it, so it is −1 to the caller.
        self._intake.held = None
        out = self._push(SampleBatch.concat([held, batch]), first_id - 1)
        out.sample -= 1
        for report in out.health:
            report.sample -= 1
        return out

    def run(self, samples: SampleBatch) -> OutputBatch:
        """A whole record: `push` it, then `flush`; every row and report, positions in
        `samples` (the final report last). In one frame where nothing is held back from an
        earlier push: the rows the gyro delay holds to the end then land beside the others,
        and the record's rows are not copied into one batch (1 ms of the pump's 5 s)."""
        require(samples, SampleBatch, "TwinEngine.run(samples)")
        if not len(samples) or self._intake.held is not None:
            return self.push(samples).then(self.flush(), len(samples))
        return self._push(samples, self._accept(samples), end=True)

    def _accept(self, batch: SampleBatch) -> int:
        """Check a non-empty batch (`SampleBatch.check`: ValueError naming the field, nothing
        changed) and give its samples their stream positions; returns the first one's."""
        batch.check()
        first_id = self._pushed
        self._pushed += len(batch)
        return first_id

    @property
    def holding(self) -> bool:
        """Whether the last sample pushed is held back (a stamp jump to confirm): the next push
        gives its outputs, as sample −1."""
        return self._intake.held is not None

    @property
    def pushed(self) -> int:
        """Samples pushed so far (a held one once): the next one's position in the stream."""
        return self._pushed

    @property
    def pending_ids(self) -> np.ndarray:
        """The positions in the stream (from 0, among all samples pushed; increasing, int64)
        of the samples whose outputs later pushes or the flush may still give (as negative
        `OutputBatch.sample`, −1 the last sample pushed): the gyro delay's pending samples
        (`delay_line`), a sample held back (a stamp jump to confirm), and the last sample
        done where decimation left it unpublished (at its run's end, `Tail`)."""
        # in stream order: the last sample done, those released after it, the held one
        ids = [self._gyro.pending_ids]
        if self._driver.tail_pending:
            ids.insert(0, np.array([self._done_at[0]], np.int64))
        if self.holding:
            ids.append(np.array([self._pushed - 1], np.int64))
        return ids[0] if len(ids) == 1 else np.concatenate(ids)

    @property
    def latency(self) -> int:
        """Samples by which outputs follow their input (the gyro delay; 0 until designed)."""
        return self._gyro.delay

    def _designed(self, stamp: float, design: Design) -> None:
        """The gyro filter was designed, at the interval into `stamp` (s)."""
        self.health.gyro_designed(stamp, design)

    def _push(self, batch: SampleBatch, first_id: int, *, end: bool = False) -> OutputBatch:
        """`push` of a batch that holds any held-back sample first (stream position
        `first_id`): its samples judged, then followed chunk by chunk, a chunk ending where a
        report falls due; with `end`, then the stream's end (`_end`) in the same frame."""
        judged = self._intake.judge(batch)
        frame = self._gyro.frame(batch.stamps, judged.f, judged.w, first_id)
        rows = BatchRows(len(frame.stamps), self.model.n_mounts)
        parts: list[Part] = []
        reports = []
        start = 0
        for stop, report_due in [*((i + 1, True) for i in judged.due), (len(batch), False)]:
            if stop > start:  # none after a report due at the batch's last sample
                self._chunk(batch, judged, (start, stop), frame, rows, parts)
            if report_due:
                stamp = float(batch.stamps[stop - 1])
                reports.append(self._reporting.report(stamp, stop - 1, parts))
            start = stop
        if end:
            reports.extend(self._end(frame, rows, parts, len(batch) - 1))
        out = self._reporting.batch(frame, rows, parts, reports)
        self._gyro.close(frame)  # last: it may write over the frame's arrays
        return out

    def _chunk(
        self,
        batch: SampleBatch,
        judged: Judged,
        span: tuple[int, int],
        frame: Frame,
        rows: BatchRows,
        parts: list[Part],
    ) -> None:
        """Tally and follow the batch's samples [start, stop) = `span`, their outputs onto
        `parts`; the wall time it took into the health window."""
        wall0 = self._clock()
        self._intake.tally(batch, judged, *span)
        for run in runs(judged.verdicts, *span):
            self._follow(self._gyro.feed(run, frame), frame, rows, parts)
        self.health.add_wall(self._clock() - wall0)

    def _follow(self, runs: list[Run], frame: Frame, rows: BatchRows, parts: list[Part]) -> None:
        """Integrate runs of frame rows (`_integrate`), their outputs onto `parts` and into the
        health window."""
        first = len(parts)
        for run in runs:
            parts.extend(self._integrate(run, frame, rows))
        self._reporting.add(parts[first:], frame)

    def _integrate(self, run: Run, frame: Frame, rows: BatchRows) -> list[Part]:
        """Integrate one run, its outputs into `rows` where it can; on a stepper failure
        restart at the next sample (the run before ends: `_close_run`)."""
        out: list[Part] = []
        index = run.index
        driver, starts = self._driver, self._starts
        samples = frame.stamps, frame.f, frame.w
        if self.health.stopped_at is not None:
            if not run.restart:
                self.counts["samples_not_followed"] += len(index)
                return out
            self.health.stopped_at = None
        if run.restart:  # gathered afresh, maybe over pushes: nothing goes on from before
            self._close_run(out)
            driver.last = None
        if driver.last is None:
            index, gathered = starts.gather(run, frame.stamps, frame.f)
            if not len(index) or not starts.started(out, index, samples, gathered, rows):
                return out
            index = index[1:]
        if len(index):
            driver.choose_at_start(float(frame.stamps[index[0]]))
        # The run's samples from the last one done on: after a stop at an event the run goes on
        # with the rows it has.
        segment: Samples | None = None
        while len(index):
            if segment is None:
                segment = _segment(driver.last, index, frame)
            step = driver.advance(segment, index, rows)
            out.append(step.rows)
            done = step.done
            if done and driver.tail_pending:  # its last sample unpublished (decimation)
                self._done_at = (
                    frame.first_id + int(frame.relative(index[done - 1 : done])[0]),
                    float(frame.stamps[index[done - 1]]),
                )
            if step.status == 0:
                break
            if step.status == AT_EVENT:
                driver.look_again(segment, done, step.events)
                index = index[done:]
                segment = Samples(*(a[done:] for a in segment))
                continue
            segment = None  # a restart takes the rows after it afresh
            rest = index[done + 1 :]
            self._close_run(out)
            if not self._failed(step.status, float(frame.stamps[index[done]]), len(rest)):
                break
            if not len(rest) or not starts.started(out, rest, samples, frame.f[rest[:1]], rows):
                break
            index = rest[1:]
        return out

    def _close_run(self, out: list[Part]) -> None:
        """The twin's run ends (a restart follows, or the stream ends): its last sample onto
        `out` where decimation left it unpublished (`Tail`), so that no peak is lost."""
        closed = self._driver.close_run()
        if closed is not None:
            out.append(Tail(*self._done_at, *closed))

    def _failed(self, status: int, stamp: float, n_rest: int) -> bool:
        """The stepper failed (`status`) into the sample at `stamp` (s), with `n_rest` samples
        after it in the run: counted and reported; returns whether the twin may restart there
        (not where the scene gives its initial motion: the `n_rest` are then not followed)."""
        self.counts["integration_failures"] += 1
        cause = STATUS_TEXT.get(status, f"status {status}")
        self.failure_causes[cause] += 1
        self.health.failure(stamp, cause)
        self._driver.last = None
        self._starts.after_failure()
        if self.scene.initial.mode != "given":
            return True
        # A restart would launch the given initial motion again: a motion the body is not
        # making. The twin stops following until the record restarts.
        self._starts.stop_following(stamp, GIVEN_MOTION_STOP)
        self.counts["samples_not_followed"] += n_rest
        return False

    def flush(self) -> OutputBatch:
        """The end of the stream (end of a bag, shutdown): the outputs of the samples the gyro
        delay still holds (the rate after the last held at its value; `sample` negative, −1
        the last sample pushed), then the last sample's where decimation left it unpublished
        (with the peaks since the row before), and in `health` the report of what happened
        since the last one, due or not (none if nothing was processed since; its `sample` is
        −1).

        A sample still held back (a stamp jump that no later sample confirmed) is counted as
        rejected_unconfirmed_jump: the record ends before it can be told from a glitch. Where
        samples were received but none ever accepted, the report (`stamp` NaN) says so at
        ERROR, and why (`input_status.ENDED`).
        """
        empty = np.zeros((0, 3))
        frame = self._gyro.frame(np.zeros(0), empty, empty, self._pushed)
        rows = BatchRows(len(frame.stamps), self.model.n_mounts)
        parts: list[Part] = []
        reports = self._end(frame, rows, parts, -1)
        return self._reporting.batch(frame, rows, parts, reports)

    def _end(
        self, frame: Frame, rows: BatchRows, parts: list[Part], last: int
    ) -> list[HealthReport]:
        """The stream's end in `frame` (`flush`'s, or the last push's in `run`): a held-back
        sample counted rejected, the gyro delay drained onto `parts`, the run's last sample
        where decimation left it unpublished, and the final report (after `parts`, at sample
        `last`), if one is due."""
        if self._intake.held is not None:
            self._intake.held = None
            self.count("received")
            self.count("rejected_unconfirmed_jump")
        self._follow(self._gyro.drain(frame), frame, rows, parts)
        tail: list[Part] = []
        self._close_run(tail)
        parts += tail
        self._reporting.add(tail, frame)
        last_stamp = self._intake.last_stamp
        if last_stamp is not None:
            if self.health.pending(self.counts):
                return [self._reporting.report(last_stamp, last, parts, ended=True)]
        elif self.counts["received"] and not self.counts["accepted"]:
            return [self._reporting.report(math.nan, last, parts, stalled_s=ENDED, ended=True)]
        return []

    def report_stalled(self, waited_s: float) -> HealthReport:
        """The report a live adapter publishes when `waited_s` (s, its clock) passed without a
        sample accepted nor a report due: the window so far, as `flush` gives it, with the
        input status an ERROR that says why (nothing received, everything rejected, or the
        samples accepted came before). Works before any sample was accepted.

        Its `stamp` is the last accepted stamp (engine seconds, NaN if none), its `sample` −1.
        The window starts anew, and the stamp cadence restarts at the next accepted sample.
        """
        last_stamp = self._intake.last_stamp
        stamp = math.nan if last_stamp is None else last_stamp
        report = self._reporting.report(stamp, -1, stalled_s=waited_s)
        self.health.restart_cadence()
        return report
